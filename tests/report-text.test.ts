/** The clock every surface writes capture times in (info, report, doctor, the replay bar). */
import { describe, expect, it } from 'vitest';
import { formatClock } from '../src/report/report-text.js';

describe('formatClock', () => {
  it('rounds to a tenth before it splits minutes and seconds: never 0:010.0 or 0:60.0', () => {
    expect(formatClock(3.2e6)).toBe('0:03.2');
    expect(formatClock(9.94e6)).toBe('0:09.9');
    expect(formatClock(9.96e6)).toBe('0:10.0');
    expect(formatClock(59.96e6)).toBe('1:00.0');
    expect(formatClock(61.25e6)).toBe('1:01.3');
    expect(formatClock(3723e6)).toBe('1:02:03');
    expect(formatClock(-5)).toBe('0:00.0');
    expect(formatClock(Number.NaN)).toBe('?');
  });

  it('reads every tenth of the first ten minutes as m:ss.s, in order', () => {
    let previous = '';
    for (let tenth = 0; tenth < 6000; tenth++) {
      const text = formatClock(tenth * 1e5 + 40_000);
      expect(text).toMatch(/^\d+:[0-5]\d\.\d$/);
      expect(text > previous || text.length > previous.length).toBe(true);
      previous = text;
    }
  });
});
