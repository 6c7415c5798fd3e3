/** The link monitor: the failsafe state machine of spec §7.1, episodes, period, missed frames. */
import { describe, expect, it } from 'vitest';
import { LinkMonitor, type DecodedFrame } from '../src/decoder/index.js';

/** A stand-in frame: only what the monitor reads. */
function frame(timeUs: number, fadesDelta = 0, system: number | null = 0xb2): DecodedFrame {
  return { timeUs, fadesDelta, system, rssi: null } as DecodedFrame;
}

describe('LinkMonitor', () => {
  it('goes live on a frame, holds after 40 ms without one, fails safe after 1 s, and is live again on the next', () => {
    const link = new LinkMonitor();
    expect(link.state).toBe('waiting');
    for (let t = 0; t <= 110_000; t += 11_000) link.frame(frame(t));
    expect(link.state).toBe('live');
    expect(link.update(110_000 + 39_000)).toBe('live');
    expect(link.update(110_000 + 41_000)).toBe('hold');
    expect(link.update(110_000 + 999_000)).toBe('hold');
    expect(link.update(110_000 + 1_000_000)).toBe('failsafe');
    link.frame(frame(1_500_000));
    expect(link.state).toBe('live');
    expect(link.stats).toMatchObject({ holds: 1, failsafes: 1 });
    expect(link.episodes.map((e) => [e.id, e.kind, e.startUs, e.endUs])).toEqual([
      [0, 'hold', 110_000 + 40_000, 110_000 + 1_000_000],
      [1, 'failsafe', 110_000 + 1_000_000, 1_500_000],
    ]);
  });

  it('opens the episodes of a gap even when nothing called update() during it', () => {
    const link = new LinkMonitor();
    link.frame(frame(0));
    link.frame(frame(11_000));
    link.frame(frame(2_011_000));
    expect(link.episodes.map((e) => e.kind)).toEqual(['hold', 'failsafe']);
    expect(link.stats.longestGapUs).toBe(2_000_000);
    expect(link.stats.missedFrames).toBe(181);
  });

  it('measures the period over the window and snaps it to 11 or 22 ms without a system byte', () => {
    const link = new LinkMonitor();
    // Five frames lost right after the start must not fix the period at 22 ms.
    let t = 0;
    link.frame(frame(t, 0, null));
    t += 6 * 11_000;
    for (let i = 0; i < 60; i++, t += 11_000) link.frame(frame(t, 0, null));
    expect(link.stats.nominalPeriodUs).toBe(11_000);
    expect(link.stats.periodUs).toBeCloseTo(11_000, 0);
  });

  it('keeps at most maxEpisodes episodes while the counts go on', () => {
    const link = new LinkMonitor({ maxEpisodes: 10 });
    let t = 0;
    for (let i = 0; i < 100; i++) {
      link.frame(frame(t));
      link.frame(frame((t += 11_000)));
      t += 60_000; // a hold each time
    }
    link.frame(frame(t));
    expect(link.stats.holds).toBe(100);
    expect(link.episodes.length).toBeLessThanOrEqual(13);
    expect(link.episodes.at(-1)?.id).toBe(99);
  });

  it('rejects durations that are not finite numbers ≥ 0', () => {
    expect(() => new LinkMonitor({ holdAfterUs: -1 })).toThrow(TypeError);
    expect(() => new LinkMonitor({ maxEpisodes: Number.NaN })).toThrow(/maxEpisodes/);
  });
});
