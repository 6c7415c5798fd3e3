/**
 * The replay timeline in proportion: a short capture's overview in bins narrow enough to draw a
 * hold as long as it was, a long one's in seconds, and a time axis counted from the capture's
 * start in round steps, whatever its length.
 */
import { describe, expect, it } from 'vitest';
import { elapsedLabel } from '../src/app/axes.js';
import { BIN_US, overviewBinUs } from '../src/worker/replay/overview.js';

describe('the replay timeline', () => {
  it('bins a capture in the narrowest round width that keeps it to 2000 bins, a second at most up to three days, and wider bins past that', () => {
    expect(overviewBinUs(740_000)).toBe(20_000);
    expect(overviewBinUs(40e6)).toBe(20_000);
    expect(overviewBinUs(41e6)).toBe(50_000);
    expect(overviewBinUs(600e6)).toBe(500_000);
    expect(overviewBinUs(86_400e6)).toBe(BIN_US);
    expect(overviewBinUs(3 * 86_400e6)).toBe(BIN_US);
    expect(overviewBinUs(7 * 86_400e6)).toBe(5e6);
    expect(overviewBinUs(365 * 86_400e6)).toBe(60e6);
    expect(overviewBinUs(Number.NaN)).toBe(BIN_US);
    for (const span of [1e3, 1e5, 3.3e6, 1e8, 1e9, 1e11, 1e12, 1e13])
      expect(span / overviewBinUs(span)).toBeLessThanOrEqual(Math.max(2000, Math.min(span / BIN_US, 1 << 18), span / 60e6));
  });

  it('labels time since the start in the step it counts in', () => {
    expect(elapsedLabel(0, 0.1)).toBe('0.0 s');
    expect(elapsedLabel(0.30000000000000004, 0.1)).toBe('0.3 s');
    expect(elapsedLabel(0.25, 0.25)).toBe('0.25 s');
    expect(elapsedLabel(12, 2)).toBe('12 s');
    expect(elapsedLabel(90, 30)).toBe('1:30');
    expect(elapsedLabel(7500, 900)).toBe('2:05:00');
  });
});
