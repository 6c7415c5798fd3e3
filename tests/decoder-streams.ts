/**
 * Streams for the decoder's tests: every way bytes reach it (`feed`), every option
 * combination, and simulated streams with damage of every kind.
 */
import type { DecoderOptions } from '../src/decoder/decoder.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { damage, type Edit } from './damage.js';
import { usbChunks } from './feeds.js';

export interface Push {
  bytes: Uint8Array;
  time?: number | Float64Array;
}

export type Feed = 'whole, per-byte times' | '64-byte chunks, chunk times' | 'random splits, no times' | 'USB chunks';
export const FEEDS: readonly Feed[] = ['whole, per-byte times', '64-byte chunks, chunk times', 'random splits, no times', 'USB chunks'];

export function* feed(bytes: Uint8Array, times: Float64Array, how: Feed): Generator<Push> {
  if (how === 'whole, per-byte times') {
    yield { bytes, time: times };
  } else if (how === '64-byte chunks, chunk times') {
    for (let i = 0; i < bytes.length; i += 64) {
      const end = Math.min(bytes.length, i + 64);
      yield { bytes: bytes.subarray(i, end), time: times[end - 1] };
    }
  } else if (how === 'USB chunks') {
    for (const c of usbChunks(bytes, times)) yield { bytes: c.bytes, time: c.timeUs };
  } else {
    let seed = bytes.length;
    for (let i = 0; i < bytes.length; ) {
      seed = (Math.imul(seed, 1103515245) + 12345) >>> 0;
      const end = Math.min(bytes.length, i + 1 + ((seed >>> 16) % 97));
      yield { bytes: bytes.subarray(i, end) };
      i = end;
    }
  }
}

/** Every decoder option combination. */
export const OPTIONS: DecoderOptions[] = [];
for (const resolution of ['auto', 1024, 2048] as const) {
  for (const remote of ['auto', 'internal', 'external'] as const) {
    for (const headerMode of ['auto', 'fades', 'rssi'] as const) OPTIONS.push({ resolution, remote, headerMode });
  }
}

/** Simulated, then damaged: lost, stray and repeated stretches every ~300 bytes, a flipped bit every ~500. */
export function damagedStream(name: string, seed: number, durationUs: number): { bytes: Uint8Array; times: Float64Array } {
  const { bytes: clean, timesUs } = simulate({ ...preset(name), seed }, durationUs);
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
    bytes[at] = bytes[at]! ^ (1 << rand(8));
  }
  // Times of the damaged stream: the clean byte's; an inserted byte takes the one before it.
  const times = new Float64Array(bytes.length);
  for (let i = 0; i < bytes.length; i++) {
    const from = damaged.origin[i]!;
    times[i] = from >= 0 ? timesUs[from]! : i > 0 ? times[i - 1]! : 0;
  }
  return { bytes, times };
}
