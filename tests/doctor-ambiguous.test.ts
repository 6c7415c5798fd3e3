/**
 * A header that reads both ways (an external remote whose fade count's low byte is a §8.3
 * system byte when the decoder locks): the doctor says what it cannot know as a possibility,
 * never "certain", and when the count moves it re-reads the remote, which is not a rebind.
 */
import { describe, expect, it } from 'vitest';
import { doctorCapture } from '../src/report/doctor-capture.js';
import { LinkMonitor } from '../src/decoder/link.js';
import type { DecodedFrame } from '../src/decoder/types.js';
import { summarizeCapture } from '../src/report/summary.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { perByteCapture, recording } from './feeds.js';

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

describe('the period of a header that reads both ways', () => {
  // A count that reads as a system byte of the other period: 0x12 and 0xB2 say 11 ms, 0x01 and 0xA2 say 22 ms.
  const CASES = [
    { system: 0x01, start: 18 },
    { system: 0xa2, start: 178 },
    { system: 0x12, start: 1 },
    { system: 0xb2, start: 162 },
  ];

  it('comes from the frames once their timing refutes the count read as a system byte', () => {
    for (const { system, start } of CASES) {
      // The count never moves: the bytes read as an internal remote all through.
      const sim = external(system, start, 0);
      const nominal = system === 0x01 || system === 0xa2 ? 22_000 : 11_000;
      for (const [feed, capture] of [
        ['16 ms chunks', recording([sim])],
        ['1 ms chunks', recording([sim], true, 1_000)],
        ['per byte', perByteCapture(sim)],
      ] as const) {
        const { link } = summarizeCapture(capture);
        const where = `system 0x${system.toString(16)}, count ${start}, ${feed}`;
        expect(link.nominalPeriodUs, where).toBe(nominal);
        expect(link.missedFrames, where).toBe(0);
      }
    }
  });

  it("stays the system byte's where frames are lost but those between come a period apart", () => {
    // An internal 11 ms remote losing half its frames: its mean interval is 22 ms.
    const sim = simulate({ system: 0xb2, remote: 'internal', channels: 7, seed: 3, fades: { lossRate: 0.5, randomRate: 0 } }, 3_000_000);
    for (const capture of [recording([sim]), perByteCapture(sim)]) {
      const { link } = summarizeCapture(capture);
      expect(link.nominalPeriodUs).toBe(11_000);
      expect(link.missedFrames).toBeGreaterThan(100);
    }
  });

  /** A frame as the link monitor reads it: time, system byte, and byte 0 (a fade count, or null: RSSI mode). */
  const frame = (timeUs: number, system: number, fades: number | null) =>
    ({ timeUs, fadesDelta: 0, system, rssi: null, fades }) as unknown as DecodedFrame;

  it('is refuted however the adapter dates the frames, 8 to 16 ms chunks', () => {
    for (const chunk of [8_000, 12_000, 13_000, 16_000]) {
      const m = new LinkMonitor();
      // An external 22 ms remote whose count reads as 0xB2 (DSMX 11 ms), each frame dated at its chunk's end.
      for (let i = 0; i < 400; i++) m.frame(frame(Math.ceil((1000 + i * 22_000 + 1400) / chunk) * chunk, 0xb2, 0));
      m.finish(1000 + 400 * 22_000 + chunk);
      expect(m.stats.nominalPeriodUs, `${chunk / 1000} ms chunks`).toBe(22_000);
      expect(m.stats.missedFrames, `${chunk / 1000} ms chunks`).toBe(0);
    }
  });

  it('is not refuted by frames lost at random, nor where byte 0 is no fade count (RSSI mode)', () => {
    let seed = 7;
    const random = () => (seed = (seed * 1103515245 + 12345) & 0x7fffffff) / 0x7fffffff;
    for (const fades of [0, null]) {
      const m = new LinkMonitor();
      let lost = 0;
      for (let i = 0; i < 600; i++) {
        // A true DSMX 11 ms receiver losing 45 % of its frames for 1.5 s, in 16 ms USB chunks.
        if (i >= 200 && i < 340 && random() < 0.45) {
          lost++;
          continue;
        }
        m.frame(frame(Math.ceil((1000 + i * 11_000 + 1400) / 16_000) * 16_000, 0xb2, fades));
        expect(m.stats.nominalPeriodUs).toBe(11_000);
      }
      m.finish(1000 + 600 * 11_000 + 16_000);
      expect(m.stats.missedFrames, `byte 0 ${fades === null ? 'RSSI' : 'fades'}`).toBe(lost);
    }
    // Every other frame lost for a second, RSSI mode: no counter to rule the loss out.
    const m = new LinkMonitor();
    for (let i = 0; i < 300; i++) if (!(i >= 100 && i < 200 && i % 2 === 1)) m.frame(frame(1000 + i * 11_000, 0xb2, null));
    m.finish(1000 + 300 * 11_000);
    expect(m.stats.missedFrames).toBe(50);
  });
});
