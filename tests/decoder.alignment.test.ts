/**
 * Where frames start when an external remote's header reads as a slot (issue 34, item 3): a
 * fade count of 256 or more is a valid channel word in both resolutions, so a reading shifted
 * by words can chain as well as the real one. The decoder opened mid-frame at every offset
 * must read the frames the receiver sent: by the phase bit where frames come in pairs (11 ms,
 * and 22 ms with more than 7 channels), by the silence between frames where each byte has its
 * own time. What is left (22 ms, up to 7 channels, no byte times) the README names.
 */
import { describe, expect, it } from 'vitest';
import { SpektrumDecoder } from '../src/decoder/decoder.js';
import type { Scenario } from '../src/simulator/scenario.js';
import { simulate } from '../src/simulator/simulator.js';

/** Offsets of the frames decoded that are not where the receiver started one, out of those decoded. */
function misread(s: Scenario, timed: boolean): { wrong: number; read: number } {
  const sim = simulate(s, 1e6, { truth: true });
  const starts = new Set(sim.truth?.frames.map((f) => f.offset));
  const d = new SpektrumDecoder();
  d.push(sim.bytes, timed ? sim.timesUs : undefined);
  d.end();
  let wrong = 0;
  let read = 0;
  for (let f = d.next(); f; f = d.next()) {
    read++;
    if (!starts.has(f.offset)) wrong++;
  }
  return { wrong, read };
}

const still = Object.fromEntries(Array.from({ length: 20 }, (_, id) => [id, { kind: 'fixed', percent: id === 0 ? -100 : 0 } as const]));

describe('an external remote whose count reads as a slot, opened mid-frame', () => {
  it('reads the frames sent at every offset where frames come in pairs, without byte times', () => {
    for (const [system, channels] of [
      [0x12, 7],
      [0xb2, 7],
      [0xb2, 12],
      [0xa2, 12],
    ] as const) {
      for (const count of [40, 286, 1000]) {
        for (let skip = 0; skip < 16; skip++) {
          const s: Scenario = {
            system,
            remote: 'external',
            channels,
            fades: { start: count, lossRate: 0, randomRate: 0 },
            motion: still,
            damage: { startMidFrame: skip },
          };
          const r = misread(s, false);
          expect(r, `system ${system.toString(16)}, ${channels} ch, count ${count}, ${skip} bytes skipped`).toEqual({
            wrong: 0,
            read: r.read,
          });
          expect(r.read).toBeGreaterThan(40);
        }
      }
    }
  });

  it('reads the frames sent at every offset in every system where each byte has its own time', () => {
    for (const system of [0x01, 0x12, 0xa2, 0xb2]) {
      for (const channels of [4, 7]) {
        for (let skip = 0; skip < 16; skip++) {
          const s: Scenario = {
            system,
            remote: 'external',
            channels,
            fades: { start: 286, lossRate: 0, randomRate: 0 },
            motion: still,
            damage: { startMidFrame: skip },
          };
          const r = misread(s, true);
          expect(r, `system ${system.toString(16)}, ${channels} ch, ${skip} bytes skipped`).toEqual({ wrong: 0, read: r.read });
          expect(r.read).toBeGreaterThan(40);
        }
      }
    }
  });
});
