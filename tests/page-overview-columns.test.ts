/**
 * The replay timeline's overview in the columns it is drawn in (ReplayBar/columns.ts): each
 * column the worst second of the bins in it, never a value no second had; a short overview
 * drawn bin by bin; a growing one keeping its columns.
 */
import { describe, expect, it } from 'vitest';
import { overviewColumns } from '../src/app/components/ReplayBar/columns.js';
import type { Overview } from '../src/worker/protocol.js';

/** `n` one-second bins from `fromS`: lost and fade rate from the seed, some fade rates NaN. */
function overview(n: number, fromS = 1000, seed = 1): Overview {
  let s = seed;
  const next = (k: number): number => {
    s = (s * 1103515245 + 12345) >>> 0;
    return s % k;
  };
  return {
    t: Float64Array.from({ length: n }, (_, b) => (fromS + b) * 1e6),
    binUs: 1e6,
    lost: Float32Array.from({ length: n }, () => (next(50) === 0 ? next(90) : 0)),
    fadeRate: Float32Array.from({ length: n }, () => (next(30) === 0 ? Number.NaN : next(7) === 0 ? next(40) / 4 : 0)),
    failsafe: [],
    readUntilUs: (fromS + n) * 1e6,
    complete: true,
  };
}

/** The largest of `values`, NaN ignored (NaN when all are). */
function most(values: number[]): number {
  const real = values.filter((v) => !Number.isNaN(v));
  return real.length === 0 ? Number.NaN : Math.max(...real);
}

describe('the overview in the timeline’s columns', () => {
  it('is the bins themselves when there are no more bins than columns', () => {
    const o = overview(600);
    expect(overviewColumns(o, 1200, 1000, 1600)).toEqual({
      x: Array.from(o.t, (t) => t / 1e6),
      lost: Array.from(o.lost),
      fadeRate: Array.from(o.fadeRate),
    });
  });

  it('shows each column’s worst second: its most frames lost and highest fade rate, each a bin’s own', () => {
    for (const [n, columns] of [
      [86_400, 1000],
      [86_400, 2560],
      [3_601, 777],
    ] as const) {
      const o = overview(n, 5000, n + columns);
      const got = overviewColumns(o, columns, 5000, 5000 + n);
      expect(got.x.length).toBeLessThanOrEqual(columns);
      expect(got.x.length).toBeGreaterThan(columns * 0.95);
      // The same columns worked out bin by bin: which column each bin's start falls in.
      const byColumn = new Map<number, number[]>();
      for (let b = 0; b < n; b++) {
        const c = Math.floor((b / n) * columns);
        const bins = byColumn.get(c);
        if (bins === undefined) byColumn.set(c, [b]);
        else bins.push(b);
      }
      const want = [...byColumn.values()];
      expect(got.x).toEqual(want.map((bins) => (o.t[bins[0] ?? 0] ?? 0) / 1e6));
      expect(got.lost).toEqual(want.map((bins) => most(bins.map((b) => o.lost[b] ?? 0))));
      expect(got.fadeRate).toEqual(want.map((bins) => most(bins.map((b) => o.fadeRate[b] ?? 0))));
      // Nothing drawn that no second had, and the worst second of all still there.
      expect(Math.max(...got.lost)).toBe(Math.max(...o.lost));
      const rates = new Set(o.fadeRate);
      expect(got.fadeRate.filter((v) => !Number.isNaN(v) && !rates.has(v))).toEqual([]);
    }
  });

  it('keeps its columns while the overview grows', () => {
    const whole = overview(86_400);
    const full = overviewColumns(whole, 1000, 1000, 87_400);
    const part: Overview = {
      ...whole,
      t: whole.t.subarray(0, 40_000),
      lost: whole.lost.subarray(0, 40_000),
      fadeRate: whole.fadeRate.subarray(0, 40_000),
    };
    const grown = overviewColumns(part, 1000, 1000, 87_400);
    const k = grown.x.length - 1;
    // Every column but the last, still filling, is the whole overview's.
    expect(grown.x.slice(0, k)).toEqual(full.x.slice(0, k));
    expect(grown.lost.slice(0, k)).toEqual(full.lost.slice(0, k));
    expect(grown.fadeRate.slice(0, k)).toEqual(full.fadeRate.slice(0, k));
  });
});
