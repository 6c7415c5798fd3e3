/**
 * The locked decoder's one-pass path changes nothing but speed: every fixture, every real
 * capture in ../shared/captures (every file `readCapture` reads, every port) and damaged
 * simulator streams of every preset decode to the same frames (every field), the same events
 * (in order, with their formats), the same counters after every frame and every push, and the
 * same format at the end with the fast path on and off (`fastPath: false`: the general path
 * only), under every option and however the bytes come (tests/lockstep.ts compares them).
 * Streams of over a megabyte: tests/slow/decoder.fastpath-long.test.ts (npm run test:slow).
 */
import { readdirSync, readFileSync } from 'node:fs';
import { join, relative } from 'node:path';
import { describe, expect, it } from 'vitest';
import { CAPTURE_DIR, filesUnder } from './shared-captures.js';
import { CaptureFormatError, captureChunks, capturePorts, readCapture } from '../src/capture/index.js';
import { CLEAN_PRESETS } from './damage.js';
import { damagedStream, expectSame, FEEDS, feed, OPTIONS } from './lockstep.js';

const fixtureDir = join(import.meta.dirname, 'fixtures');
const fixtures = readdirSync(fixtureDir)
  .filter((f) => f.endsWith('.bin'))
  .map((f) => f.replace('.bin', ''));

const captureFiles = filesUnder(CAPTURE_DIR);

describe('the fast path gives what the general path gives', () => {
  it.each(fixtures)('fixture %s, every option, every feed', (name) => {
    const bytes = new Uint8Array(readFileSync(join(fixtureDir, `${name}.bin`)));
    const raw = readFileSync(join(fixtureDir, `${name}.times.f64`));
    const times = new Float64Array(raw.buffer.slice(raw.byteOffset, raw.byteOffset + raw.byteLength));
    for (const options of OPTIONS) for (const how of FEEDS) expectSame(feed(bytes, times, how), options, `${name}, ${how}`);
  });

  if (captureFiles.length === 0) console.warn(`skipping the real captures in the fast-path test: ${CAPTURE_DIR} is not here`);
  it.skipIf(captureFiles.length === 0)('reads every file in ../shared/captures that is a capture (the rest are notes)', () => {
    for (const file of captureFiles) {
      try {
        readCapture(new Uint8Array(readFileSync(join(CAPTURE_DIR, file))), file);
      } catch (e) {
        expect(e, file).toBeInstanceOf(CaptureFormatError);
        expect(file, 'a file readCapture rejects').toMatch(/\.(md|txt)$/i);
        expect(readFileSync(join(CAPTURE_DIR, file), 'utf8'), file).not.toMatch(/^Time \[s\]/);
      }
    }
  });

  const captures = captureFiles.filter((file) => {
    try {
      readCapture(new Uint8Array(readFileSync(join(CAPTURE_DIR, file))), file);
      return true;
    } catch {
      return false;
    }
  });
  it.skipIf(captures.length === 0).each(captures)('real capture %s, every port, every option, as recorded and every feed', (file) => {
    const capture = readCapture(new Uint8Array(readFileSync(join(CAPTURE_DIR, file))), file);
    const rel = relative(CAPTURE_DIR, join(CAPTURE_DIR, file));
    let frames = 0;
    for (const port of capturePorts(capture)) {
      for (const options of OPTIONS) {
        frames += expectSame(captureChunks(capture, port), options, `${rel} port ${port}, as recorded`);
        if (capture.byteTimesUs !== undefined && capturePorts(capture).length === 1) {
          for (const how of FEEDS) expectSame(feed(capture.bytes, capture.byteTimesUs, how), options, `${rel}, ${how}`);
        }
      }
    }
    expect(frames, `${rel}: frames decoded under some option`).toBeGreaterThan(0);
  });

  it.each(CLEAN_PRESETS)('damaged 30 s simulator stream %s: lost, stray, repeated bytes and flipped bits', (name) => {
    for (const seed of [1, 2]) {
      const { bytes, times } = damagedStream(name, seed, 30_000_000);
      for (const how of FEEDS) expectSame(feed(bytes, times, how), {}, `${name} seed ${seed}, ${how}`);
      expectSame(feed(bytes, times, '64-byte chunks, chunk times'), { resolution: name.includes('1024') ? 1024 : 2048 }, `${name}, forced`);
    }
  });
});
