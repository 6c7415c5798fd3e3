/**
 * The binned series of a link (src/report/series.ts), column by column: every bin's frames,
 * fades, lost frames, RSSI and intervals are the plain sums of what the monitor decided for
 * each frame, in the bin the frame's time falls in, whenever the series is read (in the middle
 * of a bin too) and in its checkpoint.
 */
import { describe, expect, it } from 'vitest';
import { LinkSeries, monitorWithSeries } from '../src/report/series.js';
import type { DecodedFrame } from '../src/decoder/types.js';
import { LinkMonitor } from '../src/decoder/link.js';
import { SpektrumDecoder } from '../src/decoder/decoder.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';

type Sums = { frames: number; fades: number; lost: number; rssi: number[]; intervals: number[] };

/** Each bin's sums, kept by hand: what the series must hold. */
class PlainSums {
  readonly #bins = new Map<number, Sums>();
  /** Bin `b`'s sums, to add to. */
  at(b: number): Sums {
    let bin = this.#bins.get(b);
    if (bin === undefined) {
      bin = PlainSums.empty();
      this.#bins.set(b, bin);
    }
    return bin;
  }
  /** Bin `b`'s sums, to read (none added yet: all zero). */
  of(b: number): Sums {
    return this.#bins.get(b) ?? PlainSums.empty();
  }
  static empty(): Sums {
    return { frames: 0, fades: 0, lost: 0, rssi: [], intervals: [] };
  }
}

const READERS = ['frames', 'fades', 'lost', 'rssiMean', 'rssiMin', 'intervalMean'] as const;

/**
 * The series' bins as its readers give them, bins `[0, n)`, reader `first` over every bin
 * before the others (each reader must see what was added since the last read on its own).
 */
function read(series: LinkSeries, n: number, first = 0) {
  const order = [...READERS.slice(first % READERS.length), ...READERS.slice(0, first % READERS.length)];
  const bins = Array.from({ length: n }, (_, i) => ({ i }) as { i: number } & Record<(typeof READERS)[number], number>);
  for (const name of order) for (const bin of bins) bin[name] = series[name](bin.i);
  return bins;
}

function want(sums: PlainSums, n: number) {
  const mean = (xs: number[]) => (xs.length === 0 ? Number.NaN : xs.reduce((a, b) => a + b, 0) / xs.length);
  return Array.from({ length: n }, (_, i) => {
    const bin = sums.of(i);
    return {
      i,
      frames: bin.frames,
      fades: bin.fades,
      lost: bin.lost,
      rssiMean: mean(bin.rssi),
      rssiMin: bin.rssi.length === 0 ? Number.NaN : Math.min(...bin.rssi),
      intervalMean: mean(bin.intervals),
    };
  });
}

/** The checkpoint's columns as the plain sums have them: frames, fades, lost, RSSI sum, count and minimum, interval sum and count. */
function wantColumns(sums: PlainSums, n: number): number[][] {
  const bins = Array.from({ length: n }, (_, i) => sums.of(i));
  const sum = (xs: number[]) => xs.reduce((a, b) => a + b, 0);
  return [
    bins.map((b) => b.frames),
    bins.map((b) => b.fades),
    bins.map((b) => b.lost),
    bins.map((b) => sum(b.rssi)),
    bins.map((b) => b.rssi.length),
    bins.map((b) => (b.rssi.length === 0 ? Number.POSITIVE_INFINITY : Math.min(...b.rssi))),
    bins.map((b) => sum(b.intervals)),
    bins.map((b) => b.intervals.length),
  ];
}

describe('the binned series of a link', () => {
  for (const name of ['rssi-spm4649t', 'dropouts-failsafe', 'dsm2-22ms-1024-external'])
    it(`holds in every column of every bin the plain sums of what the monitor decided, read at any moment (${name})`, () => {
      const sim = simulate(preset(name), 4_000_000);
      const binUs = 100_000;
      const series = new LinkSeries(binUs, 0);
      const sums = new PlainSums();
      // The missed frames go into the plain sums too, one a period apart from where the first was due.
      const link = new LinkMonitor({
        onMissed: (fromUs, toUs, count, periodUs) => {
          series.missed(fromUs, toUs, count, periodUs);
          for (let k = 0; k < count; k++) sums.at(Math.floor(Math.min(fromUs + k * periodUs, toUs) / binUs)).lost++;
        },
      });
      const decoder = new SpektrumDecoder();
      let frames = 0;
      let reads = 0;
      let lostSeen = 0;
      const feed = (f: DecodedFrame): void => {
        link.frame(f);
        series.frame(f, link);
        const bin = sums.at(Math.floor(f.timeUs / binUs));
        bin.frames++;
        bin.fades += link.lastFades;
        if (f.rssi !== null && f.rssi !== -128) bin.rssi.push(f.rssi);
        if (Number.isFinite(link.lastIntervalUs)) bin.intervals.push(link.lastIntervalUs);
        frames++;
        // Read now and then, mostly in the middle of a bin: what is read is what was summed so far.
        if (frames % 23 === 0) {
          reads++;
          const n = series.bins;
          lostSeen = Math.max(lostSeen, ...Array.from({ length: n }, (_, i) => series.lost(i)));
          expect(read(series, n, reads)).toEqual(want(sums, n));
          expect(series.checkpoint().columns.map((c) => Array.from(c))).toEqual(wantColumns(sums, n));
        }
      };
      for (let at = 0; at < sim.bytes.length; at += 64) {
        const end = Math.min(sim.bytes.length, at + 64);
        decoder.push(sim.bytes.subarray(at, end), sim.timesUs.subarray(at, end));
        for (let f = decoder.next(); f; f = decoder.next()) feed(f);
      }
      decoder.end();
      for (let f = decoder.next(); f; f = decoder.next()) feed(f);
      const n = series.bins;
      expect(read(series, n)).toEqual(want(sums, n));
      expect(series.checkpoint().columns.map((c) => Array.from(c))).toEqual(wantColumns(sums, n));
      // The streams hold what the columns turn on.
      expect(frames).toBeGreaterThan(150);
      expect(reads).toBeGreaterThan(4);
      if (name === 'rssi-spm4649t') expect(want(sums, n).some((b) => Number.isFinite(b.rssiMin))).toBe(true);
      if (name === 'dropouts-failsafe') expect(lostSeen).toBeGreaterThan(0);
      expect(want(sums, n).some((b) => Number.isFinite(b.intervalMean))).toBe(true);
    });

  it('restored from a checkpoint taken in the middle of a bin, goes on as the series it was taken from', () => {
    // A frame every 11 ms with an RSSI that falls, then rises, in each 250 ms bin, and an interval
    // that is never a whole number of µs: each bin's minimum and sums depend on both halves.
    const frames = Array.from(
      { length: 200 },
      (_, k) =>
        ({
          timeUs: k * 11_000.37,
          fadesDelta: k % 9 === 0 ? 1 : 0,
          system: 0xb2,
          rssi: -40 - Math.abs(11 - (k % 23)) * 3,
          fades: 0,
        }) as DecodedFrame,
    );
    const whole = new LinkSeries(250_000, 0);
    const link = monitorWithSeries({}, whole);
    const taken = new Map<number, { series: ReturnType<LinkSeries['checkpoint']>; link: ReturnType<LinkMonitor['checkpoint']> }>();
    const points = [30, 57, 101, 149];
    frames.forEach((f, k) => {
      link.frame(f);
      whole.frame(f, link);
      if (points.includes(k)) taken.set(k, structuredClone({ series: whole.checkpoint(), link: link.checkpoint() }));
    });
    const end = whole.checkpoint();
    const seen = read(whole, whole.bins);
    for (const k of points) {
      // Mid-bin: the frame after the checkpoint is in the same bin.
      expect(whole.binOf(frames[k]?.timeUs ?? 0)).toBe(whole.binOf(frames[k + 1]?.timeUs ?? 0));
      // Into a new series, and back into the one it was taken from (a seek back).
      for (const series of [new LinkSeries(250_000, 0), whole]) {
        const cp = taken.get(k);
        if (cp === undefined) throw new Error('no checkpoint');
        series.restore(cp.series);
        const relink = monitorWithSeries({}, series);
        relink.restore(cp.link);
        for (const f of frames.slice(k + 1)) {
          relink.frame(f);
          series.frame(f, relink);
        }
        expect({ k, cp: series.checkpoint() }).toEqual({ k, cp: end });
        expect({ k, read: read(series, series.bins, k) }).toEqual({ k, read: seen });
      }
    }
  });
});
