/**
 * The real receiver captures in ../shared/captures/px4 (Saleae exports shipped with PX4): each
 * decodes frame for frame to what the captures' README says, fed with per-byte times, re-timed
 * into 16 ms USB-style chunks, and with no timing at all. The expected frames come from the
 * files' own timing (a 16-byte burst between idle gaps is a frame), which the decoder never uses
 * to find frames.
 */
import { existsSync, readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { describe, expect, it } from 'vitest';
import { SpektrumDecoder } from '../src/decoder/decoder.js';
import type { DecodedFrame } from '../src/decoder/types.js';
import { importSaleaeCsv } from '../src/capture/saleae.js';
import { usbChunks } from './feeds.js';

const dir = resolve(import.meta.dirname, '../../shared/captures/px4');
const present = existsSync(dir);
if (!present)
  console.warn(`skipping the PX4 capture tests: ${dir} is not here (it sits beside the repository on development machines and in CI)`);

interface Frame {
  offset: number;
  remote: string;
  system: number | null;
  fades: number | null;
  ids: number[];
  positions: number[];
}
const see = (f: DecodedFrame): Frame => ({
  offset: f.offset,
  remote: f.remote,
  system: f.system,
  fades: f.fades,
  ids: Array.from(f.ids.subarray(0, f.count)),
  positions: Array.from(f.positions.subarray(0, f.count)),
});

function load(name: string) {
  const capture = importSaleaeCsv(new Uint8Array(readFileSync(join(dir, name))));
  const times = capture.byteTimesUs!;
  // Bursts between idle gaps of more than 2 ms, from the analyser's timing.
  const bursts: [number, number][] = [];
  let start = 0;
  for (let i = 1; i <= capture.bytes.length; i++) {
    if (i === capture.bytes.length || times[i]! - times[i - 1]! > 2000) {
      bursts.push([start, i - start]);
      start = i;
    }
  }
  return {
    bytes: capture.bytes,
    times,
    full: bursts.filter(([, n]) => n === 16).map(([o]) => o),
    short: bursts.filter(([, n]) => n !== 16),
  };
}

function decode(bytes: Uint8Array, feed: (d: SpektrumDecoder, out: Frame[]) => void) {
  const d = new SpektrumDecoder();
  const out: Frame[] = [];
  feed(d, out);
  d.end();
  for (let f = d.next(); f; f = d.next()) out.push(see(f));
  return { frames: out, stats: { ...d.stats }, format: d.format, bytes };
}

function allFeeds(bytes: Uint8Array, times: Float64Array) {
  const drain = (d: SpektrumDecoder, out: Frame[]) => {
    for (let f = d.next(); f; f = d.next()) out.push(see(f));
  };
  return {
    perByte: decode(bytes, (d, out) => {
      d.push(bytes, times);
      drain(d, out);
    }),
    noTiming: decode(bytes, (d, out) => {
      for (let i = 0; i < bytes.length; i += 5) {
        d.push(bytes.subarray(i, i + 5));
        drain(d, out);
      }
    }),
    usb16ms: decode(bytes, (d, out) => {
      // What a browser sees through an FTDI adapter: whatever arrived in each 16 ms window, one time per chunk.
      for (const chunk of usbChunks(bytes, times)) {
        d.push(chunk.bytes, chunk.timeUs);
        drain(d, out);
      }
    }),
  };
}

const channelSet = (frames: Frame[]) => [...new Set(frames.flatMap((f) => f.ids))].sort((a, b) => a - b);
const valuesOf = (frames: Frame[], id: number) =>
  [...new Set(frames.flatMap((f) => f.positions.filter((_, k) => f.ids[k] === id)))].sort((a, b) => a - b);

describe.skipIf(!present)('real PX4 captures', () => {
  it('dsm_x_data.txt: frames only at the 66 full bursts, all but those right before a truncated one, 10 channels, 00 00 header', () => {
    const { bytes, times, full, short } = load('dsm_x_data.txt');
    expect(bytes.length).toBe(1105);
    expect(short.map(([, n]) => n)).toEqual([14, 14, 7, 14]);
    // A full burst right before a truncated one reads exactly like a frame that lost its own
    // end (and the `00 00` header is too weak to tell them apart): it goes with the damage.
    const beforeShort = new Set(short.map(([o]) => o - 16));
    const runs = allFeeds(bytes, times);
    const decoded = runs.perByte.frames.map((f) => f.offset);
    expect(decoded.every((o) => full.includes(o))).toBe(true);
    expect(full.filter((o) => !decoded.includes(o)).every((o) => beforeShort.has(o))).toBe(true);
    expect(decoded.length).toBe(62);
    for (const run of Object.values(runs)) {
      expect(run.frames).toEqual(runs.perByte.frames);
      expect(run.stats.discardedBytes).toBe(49 + 4 * 16);
    }
    const frames = runs.perByte.frames;
    expect(frames.every((f) => f.remote === 'external' && f.fades === 0)).toBe(true);
    expect(runs.perByte.format.resolution).toBe(2048);
    expect(channelSet(frames)).toEqual([0, 1, 2, 3, 4, 5, 6, 7, 8, 9]);
    expect(valuesOf(frames, 0)).toEqual([352, 353]);
    for (const id of [1, 2, 3, 7, 8, 9]) expect(valuesOf(frames, id)).toEqual([1024]);
    for (const id of [4, 5, 6]) expect(valuesOf(frames, id)).toEqual([1706]);
    expect(frames[0]!.ids).toEqual([1, 5, 2, 3, 0, 7, 6]);
    expect(frames[1]!.ids).toEqual([1, 5, 2, 3, 4, 8, 9]);
  });

  it('dsm_x_dx9_data.txt: all 456 frames, 16 channels with X-Plus 12–15 at 1024', () => {
    const { bytes, times, full } = load('dsm_x_dx9_data.txt');
    expect(full).toHaveLength(456);
    const runs = allFeeds(bytes, times);
    for (const run of Object.values(runs)) {
      expect(run.frames.map((f) => f.offset)).toEqual(full);
      expect(run.frames).toEqual(runs.perByte.frames);
    }
    const frames = runs.perByte.frames;
    expect(channelSet(frames)).toEqual([0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15]);
    for (const id of [12, 13, 14, 15]) expect(valuesOf(frames, id)).toEqual([1024]);
    for (const id of [4, 5, 6]) expect(valuesOf(frames, id)).toEqual([1706]);
    expect(valuesOf(frames, 9)).toEqual([1024]);
    const us = frames.flatMap((f) => f.positions.map((p) => Math.round(p * 0.583) + 903));
    expect(Math.min(...us)).toBeGreaterThanOrEqual(1102);
    expect(Math.max(...us)).toBeLessThanOrEqual(1898);
  });

  it('dsm_x_dx9_px4_binding_data.txt: 455 frames from an internal remote, system 0xB2, fades 62', () => {
    const { bytes, times, full } = load('dsm_x_dx9_px4_binding_data.txt');
    expect(full).toHaveLength(455);
    const runs = allFeeds(bytes, times);
    for (const run of Object.values(runs)) {
      expect(run.frames.map((f) => f.offset)).toEqual(full);
      expect(run.frames).toEqual(runs.perByte.frames);
    }
    const frames = runs.perByte.frames;
    expect(frames.every((f) => f.remote === 'internal' && f.system === 0xb2 && f.fades === 62)).toBe(true);
    expect(runs.perByte.format.resolutionReason).toBe('system-byte');
    expect(channelSet(frames)).toHaveLength(16);
  });
});
