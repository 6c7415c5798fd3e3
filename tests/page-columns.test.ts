import { describe, expect, it } from 'vitest';
import { AlignedColumns } from '../src/app/components/Remotes/columns.js';
import { SeriesBuffer } from '../src/app/live.js';
import type { Batch } from '../src/worker/protocol.js';

/** A batch's series of `n` 100 ms buckets from `fromUs`, fade rate `rate(i)` (NaN: no value), the last `open` of them provisional. */
function buckets(fromUs: number, n: number, rate: (i: number) => number = (i) => i, open = 0): Batch['series'] {
  const t = Float64Array.from({ length: n }, (_, i) => fromUs + i * 100_000);
  const fadeRate = Float32Array.from({ length: n }, (_, i) => rate(i));
  return {
    settled: n - open,
    t,
    fadeRate,
    rssi: new Float32Array(n).fill(Number.NaN),
    periodMs: new Float32Array(n).fill(11),
    lost: new Float32Array(n),
  };
}

describe('the graph series of a remote', () => {
  it('appends buckets once, in seconds, with a bucket without a value as a gap (null)', () => {
    const s = new SeriesBuffer();
    const batch = buckets(1_000_000, 3);
    batch.periodMs[1] = Number.NaN;
    s.append(batch);
    expect(s.t).toEqual([1, 1.1, 1.2]);
    expect(s.fadeRate).toEqual([0, 1, 2]);
    expect(s.periodMs).toEqual([11, null, 11]);
    expect(s.rssi).toEqual([null, null, null]);
    expect(s.appended).toBe(3);
    expect(s.indexAt(1.05)).toBe(1);
  });

  it("replaces the provisional buckets with the next batch's, and counts only final ones as appended", () => {
    const s = new SeriesBuffer();
    s.append(buckets(0, 4, () => 1, 2));
    expect(s.t).toEqual([0, 0.1, 0.2, 0.3]);
    expect([s.appended, s.provisional]).toEqual([2, 2]);
    // The open buckets again, one now final and changed, and one more open.
    s.append(buckets(200_000, 3, () => 5, 2));
    expect(s.t).toEqual([0, 0.1, 0.2, 0.3, 0.4]);
    expect(s.fadeRate).toEqual([1, 1, 5, 5, 5]);
    expect([s.appended, s.provisional]).toEqual([3, 2]);
    expect(s.unreadSince(2)).toBe(3);
    s.clear();
    expect([s.length, s.appended, s.provisional]).toEqual([0, 0, 0]);
  });

  it('keeps the same arrays as it grows, and drops what is older than ten minutes in one step', () => {
    const s = new SeriesBuffer();
    const column = s.t;
    for (let k = 0; k < 75; k++) s.append(buckets(k * 10_000_000, 100));
    expect(s.length).toBe(7500);
    s.append(buckets(750_000_000, 100));
    expect(s.t).toBe(column);
    expect(s.appended).toBe(7600);
    expect(s.length).toBe(6000);
    expect(s.t[s.length - 1]).toBeCloseTo(759.9, 6);
    expect(s.lost.length).toBe(6000);
  });
});

describe('the remotes on one time axis', () => {
  it('puts every remote on one bucket grid, a gap where a remote sent no bucket', () => {
    const a = new SeriesBuffer();
    const b = new SeriesBuffer();
    a.append(buckets(0, 4, () => 1));
    b.append(buckets(200_000, 3, () => 2));
    const cols = new AlignedColumns(2);
    cols.update([a, b]);
    expect(cols.x.map((x) => Math.round(x * 10))).toEqual([0, 1, 2, 3, 4]);
    expect(cols.columns).toEqual([
      [1, 1, 1, 1, null],
      [null, null, 2, 2, 2],
    ]);
  });

  it('takes only what is new on the next update, and grows to the left for a remote that starts earlier', () => {
    const a = new SeriesBuffer();
    const b = new SeriesBuffer();
    a.append(buckets(500_000, 2, () => 1));
    const cols = new AlignedColumns(2);
    cols.update([a, b]);
    const x = cols.x;
    a.append(buckets(700_000, 1, () => 3));
    b.append(buckets(300_000, 2, () => 2));
    cols.update([a, b]);
    expect(cols.x).toBe(x);
    expect(cols.x.map((v) => Math.round(v * 10))).toEqual([3, 4, 5, 6, 7]);
    expect(cols.columns).toEqual([
      [null, null, 1, 1, 3],
      [2, 2, null, null, null],
    ]);
  });

  it("reads a remote's provisional buckets again when the next batch replaced them", () => {
    const a = new SeriesBuffer();
    a.append(buckets(0, 3, () => 1, 2));
    const cols = new AlignedColumns(1);
    cols.update([a]);
    expect(cols.columns).toEqual([[1, 1, 1]]);
    a.append(buckets(100_000, 3, (i) => 4 + i, 1));
    cols.update([a]);
    expect(cols.columns).toEqual([[1, 4, 5, 6]]);
  });

  it('starts over when a remote is cleared or replaced, so nothing of the old source stays', () => {
    const a = new SeriesBuffer();
    const b = new SeriesBuffer();
    a.append(buckets(0, 3, () => 1));
    b.append(buckets(0, 3, () => 2));
    const cols = new AlignedColumns(2);
    cols.update([a, b]);
    a.clear();
    a.append(buckets(5_000_000, 1, () => 7));
    const fresh = new SeriesBuffer();
    fresh.append(buckets(5_000_000, 1, () => 8));
    cols.update([a, fresh]);
    expect(cols.x.map((v) => Math.round(v * 10))).toEqual([50]);
    expect(cols.columns).toEqual([[7], [8]]);
  });
});
