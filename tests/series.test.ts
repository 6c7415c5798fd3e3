/**
 * The binned series of a link (src/analysis/series.ts), column by column: every bin's frames,
 * fades, lost frames, RSSI and intervals are the plain sums of what the monitor decided for
 * each frame, in the bin the frame's time falls in, whenever the series is read (in the middle
 * of a bin too) and in its checkpoint.
 */
import { describe, expect, it } from 'vitest';
import { LinkSeries, monitorWithSeries } from '../src/analysis/index.js';
import { type DecodedFrame, LinkMonitor, SpektrumDecoder } from '../src/decoder/index.js';
import { preset, simulate } from '../src/simulator/index.js';

/** Each bin's sums, kept by hand: what the series must hold. */
class PlainSums {
  readonly bins = new Map<number, { frames: number; fades: number; lost: number; rssi: number[]; intervals: number[] }>();
  at(b: number) {
    let bin = this.bins.get(b);
    if (bin === undefined) {
      bin = { frames: 0, fades: 0, lost: 0, rssi: [], intervals: [] };
      this.bins.set(b, bin);
    }
    return bin;
  }
}

/** The series' bins as its readers give them, and its checkpoint's columns, bins `[0, n)`. */
function read(series: LinkSeries, n: number) {
  return Array.from({ length: n }, (_, i) => ({
    i,
    frames: series.frames(i),
    fades: series.fades(i),
    lost: series.lost(i),
    rssiMean: series.rssiMean(i),
    rssiMin: series.rssiMin(i),
    intervalMean: series.intervalMean(i),
  }));
}

function want(sums: PlainSums, n: number) {
  const mean = (xs: number[]) => (xs.length === 0 ? Number.NaN : xs.reduce((a, b) => a + b, 0) / xs.length);
  return Array.from({ length: n }, (_, i) => {
    const bin = sums.bins.get(i) ?? { frames: 0, fades: 0, lost: 0, rssi: [], intervals: [] };
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
  const bins = Array.from({ length: n }, (_, i) => sums.bins.get(i) ?? { frames: 0, fades: 0, lost: 0, rssi: [], intervals: [] });
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
          expect(read(series, n)).toEqual(want(sums, n));
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
    const sim = simulate(preset('rssi-spm4649t'), 3_000_000);
    const decoder = new SpektrumDecoder();
    decoder.push(sim.bytes, sim.timesUs);
    decoder.end();
    const frames: DecodedFrame[] = [];
    for (let f = decoder.next(); f; f = decoder.next()) frames.push({ ...f });
    const whole = new LinkSeries(250_000, 0);
    const link = monitorWithSeries({}, whole);
    const half = frames.length >> 1;
    let cp: ReturnType<LinkSeries['checkpoint']> | null = null;
    let linkCp: ReturnType<typeof link.checkpoint> | null = null;
    frames.forEach((f, k) => {
      link.frame(f);
      whole.frame(f, link);
      if (k === half) {
        cp = structuredClone(whole.checkpoint());
        linkCp = structuredClone(link.checkpoint());
      }
    });
    expect(whole.binOf(frames[half]?.timeUs ?? 0)).toBe(whole.binOf(frames[half + 1]?.timeUs ?? 0));
    const resumed = new LinkSeries(250_000, 0);
    resumed.restore(cp as unknown as ReturnType<LinkSeries['checkpoint']>);
    const relink = monitorWithSeries({}, resumed);
    relink.restore(linkCp as unknown as ReturnType<typeof link.checkpoint>);
    for (const f of frames.slice(half + 1)) {
      relink.frame(f);
      resumed.frame(f, relink);
    }
    expect(resumed.checkpoint()).toEqual(whole.checkpoint());
    expect(read(resumed, resumed.bins)).toEqual(read(whole, whole.bins));
  });
});
