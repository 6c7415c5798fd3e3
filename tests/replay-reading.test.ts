import { describe, expect, it } from 'vitest';
import { readingPercent } from '../src/app/components/ReplayBar/reading.js';

const HOUR = 3600e6;

describe('how much of a capture the replay bar says has been read', () => {
  it('says 1.7 % (not 0 %) when 1.7 % of a long capture is read and drawn', () => {
    expect(readingPercent(1e6 + 0.017 * HOUR, 1e6, 1e6 + HOUR)).toBe('1.7 %');
  });

  it('rounds down, with one decimal under 10 % and whole per cent above', () => {
    expect(readingPercent(0.0999 * HOUR, 0, HOUR)).toBe('9.9 %');
    expect(readingPercent(0.1 * HOUR, 0, HOUR)).toBe('10 %');
    expect(readingPercent(0.4299 * HOUR, 0, HOUR)).toBe('42 %');
    expect(readingPercent(0.9999 * HOUR, 0, HOUR)).toBe('99 %');
  });

  it('says "< 0.1 %" once anything is read, and 0 % only before anything is', () => {
    expect(readingPercent(0.0001 * HOUR, 0, HOUR)).toBe('< 0.1 %');
    expect(readingPercent(0, 0, HOUR)).toBe('0 %');
    expect(readingPercent(-5, 0, HOUR)).toBe('0 %');
  });

  it('never says more than all of it, nor divides by an empty span', () => {
    expect(readingPercent(2 * HOUR, 0, HOUR)).toBe('100 %');
    expect(readingPercent(5, 5, 5)).toBe('0 %');
  });
});
