/**
 * Where an external remote's frames start is not proven (`format.alignmentUnproven`, see
 * decoder.shifted.test.ts): the doctor, `satscope info` and the page say so, lower what they
 * claim about the remote, and say what would decide it (move a stick).
 */
import { describe, expect, it } from 'vitest';
import { formatSummary } from '../src/cli/format.js';
import { doctorCapture } from '../src/report/doctor-capture.js';
import { summarizeCapture } from '../src/report/summary.js';
import { simulate } from '../src/simulator/simulator.js';
import { recording } from './feeds.js';

const still = Object.fromEntries(Array.from({ length: 20 }, (_, id) => [id, { kind: 'fixed', percent: id === 0 ? -100 : 0 } as const]));

describe('the doctor on an unproven alignment', () => {
  it('says the frames may be misread, what would decide it, and calls nothing about the remote certain', () => {
    const sim = simulate(
      {
        system: 0xa2,
        remote: 'external',
        channels: 7,
        fades: { start: 1000, lossRate: 0, randomRate: 0 },
        motion: still,
        damage: { startMidFrame: 5 },
      },
      3_000_000,
    );
    const r = doctorCapture(recording([sim]));
    const f = r.findings.find((x) => x.code === 'alignment-unproven');
    expect(f?.confidence).toBe('certain');
    expect(f?.todo.join(' ')).toMatch(/Move each stick/);
    for (const x of r.findings) if (x.code !== 'alignment-unproven') expect(x.confidence, x.code).not.toBe('certain');
  });
});

describe('satscope info on an unproven alignment', () => {
  it('says how many frames were read unproven, and whether it was proven later', () => {
    const held = simulate(
      {
        system: 0xa2,
        remote: 'external',
        channels: 7,
        fades: { start: 1000, lossRate: 0, randomRate: 0 },
        motion: still,
        damage: { startMidFrame: 5 },
      },
      3_000_000,
    );
    const s = summarizeCapture(recording([held]));
    expect(s.format.alignmentUnproven).toBe(true);
    expect(s.unprovenFrames).toBe(s.decoder.frames);
    expect(formatSummary(s, 'held.sscap')).toMatch(/Alignment +not yet proven in \d+ frames: .*move each stick/);
    const motion = { ...still, 0: { kind: 'steps', levels: [-100, 100], holdUs: 1_000_000 } as const };
    const moved = simulate(
      {
        system: 0xa2,
        remote: 'external',
        channels: 7,
        fades: { start: 1000, lossRate: 0, randomRate: 0 },
        motion,
        damage: { startMidFrame: 5 },
      },
      3_000_000,
    );
    const m = summarizeCapture(recording([moved]));
    expect(m.format.alignmentUnproven).toBe(false);
    expect(m.unprovenFrames).toBeGreaterThan(30);
    expect(m.unprovenFrames).toBeLessThan(m.decoder.frames);
    expect(formatSummary(m, 'moved.sscap')).toMatch(/Alignment +proven after \d+ frames read unproven/);
  });
});
