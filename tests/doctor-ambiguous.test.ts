/**
 * A header that reads both ways (an external remote whose fade count's low byte is a §8.3
 * system byte when the decoder locks): the doctor says what it cannot know as a possibility,
 * never "certain", and when the count moves it re-reads the remote, which is not a rebind.
 */
import { describe, expect, it } from 'vitest';
import { doctorCapture } from '../src/report/doctor-capture.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { recording } from './feeds.js';

const SYSTEMS = [0x01, 0x12, 0xa2, 0xb2];
// External counts whose low byte is a system byte: 0x0012, 0x00A2, 0x00B2, 0x01B2, 0x01A2, 0x0112.
const STARTS = [18, 162, 178, 434, 418, 274];

function external(system: number, start: number, randomRate: number) {
  return simulate({ system, remote: 'external', channels: 7, seed: start, fades: { start, lossRate: 0, randomRate } }, 3_000_000);
}

describe('the doctor on a header that reads both ways', () => {
  it('never says "certain" of the remote while its count has not moved', () => {
    for (const system of SYSTEMS)
      for (const start of STARTS) {
        const r = doctorCapture(recording([external(system, start, 0)]));
        const where = `system 0x${system.toString(16)}, count ${start}`;
        const settings = r.findings.find((f) => f.code === 'fc-settings');
        expect(settings?.confidence, where).toBe('likely');
        expect(settings?.title, where).toMatch(/internal or external remote/);
        expect(
          r.findings.filter((f) => f.code === 'rebind'),
          where,
        ).toEqual([]);
        for (const f of r.findings)
          if (f.code === 'fc-settings' || f.code === 'bind-mode') expect(f.confidence, `${where}: ${f.code}`).not.toBe('certain');
      }
  });

  it('re-reads the remote when its count moves: no rebind, and then the settings are sure', () => {
    let moved = 0;
    for (const system of SYSTEMS)
      for (const start of STARTS) {
        const r = doctorCapture(recording([external(system, start, 0.02)]));
        const where = `system 0x${system.toString(16)}, count ${start}`;
        expect(
          r.findings.filter((f) => f.code === 'rebind'),
          where,
        ).toEqual([]);
        const settings = r.findings.find((f) => f.code === 'fc-settings');
        if (settings?.title.includes(' external remote') && !settings.title.includes('internal or external')) moved++;
      }
    expect(moved).toBeGreaterThan(SYSTEMS.length * STARTS.length * 0.8);
  });

  it('counts internal remotes as a possibility, not a certainty, while one of them may be external', () => {
    // Three ports: one true internal remote, two externals whose counts read as system bytes.
    const r = doctorCapture(
      recording([simulate(preset('dsmx-11ms-2048-internal'), 3_000_000), external(0xb2, 178, 0), external(0xb2, 434, 0)]),
    );
    const count = r.findings.find((f) => f.code === 'internal-count');
    expect(count).toBeDefined();
    expect(count?.confidence).toBe('possible');
    expect(count?.severity).toBe('warning');
    expect(count?.evidence.map((e) => e.text).join(' ')).toMatch(/may be an external remote/);
  });
});
