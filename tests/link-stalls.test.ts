/**
 * A live link whose adapter (or computer) stalls, once or a few times, anywhere: the page's
 * engine, fed the chunks as a browser would read them, ends with the holds and failsafes the
 * receiver had, whatever the stalls hid or looked like. A stall that holds back half a frame, one that runs
 * into a real dropout, one that swallows a dropout's start, and the page's own timer stalling
 * with it are all among the cases.
 */
import { describe, expect, it } from 'vitest';
import { USB_CHUNK_JITTER_US } from '../src/decoder/spec.js';
import { LinkMonitor } from '../src/decoder/link.js';
import type { DecodedFrame } from '../src/decoder/types.js';
import { summarizeCapture } from '../src/report/summary.js';
import { preset } from '../src/simulator/presets.js';
import { Prng } from '../src/simulator/prng.js';
import { simulate } from '../src/simulator/simulator.js';
import { Engine } from '../src/worker/engine.js';
import type { Capture } from '../src/capture/model.js';
import { encodeCapture } from '../src/capture/writer.js';
import { readCapture } from '../src/capture/sniff.js';
import { concatBytes } from './bytes.js';
import { perByteCapture, recording, usbChunks } from './feeds.js';

/** Where a stall starts (µs into the stream) and how long it lasts. */
interface Stall {
  atUs: number;
  forUs: number;
}

/**
 * The engine fed `bytes` as a serial reader wakes every 0.5–3.5 ms and takes what has arrived
 * (one chunk, its time the wake), the page asking for a batch every 16–46 ms; over each of
 * `stalls` the reader sleeps (and, in half the cases, the page's timer too), then gets what
 * piled up in pieces up to 2 ms apart. Ends 3.2 s after the last byte (the receiver quiet for good).
 */
function stalledFeed(bytes: Uint8Array, timesUs: Float64Array, stalls: Stall[], rng: Prng): Engine {
  const engine = new Engine({ resolution: 'auto', jitterUs: USB_CHUNK_JITTER_US });
  const t0 = timesUs[0] ?? 0;
  const timerStalls = rng.chance(0.5);
  let t = (timesUs[0] ?? 0) - 5_000;
  let nextBatch = t;
  let i = 0;
  while (i < bytes.length) {
    let step = rng.uniform(500, 3_500);
    const stall = stalls.find((s) => t < t0 + s.atUs && t + step >= t0 + s.atUs);
    const stalled = stall !== undefined;
    if (stalled) step += stall.forUs;
    for (; nextBatch < t + step && !(stalled && timerStalls); nextBatch += rng.uniform(16_000, 46_000)) engine.batch(nextBatch);
    t += step;
    let j = i;
    while (j < bytes.length && (timesUs[j] ?? 0) <= t) j++;
    while (i < j) {
      const n = stalled ? Math.min(j - i, 1 + rng.int(200)) : j - i;
      engine.push(bytes.subarray(i, i + n), t, t / 1000);
      i += n;
      if (stalled && i < j) t += rng.uniform(0, 2_000);
    }
    if (nextBatch < t) {
      engine.batch(t);
      nextBatch = t + rng.uniform(16_000, 46_000);
    }
  }
  for (const end = t + 3_200_000; t < end; t += 16_000) engine.batch(t);
  return engine;
}

describe('a stall of the delivery, anywhere in a link with real dropouts', () => {
  it('ends with the holds and failsafes the receiver had: 400 single stalls of 30–430 ms, 300 runs of 2–5 of 20–300 ms', () => {
    // A DSMX 11 ms link that drops out for 0.2 s (a hold) and for 1.3 s (a failsafe), then
    // recovers; after its last frame, a third hold and failsafe (the receiver quiet for good).
    const sim = simulate(preset('dropouts-failsafe'));
    const truth = summarizeCapture(perByteCapture(sim)).episodes.map((e) => e.kind);
    expect(truth).toEqual(['hold', 'hold', 'failsafe']);
    const want = [...truth, 'hold', 'failsafe'];
    const spanUs = (sim.timesUs.at(-1) ?? 0) - (sim.timesUs[0] ?? 0);
    const wrong: string[] = [];
    for (let seed = 1; seed <= 700; seed++) {
      const rng = new Prng(seed);
      const [count, shortest, longest] = seed <= 400 ? [1, 30_000, 430_000] : [2 + rng.int(4), 20_000, 300_000];
      const stalls = Array.from({ length: count }, () => {
        const forUs = rng.uniform(shortest, longest);
        // Starts anywhere, ends at least 50 ms before the last frame (one after it cannot be told from the end).
        return { atUs: rng.uniform(0, spanUs - forUs - 50_000), forUs };
      }).sort((a, b) => a.atUs - b.atUs);
      const engine = stalledFeed(sim.bytes, sim.timesUs, stalls, rng);
      const got = engine.link.episodes.map((e) => e.kind);
      const { holds, failsafes } = engine.link.stats;
      if (got.join() !== want.join() || holds !== 3 || failsafes !== 2)
        wrong.push(
          `${stalls.map((s) => `${(s.forUs / 1e3).toFixed(0)} ms at ${(s.atUs / 1e6).toFixed(3)} s`).join(', ')}: ${got.join(' ')}`,
        );
    }
    expect(wrong).toEqual([]);
  });

  it('and with a stall that ends with the feed: its hold is judged once the frames stop for good', () => {
    const sim = simulate(preset('dropouts-failsafe'));
    const spanUs = (sim.timesUs.at(-1) ?? 0) - (sim.timesUs[0] ?? 0);
    const wrong: string[] = [];
    for (let seed = 1; seed <= 100; seed++) {
      const rng = new Prng(seed);
      const forUs = rng.uniform(30_000, 430_000);
      const stall = { atUs: spanUs - forUs + rng.uniform(-60_000, 0), forUs };
      const got = stalledFeed(sim.bytes, sim.timesUs, [stall], rng).link.episodes.map((e) => e.kind);
      if (got.join() !== 'hold,hold,failsafe,hold,failsafe') wrong.push(`${(forUs / 1e3).toFixed(0)} ms at the end: ${got.join(' ')}`);
    }
    expect(wrong).toEqual([]);
  });
});

describe('a frame the decoder holds while the page asks for the state', () => {
  it('ends the silence before it, as satscope info says, whenever the page asks', () => {
    // The first frame after a dropout waits in the decoder for the one after it (its
    // confirmation); a batch in between knows only that a frame came (`pendingSinceUs`).
    for (const name of ['dsmx-22ms-2048-external', 'dsm2-22ms-1024-external', 'dsmx-11ms-2048-external']) {
      const sim = simulate({
        ...preset(name),
        dropouts: [
          { atUs: 500_000, durationUs: 300_000 },
          { atUs: 1_500_000, durationUs: 1_300_000 },
        ],
        durationUs: 3_200_000,
      });
      const truth = summarizeCapture(perByteCapture(sim)).episodes.map((e) => e.kind);
      expect(truth, name).toEqual(['hold', 'hold', 'failsafe']);
      for (const chunk of [7, 16]) {
        const engine = new Engine({ resolution: 'auto', jitterUs: USB_CHUNK_JITTER_US });
        for (let i = 0; i < sim.bytes.length; i += chunk) {
          const t = sim.timesUs[Math.min(sim.bytes.length, i + chunk) - 1] ?? 0;
          engine.push(sim.bytes.subarray(i, i + chunk), t, t / 1000);
          engine.batch(t + 500);
        }
        engine.end();
        expect(
          engine.link.episodes.map((e) => e.kind),
          `${name}, ${chunk}-byte chunks`,
        ).toEqual(truth);
      }
    }
  });
});

/** A stand-in frame of an internal DSMX 11 ms remote (its system byte gives the period): only what the monitor reads. */
const frame = (timeUs: number, fades: number, fadesDelta: number): DecodedFrame =>
  ({ timeUs, fades: fades & 0xff, fadesDelta, system: 0xb2, remote: 'internal', rssi: null }) as DecodedFrame;

describe("the receiver's counter, where the adapter saw no silence", () => {
  it('counts a run of lost frames a stall hid as the hold it was, and its failsafe past a second', () => {
    for (const [run, failsafes] of [
      [18, 0],
      [118, 1],
    ] as const) {
      const link = new LinkMonitor({ jitterUs: 20_000 });
      let t = 0;
      for (let k = 0; k < 50; k++, t += 11_000) link.frame(frame(t, 40, 0));
      // The last frames before the silence came late, in a burst; the first after it 20 ms on.
      link.frame(frame(t + 20_000, 40 + run, run));
      expect(link.stats, `${run}`).toMatchObject({ holds: 1, failsafes, missedFrames: run });
      const [hold] = link.episodes;
      expect(hold?.startUs).toBe(t + 20_000 - run * 11_000);
      expect(link.episodes.at(-1)?.endUs).toBe(t + 20_000);
    }
  });

  it("dates them on the receiver's clock where the adapter saw a shorter silence: each episode starts before it ends", () => {
    const link = new LinkMonitor({ jitterUs: 20_000 });
    let t = 0;
    for (let k = 0; k < 50; k++, t += 11_000) link.frame(frame(t, 40, 0));
    // 300 ms without frames seen, then one whose count says 181 were lost (2 s).
    link.update(t + 290_000);
    link.frame(frame(t + 300_000, 40 + 181, 181));
    expect(link.stats).toMatchObject({ holds: 1, failsafes: 1 });
    const [hold, failsafe] = link.episodes;
    expect(hold!.startUs).toBe(t + 300_000 - 181 * 11_000);
    expect(hold!.endUs).toBe(failsafe!.startUs);
    expect(failsafe!.startUs).toBeGreaterThan(hold!.startUs);
    expect(failsafe!.endUs).toBe(t + 300_000);
  });

  it('adds nothing where the period is only estimated (an external remote): a period read twice too long makes every run a hold', () => {
    const link = new LinkMonitor({ jitterUs: 20_000 });
    const ext = (timeUs: number, fades: number, fadesDelta: number): DecodedFrame =>
      ({ timeUs, fades, fadesDelta, system: null, remote: 'external', rssi: null }) as DecodedFrame;
    let t = 0;
    for (let k = 0; k < 50; k++, t += 11_000) link.frame(ext(t, 40, 0));
    link.frame(ext(t + 20_000, 58, 18));
    expect(link.stats).toMatchObject({ holds: 0, failsafes: 0, missedFrames: 18 });
  });

  it('reads the period of an external remote delivered in batches, and withdraws the holds the batches made', () => {
    // An adapter that hands over 32–200 ms at a time (a long latency timer): every batch is a
    // silence longer than a hold to the adapter, while the receiver's counter shows no frame lost
    // in it. Its frames come 1.4 ms apart inside a batch: the period is read from the batches'
    // span, where that tells 11 from 22 ms, and never guessed where it does not. A period
    // guessed 11 ms from 9 frames of 22 ms in 64 ms batches counted half the frames missing.
    for (const name of ['dsmx-11ms-2048-external', 'dsm2-22ms-1024-external', 'dsmx-22ms-2048-external'] as const) {
      const sim = simulate(preset(name), 10e6);
      const truth = summarizeCapture(perByteCapture(sim));
      for (const windowUs of [32_000, 50_000, 64_000, 88_000, 120_000, 200_000]) {
        const s = summarizeCapture(recording([sim], true, windowUs));
        // The last batch's time may lie up to a window after its last frame: the capture's end,
        // silent that long, may be a hold.
        const held = s.episodes.filter((e) => e.kind === 'hold' && e.endUs !== null);
        expect(held, `${name} in ${windowUs / 1000} ms batches`).toEqual([]);
        expect(s.link.failsafes).toBe(truth.link.failsafes);
        expect(s.link.missedFrames).toBe(truth.link.missedFrames);
        const period = s.link.nominalPeriodUs;
        if (windowUs <= 120_000) expect(period, `${name} in ${windowUs / 1000} ms batches`).toBe(truth.link.nominalPeriodUs);
        else if (!Number.isNaN(period)) expect(period).toBe(truth.link.nominalPeriodUs);
        // Frames that did not reach the adapter: only those the receiver lost (the batches bring
        // the rest). Through batches of over 100 ms a window's most punctual frame, a batch's
        // last, may be dated anywhere up to a period late: the count is good to one there.
        const slack = windowUs > 100_000 ? 1 : 0;
        expect(s.link.lostFrames, `${name} in ${windowUs / 1000} ms batches`).toBeLessThanOrEqual(truth.link.missedFrames + slack);
      }
    }
  });

  it("keeps a real dropout's hold on a 22 ms external remote whose period is not measured yet", () => {
    // A review found these withdrawn when a run the counter counted was timed at 11 ms with no
    // period known: 3 frames lost at 22 ms are an 88 ms silence on the receiver's line.
    const cases = [
      {
        name: 'dsm2-22ms-1024-external',
        seed: 4,
        dropouts: [
          { atUs: 169_568, durationUs: 67_813 },
          { atUs: 2_661_313, durationUs: 165_833 },
        ],
      },
      { name: 'dsmx-22ms-2048-external', seed: 55, dropouts: [{ atUs: 83_813, durationUs: 84_926 }] },
    ] as const;
    for (const c of cases) {
      const sim = simulate({ ...preset(c.name), seed: c.seed, dropouts: [...c.dropouts] }, 5e6);
      const truth = summarizeCapture(perByteCapture(sim));
      // 32-byte chunks, each timed by its last byte.
      const n = sim.bytes.length;
      const ends = Uint32Array.from({ length: Math.ceil(n / 32) }, (_, k) => Math.min(n, (k + 1) * 32));
      const capture: Capture = {
        ...perByteCapture(sim),
        kind: 'sscap',
        timing: 'per-chunk',
        byteTimesUs: undefined,
        chunkEnds: ends,
        chunkTimesUs: Float64Array.from(ends, (e) => sim.timesUs[e - 1]!),
        chunkPorts: new Uint8Array(ends.length),
      };
      const s = summarizeCapture(capture);
      expect(truth.link.holds, c.name).toBe(c.dropouts.length);
      expect(s.link.holds, c.name).toBe(truth.link.holds);
    }
  });

  it('keeps the holds of real dropouts after a stall that raised the delivery jitter', () => {
    // A 300 ms stall at 2 s makes the measured jitter 300 ms, and so the adapter's hold
    // threshold: a real dropout of 100-500 ms at 6 s, which the receiver's counter counts,
    // is a hold all the same (found by a review: 0 holds beside 23 missed frames).
    for (const dropUs of [100_000, 250_000, 500_000]) {
      const sim = simulate(
        {
          ...preset('dsmx-11ms-2048-internal'),
          seed: 2,
          fades: { lossRate: 0, randomRate: 0 },
          dropouts: [{ atUs: 6e6, durationUs: dropUs }],
        },
        10e6,
      );
      const truth = summarizeCapture(perByteCapture(sim));
      const chunks: { bytes: Uint8Array; timeUs: number }[] = [];
      let held: Uint8Array[] = [];
      for (const c of usbChunks(sim.bytes, sim.timesUs)) {
        if (c.timeUs >= 2e6 && c.timeUs < 2.3e6) {
          held.push(c.bytes);
          continue;
        }
        chunks.push({ bytes: concatBytes([...held, c.bytes]), timeUs: c.timeUs });
        held = [];
      }
      const capture = readCapture(
        encodeCapture(
          { baudRate: 115_200, source: 'test' },
          chunks.map((c) => ({ type: 'data' as const, ...c, port: 0 })),
        ),
        'stalled.sscap',
      );
      const s = summarizeCapture(capture).link;
      expect(truth.link.holds, `${dropUs}`).toBe(1);
      expect({ holds: s.holds, failsafes: s.failsafes, missed: s.missedFrames }, `${dropUs}`).toEqual({
        holds: truth.link.holds,
        failsafes: truth.link.failsafes,
        missed: truth.link.missedFrames,
      });
    }
  });

  it('adds nothing after a break in its view (an interrupt): the count spans time it did not see', () => {
    const link = new LinkMonitor({ jitterUs: 20_000 });
    let t = 0;
    for (let k = 0; k < 50; k++, t += 11_000) link.frame(frame(t, 40, 0));
    link.interrupt(t);
    link.frame(frame(t + 3_000_000, 52, 12));
    expect(link.stats).toMatchObject({ holds: 0, failsafes: 0 });
  });
});
