/**
 * The worker's parts that run without a browser: the engine's batches (graph buckets, lost
 * frames, episodes, a forced resolution), replay on the capture's own clock, and the wording
 * of port errors.
 */
import { describe, expect, it } from 'vitest';
import { encodeCapture } from '../src/capture/writer.js';
import { importRaw } from '../src/capture/raw.js';
import { readCapture } from '../src/capture/sniff.js';
import type { Capture } from '../src/capture/model.js';
import { captureSpan } from '../src/report/capture-span.js';
import type { Batch } from '../src/worker/protocol.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { Engine, SETTLE_US } from '../src/worker/engine.js';
import { SeriesBuffer } from '../src/app/live.js';
import { ReplaySource } from '../src/worker/sources/replay.js';
import { openProblem } from '../src/worker/sources/serial.js';
import { usbChunks, perByteCapture } from './feeds.js';
import { SimulatedClock } from './worker-fakes.js';

interface Collected {
  /** The final buckets. */
  series: { t: number[]; fadeRate: number[]; lost: number[]; periodMs: number[] };
  /** The buckets as the page holds them after each batch (final and provisional). */
  page: SeriesBuffer;
  /** Each batch's missed frames and fades, and the lost frames and fades the page's buckets hold then. */
  shown: { missed: number; lost: number; fades: number; fadesShown: number }[];
  episodes: Batch['episodes'];
  last: Batch | null;
}

const sum = (xs: readonly number[]): number => xs.reduce((a, b) => a + b, 0);

function collector(engine: Engine) {
  const c: Collected = {
    series: { t: [], fadeRate: [], lost: [], periodMs: [] },
    page: new SeriesBuffer(),
    shown: [],
    episodes: [],
    last: null,
  };
  const take = (now: number) => {
    const out = engine.batch(now);
    if (out === null) return;
    const s = out.batch.series;
    const n = s.settled;
    c.series.t.push(...s.t.subarray(0, n));
    c.series.fadeRate.push(...s.fadeRate.subarray(0, n));
    c.series.lost.push(...s.lost.subarray(0, n));
    c.series.periodMs.push(...s.periodMs.subarray(0, n));
    c.page.append(s);
    const link = out.batch.link;
    c.shown.push({
      missed: link.missedFrames,
      lost: sum(c.page.lost),
      fades: link.fades,
      fadesShown: Math.round(sum(c.page.fadeRate) * 0.1),
    });
    c.episodes.push(...out.batch.episodes);
    c.last = out.batch;
  };
  return { c, take };
}

/** The live path: 16 ms chunks, the worker's 50 ms idle ticks between them, and the end of the stream. */
function run(name: string, seed: number, durationUs: number) {
  const sim = simulate({ ...preset(name), seed }, durationUs, { truth: true });
  const engine = new Engine({ resolution: 'auto', jitterUs: 20_000 });
  const { c, take } = collector(engine);
  const chunks = usbChunks(sim.bytes, sim.timesUs);
  let last = chunks[0]!.timeUs;
  for (const chunk of chunks) {
    for (let t = last + 50_000; t < chunk.timeUs; t += 50_000) take(t);
    engine.push(chunk.bytes, chunk.timeUs, 0);
    take(chunk.timeUs);
    last = chunk.timeUs;
  }
  engine.end(last);
  take(last + 5_000_000);
  return { sim, engine, ...c };
}

describe('the engine', () => {
  it('sums frames into 100 ms buckets whose lost frames add up to the missed frames, each counted once', () => {
    const { sim, series, engine } = run('dropouts-failsafe', 3, 3_200_000);
    expect(series.t.every((t, i) => i === 0 || t - series.t[i - 1]! === 100_000)).toBe(true);
    const lost = series.lost.reduce((a, b) => a + b, 0);
    expect(lost).toBe(engine.link.stats.missedFrames);
    // The receiver's counter says what it missed: every frame the dropouts took, and no more than it counted.
    const truth = sim.truth!.gaps.reduce((n, g) => n + g.missedFrames, 0);
    expect(engine.link.stats.missedBasis).toBe('fade-counter');
    expect(engine.link.stats.missedFrames).toBeGreaterThanOrEqual(truth);
    expect(engine.link.stats.missedFrames).toBe(engine.link.stats.fades);
    // Frame spacing leaves the gaps out: about 11 ms.
    const periods = series.periodMs.filter(Number.isFinite);
    expect(periods.filter((p) => p > 9 && p < 13).length).toBeGreaterThan(periods.length * 0.8);
  });

  it('holds, after every batch, the missed frames and fades the counters say in the buckets the page shows', () => {
    const { shown, engine } = run('dropouts-failsafe', 3, 3_200_000);
    expect(engine.link.stats.missedFrames).toBeGreaterThan(20);
    expect(shown.filter((b) => b.missed > 0 && b.missed < engine.link.stats.missedFrames).length).toBeGreaterThan(5);
    for (const b of shown) expect({ lost: b.lost, fades: b.fadesShown }).toEqual({ lost: b.missed, fades: b.fades });
  });

  it('marks a bucket final only once missing frames can no longer be placed in it', () => {
    const sim = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 2 }, 3_000_000);
    const engine = new Engine({ resolution: 'auto', jitterUs: 20_000 });
    const { c, take } = collector(engine);
    for (const chunk of usbChunks(sim.bytes, sim.timesUs)) {
      engine.push(chunk.bytes, chunk.timeUs, 0);
      take(chunk.timeUs);
      expect(c.series.t.every((t) => t + 100_000 <= chunk.timeUs - SETTLE_US)).toBe(true);
    }
    expect(c.series.t.length).toBeGreaterThan(15);
  });

  it('reports each hold and failsafe once when it starts and once when it ends', () => {
    const { episodes, engine } = run('dropouts-failsafe', 3, 3_200_000);
    const byId = new Map<number, { kind: string; endUs: number | null }[]>();
    for (const e of episodes) byId.set(e.id, [...(byId.get(e.id) ?? []), e]);
    expect(engine.link.stats.failsafes).toBe(1);
    expect(engine.link.stats.holds).toBe(2);
    expect(byId.size).toBe(engine.link.episodes.length);
    for (const reports of byId.values()) {
      expect(reports.length).toBeLessThanOrEqual(2);
      expect(reports.at(-1)?.endUs).not.toBeNull();
    }
  });

  it('shows fades as a rate per second in the bucket they were reported', () => {
    const { series, engine } = run('fade-wrap-internal', 4, 2_000_000);
    const total = series.fadeRate.reduce((a, b) => a + b * 0.1, 0);
    expect(engine.link.stats.fades).toBeGreaterThan(5);
    expect(Math.round(total)).toBe(engine.link.stats.fades);
  });

  it('after the end, stands still: the state and clock stay as they were at the end however late the page asks', () => {
    const { engine, last } = run('dsmx-11ms-2048-internal', 5, 1_000_000);
    expect(last!.ended).toBe(true);
    expect(last!.link.state).toBe('live');
    const later = engine.batch(1e12);
    expect(later?.batch.link.state ?? 'live').toBe('live');
    expect(engine.link.stats.holds).toBe(0);
  });
});

describe('delivery stalls are not holds', () => {
  it('withdraws on the page a hold the worker showed during a stall, once the burst after it shows nothing was missing', () => {
    const sim = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 9 }, 3_000_000);
    const engine = new Engine({ resolution: 'auto', jitterUs: 20_000 });
    const { c, take } = collector(engine);
    const retracted: number[] = [];
    // The worker stalls 200 ms at 0.5 s: the chunks due meanwhile arrive together after it.
    let held: { bytes: Uint8Array; timeUs: number }[] = [];
    for (const chunk of usbChunks(sim.bytes, sim.timesUs)) {
      if (chunk.timeUs > 500_000 && chunk.timeUs < 700_000) {
        held.push(chunk);
        take(chunk.timeUs);
        retracted.push(...(c.last?.retracted ?? []));
        continue;
      }
      for (const h of held) engine.push(h.bytes, chunk.timeUs, 0);
      held = [];
      engine.push(chunk.bytes, chunk.timeUs, 0);
      take(chunk.timeUs);
      retracted.push(...(c.last?.retracted ?? []));
    }
    // It looked like a hold while it lasted; the page was told to drop it.
    expect(c.episodes.some((e) => e.kind === 'hold')).toBe(true);
    // Every hold it was shown (the one open during the stall; the silence, once the frame
    // whose bytes straddled the stall came, may show again as one that ended) is withdrawn.
    expect(retracted).toEqual([...new Set(c.episodes.map((e) => e.id))]);
    expect(engine.link.stats).toMatchObject({ holds: 0, failsafes: 0, missedFrames: 0 });
    expect(c.last!.link.holds).toBe(0);
  });
});

describe('a forced resolution is not link loss', () => {
  it('counts nothing while a forced 1024 matches no frame of a 2048 stream, says what the stream looks like, and leaves nothing after switching back', () => {
    const sim = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 6 }, 8_000_000);
    const engine = new Engine({ resolution: 'auto', jitterUs: 20_000 });
    const { c, take } = collector(engine);
    const chunks = usbChunks(sim.bytes, sim.timesUs);
    let framesWhileForced = -1;
    for (const chunk of chunks) {
      if (chunk.timeUs >= 2_000_000 && framesWhileForced < 0) {
        engine.setResolution(1024, chunk.timeUs);
        framesWhileForced = engine.decoder.stats.frames;
      }
      if (chunk.timeUs >= 5_000_000 && framesWhileForced >= 0 && engine.mismatch !== null) {
        expect(engine.decoder.stats.frames).toBe(framesWhileForced);
        expect(c.last!.mismatch).toBe(2048);
        expect(c.last!.link.state).toBe('waiting');
        engine.setResolution('auto', chunk.timeUs);
        framesWhileForced = Infinity;
      }
      engine.push(chunk.bytes, chunk.timeUs, 0);
      for (let t = chunk.timeUs; t < chunk.timeUs + 16_000; t += 8_000) take(t);
    }
    expect(framesWhileForced).toBe(Infinity);
    expect(engine.decoder.format.resolution).toBe(2048);
    expect(c.last!.mismatch).toBeNull();
    expect(c.last!.link.state).toBe('live');
    expect(engine.link.stats).toMatchObject({ holds: 0, failsafes: 0, missedFrames: engine.link.stats.fades });
    expect(engine.link.episodes).toEqual([]);
    expect(c.episodes).toEqual([]);
  });
});

function replayOf(capture: Capture, options: { untimedPeriodUs?: number } = {}) {
  const clock = new SimulatedClock();
  const positions: number[] = [];
  let ended = 0;
  const engine = new Engine({ resolution: 'auto', jitterUs: 0 });
  const r: ReplaySource = new ReplaySource(
    { capture },
    (_p, bytes, time) => engine.push(bytes, time, 0),
    (clockUs) => {
      positions.push(clockUs);
      engine.batch(r.linkNowUs(0));
    },
    () => {
      ended++;
      engine.end(r.recordedTiming ? r.endUs : Number.NaN);
    },
    { clock, ...options },
  );
  return { r, clock, positions, engine, ended: () => ended };
}

describe("replay runs on the capture's clock", () => {
  const sim = simulate({ ...preset('dropouts-failsafe'), seed: 3 }, 4_000_000);

  it('gives a Saleae export (one chunk, per-byte times) its timeline: start, end, 1× pace, seeking and full speed', () => {
    const capture = perByteCapture(sim);
    const { r, clock, positions, engine, ended } = replayOf(capture);
    expect(r.startUs).toBe(sim.timesUs[0]);
    expect(r.endUs).toBe(sim.timesUs.at(-1));
    expect(r.timed).toBe(true);
    r.play();
    clock.tick(100); // 1 s of wall time at 1×
    expect(r.positionUs - r.startUs).toBeCloseTo(1_000_000, -3);
    expect(ended()).toBe(0);
    const framesAt1s = engine.decoder.stats.frames;
    expect(framesAt1s).toBeGreaterThan(60);
    expect(framesAt1s).toBeLessThan(100);
    r.setSpeed(4);
    clock.tick(25); // 1 s more of capture
    expect(r.positionUs - r.startUs).toBeCloseTo(2_000_000, -4);
    r.seek(r.startUs + 3_000_000);
    expect(r.positionUs).toBe(r.startUs + 3_000_000);
    r.setSpeed(0);
    clock.tick(10);
    expect(ended()).toBe(1);
    expect(r.positionUs).toBe(r.endUs);
    expect(Math.max(...positions)).toBeLessThanOrEqual(r.endUs);
  });

  it('ends at the last recorded time, never past it, and freezes the state there', () => {
    const capture = perByteCapture(simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 8 }, 1_500_000));
    const { r, clock, positions, engine, ended } = replayOf(capture);
    r.play();
    clock.tick(1000);
    expect(ended()).toBe(1);
    expect(r.ended).toBe(true);
    expect(Math.max(...positions)).toBe(r.endUs);
    const atEnd = engine.batch(r.endUs + 60e6)?.batch;
    expect(atEnd?.ended ?? true).toBe(true);
    expect(engine.link.state).toBe('live');
    expect(engine.link.stats.holds).toBe(0);
  });

  it("plays a raw .bin at the receiver's pace, decoded without times: a timeline, but nothing measured from it", () => {
    const capture = importRaw(sim.bytes);
    expect(captureSpan(capture).startUs).toBeNaN();
    const { r, clock, engine, ended } = replayOf(capture, { untimedPeriodUs: 11_000 });
    expect(r.recordedTiming).toBe(false);
    expect(r.timed).toBe(true);
    expect(r.endUs).toBeCloseTo((sim.bytes.length / 16) * 11_000, -3);
    r.play();
    clock.tick(100);
    expect(engine.decoder.stats.frames).toBeGreaterThan(70);
    expect(engine.decoder.stats.frames).toBeLessThan(110);
    r.setSpeed(0);
    clock.tick(20);
    expect(ended()).toBe(1);
    // Nothing from the paced clock; the receiver's own fade count needs none.
    expect(engine.link.stats).toMatchObject({ holds: 0, failsafes: 0, missedBasis: 'fade-counter', missedFrames: engine.link.stats.fades });
    expect(engine.link.stats.periodUs).toBeNaN();
  });

  it('plays a chunk-timed recording (.sscap) from its first chunk to its last', () => {
    const chunks = usbChunks(sim.bytes, sim.timesUs);
    const capture = readCapture(
      encodeCapture(
        { baudRate: 115200 },
        chunks.map((c) => ({ type: 'data', bytes: c.bytes, timeUs: c.timeUs, port: 0 })),
      ),
      'x.sscap',
    );
    const { r } = replayOf(capture);
    expect(r.endUs).toBe(chunks.at(-1)!.timeUs);
    expect(r.startUs).toBeLessThan(chunks[0]!.timeUs);
  });
});

describe('a seek', () => {
  /** 20 minutes of 4-byte chunks every 100 ms on two ports, read by index: what the replay feeds is what matters here. */
  function longCapture(times?: (t: Float64Array) => void): Capture {
    const n = 2 * 12_000;
    const chunkTimesUs = Float64Array.from({ length: n }, (_, i) => 1_000_000 + Math.floor(i / 2) * 100_000 + (i % 2));
    times?.(chunkTimesUs);
    return {
      kind: 'sscap',
      meta: {},
      timing: 'per-chunk',
      bytes: new Uint8Array(4 * n),
      chunkEnds: Uint32Array.from({ length: n }, (_, i) => 4 * (i + 1)),
      chunkTimesUs,
      chunkPorts: Uint8Array.from({ length: n }, (_, i) => i % 2),
      events: [],
      issues: [],
    };
  }

  /** The capture's chunk number each port is first fed after a seek to `targetUs`. */
  function firstFed(capture: Capture, targetUs: number): number[] {
    const first: number[] = [];
    const r = new ReplaySource(
      { capture },
      (port, bytes) => {
        first[port] ??= bytes.byteOffset / 4;
      },
      () => undefined,
      () => undefined,
      { clock: new SimulatedClock() },
    );
    r.seek(targetUs);
    return first;
  }

  /** What a walk from each port's first chunk finds: its first chunk at or after `fromUs`. */
  function walk(capture: Capture, fromUs: number): number[] {
    return [0, 1].map((port) => {
      for (let i = 0; i < capture.chunkPorts.length; i++)
        if (capture.chunkPorts[i] === port && !(capture.chunkTimesUs[i]! < fromUs)) return i;
      return -1;
    });
  }

  it('reads the clock once every 64 chunks it feeds, and hands each chunk the latest reading as when it was fed', () => {
    const capture = longCapture();
    const clock = new SimulatedClock();
    const readings: number[] = [];
    const now = clock.now.bind(clock);
    clock.now = () => {
      readings.push(now());
      return readings.at(-1)!;
    };
    const fedAt: number[] = [];
    const r = new ReplaySource(
      { capture },
      (_p, _b, _t, _at, fedAtMs) => fedAt.push(fedAtMs),
      () => undefined,
      () => undefined,
      { clock },
    );
    readings.length = 0;
    r.seek(15 * 60e6);
    // Ten minutes of both ports at 10 chunks a second; the seek reads the clock as it starts,
    // every 64 chunks (or ports' ends) it goes through, and once more for where playing resumes.
    expect(fedAt.length).toBe(12_001);
    expect(readings.length).toBeGreaterThanOrEqual(2 + Math.floor(fedAt.length / 64));
    expect(readings.length).toBeLessThanOrEqual(3 + Math.floor(fedAt.length / 64));
    expect(fedAt[0]).toBe(readings[0]);
    expect(fedAt.every((t, k) => readings.includes(t) && t >= (fedAt[k - 1] ?? 0))).toBe(true);
    expect(new Set(fedAt).size).toBe(readings.length - 1);
  });

  it('feeds each port from its first chunk within the ten minutes before the target', () => {
    const capture = longCapture();
    const target = 15 * 60e6;
    const first = firstFed(capture, target);
    expect(first).toEqual(walk(capture, target - 10 * 60e6));
    expect(capture.chunkTimesUs[first[0]!]).toBe(5 * 60e6);
    expect(firstFed(capture, 2_000_000)).toEqual([0, 1]);
  });

  it("feeds a logic analyser's capture (one chunk of per-byte times a port) from its first byte in the ten minutes, not from its start", () => {
    // 20 minutes, a byte every 10 ms on each port, every byte timed.
    const n = 120_000;
    const byteTimesUs = new Float64Array(2 * n);
    for (let p = 0; p < 2; p++) for (let j = 0; j < n; j++) byteTimesUs[p * n + j] = 1_000_000 + j * 10_000 + p;
    const capture: Capture = {
      kind: 'saleae-csv',
      meta: {},
      timing: 'per-byte',
      bytes: new Uint8Array(2 * n),
      chunkEnds: Uint32Array.of(n, 2 * n),
      chunkTimesUs: Float64Array.of(byteTimesUs[n - 1]!, byteTimesUs[2 * n - 1]!),
      chunkPorts: Uint8Array.of(0, 1),
      byteTimesUs,
      events: [],
      issues: [],
    };
    const fed: number[] = [];
    const r = new ReplaySource(
      { capture },
      (port, bytes) => {
        fed[port] ??= bytes.byteOffset;
      },
      () => undefined,
      () => undefined,
      { clock: new SimulatedClock() },
    );
    r.seek(15 * 60e6);
    const from = 5 * 60e6;
    const walk = (p: number) => byteTimesUs.findIndex((t, j) => j >= p * n && !(t < from));
    expect(fed).toEqual([walk(0), walk(1)]);
    expect(byteTimesUs[fed[0]!]).toBe(from);
  });

  it('finds the same chunks as a walk from the start when recorded times go back', () => {
    // A chunk at 1 min stamped 15 min (a clock that jumped): a walk stops there, and so does the seek.
    const capture = longCapture((t) => {
      t[2 * 590] = 15 * 60e6;
    });
    const target = 15 * 60e6;
    const first = firstFed(capture, target);
    expect(first).toEqual(walk(capture, target - 10 * 60e6));
    expect(first[0]).toBe(2 * 590);
  });
});

describe('port errors', () => {
  it('explains a busy port, a refusal and anything else in terms of what to do', () => {
    const busy = new Error('Failed to open serial port.');
    busy.name = 'NetworkError';
    expect(openProblem(busy).title).toBe('The port is busy');
    expect(openProblem(busy).detail).toMatch(/Close it, then connect again/);
    const refused = new Error('denied');
    refused.name = 'SecurityError';
    expect(openProblem(refused).title).toBe('Permission refused');
    expect(openProblem(new TypeError('odd')).detail).toBe('TypeError: odd');
  });
});
