/**
 * The locked decoder's one-pass path changes nothing but speed: every fixture, every real
 * capture in ../shared/captures and long damaged simulator streams decode to the same frames
 * (every field), the same events (in order, with their formats), the same counters after every
 * push and the same format at the end with the fast path on and off (`fastPath: false`: the
 * general path only), under every option and however the bytes come.
 */
import { existsSync, readdirSync, readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { describe, expect, it } from 'vitest';
import { importSaleaeCsv } from '../src/capture/index.js';
import { type DecoderEvent, type DecoderOptions, SpektrumDecoder } from '../src/decoder/index.js';
import { preset, simulate } from '../src/simulator/index.js';
import { CLEAN_PRESETS, damage, hex, type Edit } from './damage.js';

type Feed = 'whole, per-byte times' | '64-byte chunks, chunk times' | 'random splits, no times';
const FEEDS: readonly Feed[] = ['whole, per-byte times', '64-byte chunks, chunk times', 'random splits, no times'];

/** Everything a caller can see, as plain data: frames, events, counters after each push, the last format. */
function trace(bytes: Uint8Array, times: Float64Array, options: DecoderOptions, feed: Feed, fastPath: boolean) {
  const events: DecoderEvent[] = [];
  const d = new SpektrumDecoder({ ...options, fastPath, onEvent: (e) => events.push(e) });
  const seen: unknown[] = [];
  const drain = () => {
    for (let f = d.next(); f; f = d.next()) {
      seen.push({
        index: f.index,
        offset: f.offset,
        timeUs: Number.isNaN(f.timeUs) ? 'NaN' : f.timeUs,
        remote: f.remote,
        system: f.system,
        resolution: f.resolution,
        fades: f.fades,
        fadesDelta: f.fadesDelta,
        rssi: f.rssi,
        count: f.count,
        ids: Array.from(f.ids.subarray(0, f.count)),
        positions: Array.from(f.positions.subarray(0, f.count)),
        words: Array.from(f.words),
        vtx: f.vtx && { ...f.vtx },
        bytes: hex(f.bytes),
      });
      seen.push({ ...d.stats });
    }
    seen.push({ ...d.stats });
  };
  if (feed === 'whole, per-byte times') {
    d.push(bytes, times);
    drain();
  } else if (feed === '64-byte chunks, chunk times') {
    for (let i = 0; i < bytes.length; i += 64) {
      const end = Math.min(bytes.length, i + 64);
      d.push(bytes.subarray(i, end), times[end - 1]);
      drain();
    }
  } else {
    let seed = bytes.length;
    for (let i = 0; i < bytes.length; ) {
      seed = (Math.imul(seed, 1103515245) + 12345) >>> 0;
      const end = Math.min(bytes.length, i + 1 + ((seed >>> 16) % 97));
      d.push(bytes.subarray(i, end));
      drain();
      i = end;
    }
  }
  d.end();
  drain();
  return { seen, events: JSON.parse(JSON.stringify(events)) as unknown, format: d.format };
}

function expectSame(bytes: Uint8Array, times: Float64Array, options: DecoderOptions = {}, feeds: readonly Feed[] = FEEDS) {
  for (const feed of feeds) {
    const general = trace(bytes, times, options, feed, false);
    const fast = trace(bytes, times, options, feed, true);
    // One assertion for the lot would print megabytes on a failure: first the counters at the
    // end, then frames and events, then the format.
    expect(fast.seen.length, `${feed}: frames and stats snapshots`).toBe(general.seen.length);
    expect(fast.seen.at(-1), `${feed}: stats at the end`).toEqual(general.seen.at(-1));
    for (let i = 0; i < general.seen.length; i++) {
      if (JSON.stringify(fast.seen[i]) !== JSON.stringify(general.seen[i]))
        expect(fast.seen[i], `${feed}: entry ${i}`).toEqual(general.seen[i]);
    }
    expect(fast.events, `${feed}: events`).toEqual(general.events);
    expect(fast.format, `${feed}: format`).toEqual(general.format);
  }
}

/** Every decoder option combination. */
const OPTIONS: DecoderOptions[] = [];
for (const resolution of ['auto', 1024, 2048] as const) {
  for (const remote of ['auto', 'internal', 'external'] as const) {
    for (const headerMode of ['auto', 'fades', 'rssi'] as const) OPTIONS.push({ resolution, remote, headerMode });
  }
}

const fixtureDir = join(import.meta.dirname, 'fixtures');
const fixtures = readdirSync(fixtureDir)
  .filter((f) => f.endsWith('.bin'))
  .map((f) => f.replace('.bin', ''));

describe('the fast path gives what the general path gives', () => {
  it.each(fixtures)('fixture %s, every option, every feed', (name) => {
    const bytes = new Uint8Array(readFileSync(join(fixtureDir, `${name}.bin`)));
    const raw = readFileSync(join(fixtureDir, `${name}.times.f64`));
    const times = new Float64Array(raw.buffer.slice(raw.byteOffset, raw.byteOffset + raw.byteLength));
    for (const options of OPTIONS) expectSame(bytes, times, options);
  });

  const captureDir = resolve(import.meta.dirname, '../../shared/captures/px4');
  const captures = existsSync(captureDir) ? readdirSync(captureDir).filter((f) => f.endsWith('.txt')) : [];
  if (captures.length === 0) console.warn(`skipping the real captures in the fast-path test: ${captureDir} is not here`);
  it.skipIf(captures.length === 0).each(captures)('real capture %s, every option, every feed', (name) => {
    const capture = importSaleaeCsv(new Uint8Array(readFileSync(join(captureDir, name))));
    for (const options of OPTIONS) expectSame(capture.bytes, capture.byteTimesUs as Float64Array, options);
  });

  it.each(CLEAN_PRESETS)('long damaged simulator stream %s: lost, stray, repeated bytes and flipped bits', (name) => {
    for (const seed of [1, 2]) {
      const { bytes: clean, timesUs } = simulate({ ...preset(name), seed }, 30_000_000); // 30 s: 1,400–2,700 frames
      // About one edit every 300 bytes: long clean stretches for the fast path between them.
      let s = seed * 2654435761;
      const rand = (n: number) => {
        s = (Math.imul(s, 1103515245) + 12345) >>> 0;
        return (s >>> 8) % n;
      };
      const edits: Edit[] = [];
      for (let k = 0; k < clean.length / 300; k++) {
        edits.push({
          at: rand(clean.length),
          kind: rand(2) === 0 ? 'delete' : 'insert',
          length: 1 + rand(40),
          seed: rand(1 << 30),
          copy: rand(3) === 0,
        });
      }
      const damaged = damage(clean, edits);
      const bytes = damaged.bytes;
      for (let k = 0; k < bytes.length / 500; k++) {
        const at = rand(bytes.length);
        bytes[at] = (bytes[at] as number) ^ (1 << rand(8));
      }
      // Times of the damaged stream: the clean byte's, an inserted byte takes the one before it.
      const times = new Float64Array(bytes.length);
      for (let i = 0; i < bytes.length; i++) {
        const from = damaged.origin[i] as number;
        times[i] = from >= 0 ? (timesUs[from] as number) : i > 0 ? (times[i - 1] as number) : 0;
      }
      expectSame(bytes, times);
      expectSame(bytes, times, { resolution: name.includes('1024') ? 1024 : 2048 }, ['64-byte chunks, chunk times']);
      expectSame(clean, timesUs, { headerMode: 'rssi' }, ['64-byte chunks, chunk times']);
    }
  });
});
