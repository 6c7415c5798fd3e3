/**
 * The fast path against the general path (tests/lockstep.ts) on damaged simulator streams of
 * over a megabyte: every option on an internal 2048 and an external 1024 stream, and RSSI,
 * X-Plus and VTX streams under the options that lock on them, fed as a USB adapter delivers
 * them, and every feed under 'auto'. Long clean stretches between damage keep the fast path
 * running for thousands of frames at a time; the damage sends it back to the general path.
 */
import { describe, expect, it } from 'vitest';
import type { DecoderOptions } from '../../src/decoder/index.js';
import { damagedStream, expectSame, FEEDS, feed, OPTIONS } from '../lockstep.js';

/** About 1.1 MB each: 12 min at 11 ms, 24 min at 22 ms; the options each runs under. */
const LONG: readonly [string, number, readonly DecoderOptions[]][] = [
  ['dsmx-11ms-2048-internal', 720e6, OPTIONS],
  ['dsm2-22ms-1024-external', 1440e6, OPTIONS],
  ['rssi-spm4649t', 720e6, OPTIONS.filter((o) => o.resolution !== 1024 && o.remote !== 'external')],
  ['xplus-dx9', 720e6, OPTIONS.filter((o) => o.resolution !== 1024)],
  ['vtx', 720e6, OPTIONS.filter((o) => o.resolution !== 1024)],
];

describe('the fast path gives what the general path gives on long streams', () => {
  it.each(LONG)(
    'damaged simulator stream %s of over 1 MB',
    (name, durationUs, options) => {
      const { bytes, times } = damagedStream(name, 7, durationUs);
      expect(bytes.length).toBeGreaterThanOrEqual(1_000_000);
      let frames = 0;
      for (const o of options) frames += expectSame(feed(bytes, times, 'USB chunks'), o, `${name}, USB chunks`);
      for (const how of FEEDS) frames += expectSame(feed(bytes, times, how), {}, `${name}, ${how}`);
      // Most of it decodes: the comparison is of frames, not of two decoders that gave up.
      expect(frames).toBeGreaterThan(((options.length + FEEDS.length) * bytes.length) / 16 / 2);
    },
    300_000,
  );
});
