/**
 * A frame needs evidence of a channel (issue 34, item 5): runs of 0xFF parse as frames of seven
 * empty slots, and other filler and degenerate input can parse at some shift, but none of it is a
 * transmitter. The decoder locks only on chains that carry channels, says why it decodes nothing
 * from filler, and keeps every frame of a real stream, empty slots and all.
 */
import { existsSync, readFileSync } from 'node:fs';
import fc from 'fast-check';
import { describe, expect, it } from 'vitest';
import { SpektrumDecoder, type DecoderOptions } from '../src/decoder/decoder.js';
import type { DecoderEvent } from '../src/decoder/types.js';
import { encodeExternalFrame, encodeInternalFrame } from '../src/simulator/encode.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { concatBytes } from './bytes.js';
import { dsmxSlots } from './frames.js';
import { OPTIONS } from './decoder-streams.js';

function decode(bytes: Uint8Array, options: DecoderOptions = {}) {
  const events: DecoderEvent[] = [];
  const d = new SpektrumDecoder({ ...options, onEvent: (e) => events.push(e) });
  d.push(bytes);
  d.end();
  const frames: { offset: number; count: number; ids: number[] }[] = [];
  for (let f = d.next(); f; f = d.next()) frames.push({ offset: f.offset, count: f.count, ids: Array.from(f.ids.subarray(0, f.count)) });
  return { frames, format: d.format, stats: d.stats, events };
}

/** `pattern` repeated to `length` bytes. */
function repeat(pattern: ArrayLike<number>, length: number): Uint8Array {
  return Uint8Array.from({ length }, (_, i) => pattern[i % pattern.length]!);
}

/** The number of frames under the option that gives most, and that option. */
function mostFrames(bytes: Uint8Array): { frames: number; options: DecoderOptions } {
  let most = { frames: 0, options: {} as DecoderOptions };
  for (const options of OPTIONS) {
    const n = decode(bytes, options).frames.length;
    if (n > most.frames) most = { frames: n, options };
  }
  return most;
}

const FILLER_WORDS = [0xffff, 0x0000, 0x00ff, 0xff00];

describe('filler gives no frame', () => {
  it('decodes nothing from a run of any one byte value, under every option', () => {
    for (let x = 0; x < 256; x++) expect(mostFrames(repeat([x], 256)), `0x${x.toString(16)}`).toEqual({ frames: 0, options: {} });
  });

  it('says why 16,000 bytes of 0xFF give no frame, once, and keeps every byte accounted', () => {
    const { frames, format, stats, events } = decode(repeat([0xff], 16_000));
    expect(frames).toEqual([]);
    expect(format.locked).toBe(false);
    expect(format.resolution).toBeNull();
    expect(format.withheld).toBe('filler');
    expect(format.explanation).toMatch(/only of empty slots \(0xFFFF\).*carry no channel/);
    expect(events.filter((e) => e.type === 'format-changed' || e.type === 'locked').map((e) => e.type)).toEqual(['format-changed']);
    expect(stats.discardedBytes).toBe(16_000);
  });

  it('decodes nothing from any repeated pattern of 0x00 and 0xFF bytes, under every option', () => {
    fc.assert(
      fc.property(fc.array(fc.constantFrom(0x00, 0xff), { minLength: 1, maxLength: 48 }), (pattern) => {
        expect(mostFrames(repeat(pattern, 256)).frames).toBe(0);
      }),
      { numRuns: 100 },
    );
  });

  it('decodes nothing from two alternating bytes, nor from any 4- or 8-byte pattern of them', () => {
    fc.assert(
      fc.property(
        fc.integer({ min: 0, max: 255 }),
        fc.integer({ min: 0, max: 255 }),
        fc.array(fc.boolean(), { minLength: 4, maxLength: 8 }),
        (a, b, picks) => {
          expect(mostFrames(repeat([a, b], 256)).frames).toBe(0);
          expect(
            mostFrames(
              repeat(
                picks.map((p) => (p ? a : b)),
                256,
              ),
            ).frames,
          ).toBe(0);
        },
      ),
      { numRuns: 100 },
    );
  });

  it('invents no channel from frames whose slots are all filler, whatever their header, at any shift', () => {
    fc.assert(
      fc.property(
        fc.integer({ min: 0, max: 0xffff }),
        fc.integer({ min: 0, max: 2 }),
        fc.array(fc.constantFrom(...FILLER_WORDS), { minLength: 7, maxLength: 7 }),
        (header, rise, words) => {
          // An external count that rises by `rise` a frame, or any header held still.
          const frames = Array.from({ length: 10 }, (_, i) => encodeExternalFrame((header + rise * i) & 0xffff, words));
          const { frames: n, options } = mostFrames(concatBytes(frames));
          expect(n, `header ${header.toString(16)} ${JSON.stringify(options)}`).toBe(0);
        },
      ),
      { numRuns: 200 },
    );
  });

  it('decodes nothing from text or an image', () => {
    const files = [
      '../README.md',
      '../../shared/spektrum-remote-receiver-spec.txt',
      '../src/decoder/decoder.ts',
      '../public/icon-192.png',
      '../public/icon-512.png',
    ];
    // The spec lives in ../shared, beside a clone in CI; a clone elsewhere reads the others.
    for (const file of files.filter((f) => existsSync(new URL(f, import.meta.url)))) {
      const bytes = new Uint8Array(readFileSync(new URL(file, import.meta.url)));
      expect(mostFrames(bytes), file).toEqual({ frames: 0, options: {} });
    }
  });
});

describe('real streams keep every frame', () => {
  const internal = (i: number, fades = 0) => encodeInternalFrame({ fades, system: 0xb2 }, dsmxSlots(i, i / 10));
  const empty = (fades = 0) => encodeInternalFrame({ fades, system: 0xb2 }, Array(7).fill(0xffff));

  it('decodes frames of seven empty slots inside a stream of channels, as frames without channels', () => {
    const frames = [
      ...Array.from({ length: 10 }, (_, i) => internal(i)),
      ...Array.from({ length: 30 }, () => empty()),
      ...Array.from({ length: 10 }, (_, i) => internal(40 + i)),
    ];
    const out = decode(concatBytes(frames)).frames;
    expect(out.map((f) => f.offset)).toEqual(frames.map((_, i) => 16 * i));
    expect(out.slice(10, 40).every((f) => f.count === 0)).toBe(true);
    expect(out.slice(0, 10).every((f) => f.count === 7)).toBe(true);
  });

  it('gives no frame from a receiver that only ever sends empty slots, and says why', () => {
    const { frames, format } = decode(concatBytes(Array.from({ length: 50 }, () => empty())));
    expect(frames).toEqual([]);
    expect(format.withheld).toBe('filler');
  });

  it('locks on a stream right after filler, and stops at filler after a stream, with nothing from the filler', () => {
    for (const name of ['dsmx-11ms-2048-internal', 'dsm2-22ms-1024-external', 'clone-zero-header', 'empty-slots-22ms-5ch', 'vtx']) {
      const { bytes } = simulate(preset(name), 500_000);
      const clean = decode(bytes).frames.map((f) => f.offset);
      for (const filler of [0xff, 0x00]) {
        const before = repeat([filler], 1000);
        const after = decode(concatBytes([before, bytes, repeat([filler], 1000)]));
        const offsets = after.frames.map((f) => f.offset - before.length);
        // The last frame before the filler may go, as beside any damage: a frame that lost its
        // last byte to the filler reads as whole.
        expect(offsets, `${name} in 0x${filler.toString(16)}`).toEqual(clean.slice(0, offsets.length));
        expect(offsets.length, name).toBeGreaterThanOrEqual(clean.length - 1);
        // Runs of 0x00 do not even parse as frames; runs of 0xFF do, and the format says so.
        expect(after.format.withheld, name).toBe(filler === 0xff ? 'filler' : null);
        expect(after.format.locked, name).toBe(false);
      }
    }
  });

  it('clears the reason once frames with channels come', () => {
    const { bytes } = simulate(preset('dsmx-11ms-2048-internal'), 300_000);
    const { format, events } = decode(concatBytes([repeat([0xff], 4000), bytes]));
    expect(format.withheld).toBeNull();
    expect(format.locked).toBe(true);
    const kinds = events
      .filter((e) => e.type !== 'discarded')
      .map((e) => (e.type === 'format-changed' ? `changed:${e.format.withheld}` : e.type));
    expect(kinds).toEqual(['changed:filler', 'locked']);
  });
});
