/**
 * Forced options choose how frames are read, never where they lie (issue 34, item 4): a forced
 * resolution, remote or header mode that no frame matches gives no frame and says so, rather
 * than frames read at a shifted offset that match nothing that was sent.
 */
import { describe, expect, it } from 'vitest';
import { SpektrumDecoder, type DecoderOptions } from '../src/decoder/decoder.js';
import { systemInfo } from '../src/decoder/spec.js';
import type { DecoderEvent } from '../src/decoder/types.js';
import { simulate } from '../src/simulator/simulator.js';

const SYSTEMS = [0x01, 0x12, 0xa2, 0xb2];
const FORCED: DecoderOptions[] = [
  { resolution: 1024 },
  { resolution: 2048 },
  { remote: 'internal' },
  { remote: 'external' },
  { headerMode: 'fades' },
  { headerMode: 'rssi' },
];

function decode(bytes: Uint8Array, options: DecoderOptions) {
  const events: DecoderEvent[] = [];
  const d = new SpektrumDecoder({ ...options, onEvent: (e) => events.push(e) });
  d.push(bytes);
  d.end();
  const offsets: number[] = [];
  for (let f = d.next(); f; f = d.next()) offsets.push(f.offset);
  return { offsets, format: d.format, events };
}

describe('forced options against every system type', () => {
  for (const system of SYSTEMS) {
    for (const remote of ['internal', 'external'] as const) {
      const name = `${systemInfo(system)!.name} ${remote}`;
      it(`emits only frames that were sent from ${name}, under every forced option`, () => {
        for (const seed of [1, 2, 3]) {
          for (const channels of [6, 7, 10]) {
            // Fade counts from 0 to 255 (an external count's low byte is a §8.3 system byte at 1, 18, 162 and 178).
            const scenario = { system, remote, channels, seed, fades: { start: (seed * 89) % 256 } };
            const sim = simulate(scenario, 2_000_000, { truth: true });
            const sent = new Set(sim.truth!.frames.map((f) => f.offset));
            for (const options of FORCED) {
              const { offsets, format } = decode(sim.bytes, options);
              const where = `${name}, ${channels} channels, seed ${seed}, ${JSON.stringify(options)}`;
              expect(
                offsets.filter((o) => !sent.has(o)),
                where,
              ).toEqual([]);
              const resolution = systemInfo(system)!.resolution;
              if (options.resolution !== undefined && options.resolution !== resolution) {
                // The other resolution reads no frame (and says so), or reads the frames where
                // they are (six channels of 2048 are valid IDs at 1024 too): what forcing it means.
                if (offsets.length === 0) {
                  expect(format.withheld, where).toBe('forced');
                  expect(format.forcedMismatch, where).toBe(resolution);
                }
              } else {
                // A forced reading the frames fit decodes them (a forced header mode may drop the
                // frames where it breaks the chain, never most of them).
                expect(offsets.length, where).toBeGreaterThan(sent.size / 2);
              }
            }
          }
        }
      });
    }
  }
});

describe('a forced resolution no frame matches', () => {
  it('decodes nothing from DSMX 22 ms 2048 frames with 1024 forced, where shifted readings fit 1024', () => {
    for (const seed of [1, 2, 3, 4, 5]) {
      const sim = simulate({ system: 0xa2, remote: 'internal', channels: 7, seed }, 3_000_000);
      const { offsets, format, events } = decode(sim.bytes, { resolution: 1024 });
      expect(offsets, `seed ${seed}`).toEqual([]);
      expect(format.forcedMismatch).toBe(2048);
      expect(format.withheld).toBe('forced');
      expect(format.explanation).toBe('Forced 1024: no frame matches; the stream looks like 2048.');
      // Said once, as a format change, and never a lock.
      expect(events.filter((e) => e.type === 'locked')).toEqual([]);
      expect(events.filter((e) => e.type === 'format-changed')).toHaveLength(1);
    }
  });

  it('says which forced setting fits no frame when it is not the resolution', () => {
    // An external count that moves nearly every frame never holds still in its low byte, which
    // an internal remote's system byte does.
    const sim = simulate({ system: 0xb2, remote: 'external', channels: 10, seed: 4, fades: { lossRate: 0, randomRate: 0.9 } }, 1_000_000);
    const { offsets, format, events } = decode(sim.bytes, { remote: 'internal' });
    expect(offsets).toEqual([]);
    expect(format.withheld).toBe('forced');
    expect(format.forcedMismatch).toBeNull();
    expect(format.explanation).toBe(
      'No frame matches the forced remote internal: the bytes are frames, read another way; nothing is decoded.',
    );
    expect(events.filter((e) => e.type !== 'discarded').map((e) => e.type)).toEqual(['format-changed']);
    // Unforced, the same bytes are frames.
    expect(decode(sim.bytes, {}).offsets.length).toBeGreaterThan(80);
  });

  it('clears what it said when the setting changes, and decodes again', () => {
    const sim = simulate({ system: 0x01, remote: 'internal', channels: 6, seed: 1 }, 2_000_000);
    const d = new SpektrumDecoder({ resolution: 2048 });
    d.push(sim.bytes.subarray(0, 800));
    while (d.next());
    expect(d.format.withheld).toBe('forced');
    d.setResolution('auto');
    expect(d.format.withheld).toBeNull();
    expect(d.format.forcedMismatch).toBeNull();
    d.push(sim.bytes.subarray(800));
    d.end();
    let n = 0;
    while (d.next()) n++;
    expect(n).toBeGreaterThan(20);
    expect(d.format.resolution).toBe(1024);
  });
});
