/**
 * A long capture in the worker (replay-pass.ts, replay-session.ts): its overview grows as it is
 * read, never showing what has not been read, and ends equal to the overview made in one go; a
 * seek starts from the nearest checkpoint, with the counters and link figures of the whole
 * capture up to the target, as a decode fed every chunk up to there has them.
 */
import { describe, expect, it } from 'vitest';
import type { Capture } from '../src/capture/model.js';
import { captureChunksByPort, capturePorts } from '../src/capture/facts.js';
import { encodeCapture } from '../src/capture/writer.js';
import { readCapture } from '../src/capture/sniff.js';
import { Dispatcher } from '../src/worker/dispatcher.js';
import { addOverviews, overviewOf } from '../src/worker/replay/overview.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { usbChunks } from './feeds.js';
import { CHECKPOINT_US, ReplayPass, checkpointDue } from '../src/worker/replay/replay-pass.js';
import { checkpointChunks } from '../src/worker/replay/replay-split.js';
import { passOverFile } from '../src/worker/replay/replay-file-pass.js';
import { type PreviewSizes, previewOf } from '../src/worker/replay/replay-preview.js';
import { captureSpan } from '../src/report/capture-span.js';
import { healthReport } from '../src/report/report.js';
import type { Overview } from '../src/worker/protocol.js';
import { MINUTE, libraryUpTo, longCapture, longCaptureWithSeed } from './long-capture.js';
import { FakeClock, ReadingClock, fakeHost } from './worker-fakes.js';

const FILE = longCapture();

function open(clock: FakeClock, previewSizes?: PreviewSizes) {
  const fake = fakeHost(clock);
  const worker = new Dispatcher(fake.host, { previewSizes });
  const send = async (...messages: Parameters<Dispatcher['receive']>[0][]): Promise<void> => {
    for (const m of messages) worker.receive(m);
    await worker.queue.idle();
  };
  return { ...fake, worker, send };
}

describe('a long capture in the worker', () => {
  it('draws its overview as it is read: nothing after the part read, each part as the complete one has it, and complete at the end as made in one go', async () => {
    const clock = new ReadingClock();
    const { send, of } = open(clock);
    await send({ type: 'replay-open', name: 'long.sscap', file: new Blob([FILE.slice()]) });
    const first = of('overview')[0];
    expect(first?.overview.complete).toBe(false);
    for (let guard = 0; guard < 1000 && !of('overview').at(-1)?.overview.complete; guard++) clock.advance(10);
    const all = of('overview').map((m) => m.overview);
    expect(all.length).toBeGreaterThan(3);
    const last = all.at(-1) as Overview;
    expect(last.complete).toBe(true);
    const capture = readCapture(FILE, 'long.sscap');
    const once = overviewOf(capture, capturePorts(capture), 'auto').overview;
    expect(Array.from(last.t)).toEqual(Array.from(once.t));
    expect(Array.from(last.fadeRate)).toEqual(Array.from(once.fadeRate));
    expect(Array.from(last.lost)).toEqual(Array.from(once.lost));
    expect(last.failsafe).toEqual(once.failsafe);
    expect(once.failsafe.length).toBe(1);
    let before = Number.NEGATIVE_INFINITY;
    for (const o of all.slice(0, -1)) {
      // It grows, and only up to where every port has been read.
      expect(o.readUntilUs).toBeGreaterThanOrEqual(before);
      before = o.readUntilUs;
      expect(o.t.length).toBeLessThanOrEqual(Math.round((o.readUntilUs - (once.t[0] ?? 0)) / o.binUs));
      for (let b = 0; b < o.t.length; b++) {
        expect(o.t[b]).toBe(once.t[b]);
        expect([b, o.fadeRate[b], o.lost[b]]).toEqual([b, once.fadeRate[b], once.lost[b]]);
      }
      for (const f of o.failsafe) expect(f.endUs).toBeLessThanOrEqual(o.readUntilUs);
    }
  });

  it("seeks anywhere from a checkpoint: the counters and link figures are the whole capture's up to the target", async () => {
    const clock = new FakeClock();
    const { send, worker } = open(clock);
    await send({ type: 'replay-open', name: 'long.sscap', file: new Blob([FILE.slice()]) }, { type: 'replay-pause' });
    const capture = readCapture(FILE, 'long.sscap');
    const start = worker.replay?.source.startUs ?? Number.NaN;
    // Past the fresh decode's 10 minutes, before and after the failsafe, backwards and forwards.
    for (const at of [11.2, 3.5, 0.5, 7.25, 10.9, 1.4]) {
      const target = start + at * MINUTE;
      await send({ type: 'replay-seek', timeUs: target });
      for (const port of [0, 1]) {
        const engine = worker.registry.get(port)?.engine;
        const want = libraryUpTo(capture, port, target);
        expect({ at, port, decoder: { ...engine?.decoder.stats } }).toEqual({ at, port, decoder: want.decoder });
        const l = engine?.link.stats;
        const got = {
          frames: l?.frames,
          fades: l?.fades,
          missed: l?.missedFrames,
          lost: l?.lostFrames,
          holds: l?.holds,
          failsafes: l?.failsafes,
        };
        const w = want.link;
        expect({ at, port, ...got }).toEqual({
          at,
          port,
          frames: w.frames,
          fades: w.fades,
          missed: w.missedFrames,
          lost: w.lostFrames,
          holds: w.holds,
          failsafes: w.failsafes,
        });
      }
    }
    // After the failsafe at 5 minutes, it is counted.
    expect(worker.registry.get(0)?.engine.link.stats.failsafes).toBe(0);
    await send({ type: 'replay-seek', timeUs: start + 8 * MINUTE });
    expect(worker.registry.get(0)?.engine.link.stats.failsafes).toBe(1);
  });

  it('previews a long file from its first records and its end, and the decode begun on them goes on with the whole capture to the same overview and checkpoints', async () => {
    const capture = readCapture(FILE, 'long.sscap');
    const ports = capturePorts(capture);
    const span = captureSpan(capture);
    const preview = await previewOf(new Blob([FILE.slice()]), { minBytes: 0, headBytes: 400_000, tailBytes: 20_000 });
    expect(preview).not.toBeNull();
    if (preview === null) return;
    expect([preview.startUs, preview.endUs]).toEqual([span.startUs, span.endUs]);
    expect(preview.ports).toEqual(ports);
    // Its size counted by its index, exactly.
    expect(preview.indexed).toBe(true);
    expect(preview.expected.records).toBe(capture.chunkEnds.length);
    expect(preview.expected.dataBytes).toBe(capture.bytes.length);
    expect(preview.expected.chunksByPort).toEqual(Array.from(captureChunksByPort(capture)));
    // Without its final index (a recording cut short), guessed from the start: a few percent over.
    const cut = FILE.subarray(0, FILE.length - 200);
    const guessed = await previewOf(new Blob([cut.slice()]), { minBytes: 0, headBytes: 400_000, tailBytes: 20_000 });
    expect(guessed?.indexed).toBe(false);
    expect(guessed?.expected.records).toBeGreaterThan(capture.chunkEnds.length * 0.97);
    expect(guessed?.expected.records).toBeLessThan(capture.chunkEnds.length * 1.1);
    // The head is the file's first records: a prefix of the whole capture's chunks.
    const n = preview.head.chunkEnds.length;
    expect(n).toBeGreaterThan(1000);
    expect(n).toBeLessThan(capture.chunkEnds.length / 4);
    expect(Array.from(preview.head.chunkTimesUs)).toEqual(Array.from(capture.chunkTimesUs.subarray(0, n)));
    const now = (() => {
      let t = 0;
      return () => (t += 1);
    })();
    const early = new ReplayPass(preview.head, preview.ports, 'auto', preview.startUs, preview.endUs, true);
    // Decoded to the head's end, it is not done: the capture goes on.
    for (let k = 0; k < 100; k++) expect(early.step(40, now)).toBe(false);
    expect(early.overview().complete).toBe(false);
    const other = readCapture(longCaptureWithSeed(5), 'other.sscap');
    expect(early.continueWith(other, ports, span.startUs, span.endUs)).toBe(false);
    expect(early.continueWith(capture, ports, span.startUs, span.endUs)).toBe(true);
    while (!early.step(40, now));
    const whole = new ReplayPass(capture, ports, 'auto', span.startUs, span.endUs);
    while (!whole.step(40, now));
    const a = early.overview();
    const b = whole.overview();
    expect([Array.from(a.t), Array.from(a.fadeRate), Array.from(a.lost), a.failsafe]).toEqual([
      Array.from(b.t),
      Array.from(b.fadeRate),
      Array.from(b.lost),
      b.failsafe,
    ]);
    expect(early.checkpoints.map((c) => c.chunk)).toEqual(whole.checkpoints.map((c) => c.chunk));
    expect(JSON.stringify(early.checkpoints.at(-1)?.ports.get(1)?.link)).toBe(JSON.stringify(whole.checkpoints.at(-1)?.ports.get(1)?.link));
  });

  it('reads a file too short for a preview, or not a capture with chunk times, whole', async () => {
    expect(await previewOf(new Blob([FILE.slice()]))).toBeNull();
    expect(await previewOf(new Blob([new Uint8Array(1000)]), { minBytes: 0, headBytes: 400, tailBytes: 100 })).toBeNull();
  });

  it("shows a long file's span and its first records' overview before reading it whole, then plays and seeks as one read whole", async () => {
    const clock = new FakeClock();
    const { send, posts, worker } = open(clock, { minBytes: 0, headBytes: 400_000, tailBytes: 20_000 });
    await send({ type: 'replay-open', name: 'long.sscap', file: new Blob([FILE.slice()]) });
    const capture = readCapture(FILE, 'long.sscap');
    const span = captureSpan(capture);
    // First: the span and a partial overview, nothing played; then the replay of the whole file.
    const first = posts.findIndex((m) => m.type === 'replay' && m.replay !== null);
    const firstReplay = posts[first];
    expect(firstReplay?.type === 'replay' && firstReplay.replay).toMatchObject({
      startUs: span.startUs,
      endUs: span.endUs,
      playing: false,
      frames: 0,
    });
    const overviews = posts.flatMap((m, k) => (m.type === 'overview' ? [{ k, o: m.overview }] : []));
    expect(overviews[0]?.k).toBeGreaterThan(first);
    expect(overviews[0]?.o.complete).toBe(false);
    expect(overviews[0]?.o.readUntilUs).toBeLessThan(span.startUs + 2 * MINUTE);
    const playing = posts.findIndex((m) => m.type === 'replay' && m.replay?.playing === true);
    expect(playing).toBeGreaterThan(overviews[0]?.k ?? Infinity);
    const last = overviews.at(-1)?.o;
    const once = overviewOf(capture, capturePorts(capture), 'auto').overview;
    expect(last?.complete).toBe(true);
    expect(Array.from(last?.lost ?? [])).toEqual(Array.from(once.lost));
    expect(last?.failsafe).toEqual(once.failsafe);
    await send({ type: 'replay-pause' }, { type: 'replay-seek', timeUs: span.startUs + 11 * MINUTE });
    expect({ ...worker.registry.get(0)?.engine.decoder.stats }).toEqual(libraryUpTo(capture, 0, span.startUs + 11 * MINUTE).decoder);
  });

  it('draws a failsafe still on when the capture ends to its end, read as it goes, in parts or in one go, as the report has it', () => {
    // The internal remote falls silent 40 s in and never comes back; the external one goes on to the end at 60 s.
    const a = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 5, dropouts: [{ atUs: 40e6, durationUs: 100e6 }] }, 60e6);
    const b = simulate({ ...preset('dsmx-11ms-2048-external'), seed: 6 }, 60e6);
    const records = [
      ...usbChunks(a.bytes, a.timesUs).map((c) => ({ type: 'data' as const, bytes: c.bytes, timeUs: c.timeUs, port: 0 })),
      ...usbChunks(b.bytes, b.timesUs).map((c) => ({ type: 'data' as const, bytes: c.bytes, timeUs: c.timeUs + 3, port: 1 })),
    ].sort((x, y) => x.timeUs - y.timeUs);
    const capture = readCapture(encodeCapture({ baudRate: 115200 }, records));
    const { startUs, endUs } = captureSpan(capture);
    const [episode, ...others] = healthReport(capture).remotes.flatMap((r) => r.failsafes);
    expect(others).toEqual([]);
    expect(episode?.ongoing).toBe(true);
    const asReported = [{ startUs: (episode?.startUs ?? 0) + startUs, endUs: (episode?.endUs ?? 0) + startUs }];
    const near = (got: Overview['failsafe']) => got.map((f) => ({ startUs: Math.round(f.startUs / 10), endUs: Math.round(f.endUs / 10) }));
    expect(near(asReported)[0]?.endUs).toBe(Math.round(endUs / 10));
    // In one go.
    expect(near(overviewOf(capture, [0, 1], 'auto').overview.failsafe)).toEqual(near(asReported));
    // Read as it goes: nothing of it before the reading is past the silence (the overview waits for
    // the silent port's evidence), then all of it, to the end.
    const pass = new ReplayPass(capture, [0, 1], 'auto', startUs, endUs);
    let clock = 0;
    let steps = 0;
    for (; !pass.step(1, () => (clock += 1)); steps++) {
      const o = pass.overview();
      for (const f of o.failsafe) expect(f.endUs).toBeLessThanOrEqual(o.readUntilUs);
    }
    expect(steps).toBeGreaterThan(10);
    expect(near(pass.overview().failsafe)).toEqual(near(asReported));
    // Each port decoded apart (a pass split with a helper), and added up.
    const parts = [0, 1].map((port) => {
      const part = new ReplayPass(capture, [port], 'auto', startUs, endUs);
      while (!part.step(1000, () => performance.now()));
      return part.overview();
    });
    expect(near(addOverviews(parts, startUs).failsafe)).toEqual(near(asReported));
  });
});

describe("a recording's unplug in the overview", () => {
  it('draws no failsafe for the time the adapter was away ("device lost"), in one go, read as it goes and walked from the file', async () => {
    const a = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 5, fades: { lossRate: 0, randomRate: 0 } }, 8e6);
    const chunks = usbChunks(a.bytes, a.timesUs);
    const before = chunks.filter((c) => c.timeUs < 3e6);
    const after = chunks.filter((c) => c.timeUs >= 5.5e6);
    const make = (events: boolean) =>
      encodeCapture({ baudRate: 115200 }, [
        ...before.map((c) => ({ type: 'data' as const, ...c, port: 0 })),
        ...(events ? [{ type: 'event' as const, text: 'device lost', timeUs: before.at(-1)!.timeUs + 300, port: 0 }] : []),
        ...after.map((c) => ({ type: 'data' as const, ...c, port: 0 })),
      ]);
    const failsafes = async (file: Uint8Array): Promise<number[]> => {
      const capture = readCapture(file);
      const { startUs, endUs } = captureSpan(capture);
      const pass = new ReplayPass(capture, [0], 'auto', startUs, endUs);
      let clock = 0;
      while (!pass.step(1, () => (clock += 1)));
      // The file walked record by record (a large file's pass in a helper), in 4 kB slices.
      let walked: Overview | null = null;
      const sliced = {
        size: file.length,
        slice: (from: number, to: number) => ({ arrayBuffer: async () => file.slice(from, to).buffer }),
      };
      const job = {
        size: file.length,
        ports: [0],
        alsoChecked: [],
        sliceBytes: 4096,
        resolution: 'auto' as const,
        originUs: startUs,
        endUs,
      };
      await passOverFile(
        job,
        sliced,
        (r) => {
          if (r.type === 'done') walked = r.overview;
        },
        () => 0,
      );
      return [
        overviewOf(capture, [0], 'auto').overview.failsafe.length,
        pass.overview().failsafe.length,
        (walked as Overview | null)?.failsafe.length ?? -1,
      ];
    };
    expect(await failsafes(make(false))).toEqual([1, 1, 1]);
    expect(await failsafes(make(true))).toEqual([0, 0, 0]);
  });
});

describe('where the checkpoints fall in a capture', () => {
  /** The rule as the replay pass applies it, chunk by chunk: the reference. */
  function walked(times: number[], originUs: number): { chunk: number; fedUntilUs: number }[] {
    const out: { chunk: number; fedUntilUs: number }[] = [];
    let next = originUs + CHECKPOINT_US;
    let fed = Number.NEGATIVE_INFINITY;
    times.forEach((t, i) => {
      const due = checkpointDue(next, t);
      if (due !== next) {
        out.push({ chunk: i, fedUntilUs: fed });
        next = due;
      }
      if (t > fed) fed = t;
    });
    return out;
  }
  const columns = (times: number[]): Capture => ({
    kind: 'raw',
    meta: {},
    timing: 'per-chunk',
    bytes: new Uint8Array(times.length),
    chunkEnds: Uint32Array.from(times, (_, i) => i + 1),
    chunkTimesUs: Float64Array.from(times),
    chunkPorts: new Uint8Array(times.length),
    events: [],
    issues: [],
  });

  it('finds the chunks the pass’s rule puts them on, by bisection where the times never go back and chunk by chunk where they do', () => {
    let seed = 7;
    const random = (): number => {
      seed = (seed * 48271) % 2147483647;
      return seed / 2147483647;
    };
    let onDue = 0;
    for (let run = 0; run < 60; run++) {
      // Chunks 16 ms apart, with runs of equal times, silences of seconds to minutes (several
      // checkpoints due at once) and, all steps whole 16 ms, chunks right on a due time; in
      // some runs a step back or a NaN.
      const times: number[] = [];
      let t = 1e6;
      const n = 200 + Math.floor(random() * 30000);
      for (let i = 0; i < n; i++) {
        const r = random();
        t += r < 0.1 ? 0 : r < 0.997 ? 16e3 : Math.floor(random() * 12500) * 16e3;
        times.push(t);
      }
      if (run % 5 === 1) times[n >> 2] = (times[n >> 2] ?? 0) - 30e6;
      if (run % 7 === 2) times[n >> 3] = Number.NaN;
      const origin = times[0] ?? 0;
      const want = walked(times, origin);
      expect({ run, at: checkpointChunks(columns(times), origin) }).toEqual({ run, at: want });
      onDue += want.filter(
        (c) =>
          (times[c.chunk] ?? 0) === (times[0] ?? 0) + Math.round(((times[c.chunk] ?? 0) - (times[0] ?? 0)) / CHECKPOINT_US) * CHECKPOINT_US,
      ).length;
    }
    // Chunks right on a due time were among them.
    expect(onDue).toBeGreaterThan(5);
  });
});
