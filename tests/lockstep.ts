/**
 * The fast-path equivalence check (tests/decoder.fastpath*.test.ts): a general-path and a
 * fast-path decoder run in lockstep on the same pushes and are compared as they go, so a
 * megabyte-long stream is checked frame by frame without holding its frames.
 */
import { expect } from 'vitest';
import { type DecodedFrame, type DecoderEvent, type DecoderOptions, type DecoderStats, SpektrumDecoder } from '../src/decoder/index.js';
import { preset, simulate } from '../src/simulator/index.js';
import { damage, type Edit } from './damage.js';
import { usbChunks } from './feeds.js';

export interface Push {
  bytes: Uint8Array;
  time?: number | Float64Array;
}

/** Whether two frames agree in every field a caller may read (explicit fields: this runs for millions of frames). */
function sameFrame(a: DecodedFrame, b: DecodedFrame): boolean {
  if (
    a.index !== b.index ||
    a.offset !== b.offset ||
    !Object.is(a.timeUs, b.timeUs) ||
    a.remote !== b.remote ||
    a.system !== b.system ||
    a.resolution !== b.resolution ||
    a.fades !== b.fades ||
    a.fadesDelta !== b.fadesDelta ||
    a.rssi !== b.rssi ||
    a.count !== b.count
  )
    return false;
  for (let i = 0; i < a.count; i++) if (a.ids[i] !== b.ids[i] || a.positions[i] !== b.positions[i]) return false;
  for (let i = 0; i < 7; i++) if (a.words[i] !== b.words[i]) return false;
  for (let i = 0; i < 16; i++) if (a.bytes[i] !== b.bytes[i]) return false;
  const x = a.vtx;
  const y = b.vtx;
  if (x === null || y === null) return x === y;
  return x.raw === y.raw && x.band === y.band && x.channel === y.channel && x.power === y.power && x.region === y.region && x.pit === y.pit;
}

/** A frame as plain data, to show where two differ. */
function shown(f: DecodedFrame) {
  return {
    ...f,
    ids: Array.from(f.ids.subarray(0, f.count)),
    positions: Array.from(f.positions.subarray(0, f.count)),
    words: Array.from(f.words),
    bytes: Array.from(f.bytes),
    vtx: f.vtx && { ...f.vtx },
  };
}

function sameStats(a: Readonly<DecoderStats>, b: Readonly<DecoderStats>): boolean {
  return (
    a.bytes === b.bytes &&
    a.frames === b.frames &&
    a.frameBytes === b.frameBytes &&
    a.discardedBytes === b.discardedBytes &&
    a.pendingBytes === b.pendingBytes &&
    a.resyncs === b.resyncs &&
    a.badFrames === b.badFrames &&
    a.emptySlots === b.emptySlots &&
    a.vtxFrames === b.vtxFrames &&
    a.fadeJumps === b.fadeJumps
  );
}

/**
 * Feeds `pushes` to a general-path and a fast-path decoder and compares, after every frame and
 * every push: the frame, the counters and the events so far; at the end the format. Returns
 * the number of frames.
 */
export function expectSame(pushes: Iterable<Push>, options: DecoderOptions, label: string): number {
  // Events as JSON, made during the call: a discard's bytes are borrowed for its length only.
  const generalEvents: string[] = [];
  const fastEvents: string[] = [];
  const asJson = (e: DecoderEvent) => JSON.stringify(e, (_k, v: unknown) => (v instanceof Uint8Array ? Array.from(v) : v));
  const general = new SpektrumDecoder({ ...options, fastPath: false, onEvent: (e) => generalEvents.push(asJson(e)) });
  const fast = new SpektrumDecoder({ ...options, fastPath: true, onEvent: (e) => fastEvents.push(asJson(e)) });
  let frames = 0;
  let pushed = 0;
  const fail = (what: string) => expect.fail(`${label}, ${JSON.stringify(options)}, push ${pushed}, frame ${frames}: ${what}`);
  const sameEvents = () => {
    if (generalEvents.length === 0 && fastEvents.length === 0) return;
    if (generalEvents.length !== fastEvents.length) fail(`events: general ${generalEvents.join(', ')}, fast ${fastEvents.join(', ')}`);
    for (let i = 0; i < generalEvents.length; i++) {
      const a = generalEvents[i];
      const b = fastEvents[i];
      if (a !== b) fail(`event ${i}: general ${a}, fast ${b}`);
    }
    generalEvents.length = 0;
    fastEvents.length = 0;
  };
  const drain = () => {
    for (;;) {
      const a = general.next();
      const b = fast.next();
      sameEvents();
      if (a === undefined || b === undefined) {
        if (a !== b) fail(a === undefined ? 'only the fast path gave a frame' : 'only the general path gave a frame');
        break;
      }
      if (!sameFrame(a, b)) expect(shown(b), `${label}, ${JSON.stringify(options)}, frame ${frames}`).toEqual(shown(a));
      if (!sameStats(general.stats, fast.stats))
        fail(`stats: general ${JSON.stringify(general.stats)}, fast ${JSON.stringify(fast.stats)}`);
      frames++;
    }
    if (!sameStats(general.stats, fast.stats)) fail(`stats: general ${JSON.stringify(general.stats)}, fast ${JSON.stringify(fast.stats)}`);
  };
  for (const p of pushes) {
    general.push(p.bytes, p.time);
    fast.push(p.bytes, p.time);
    pushed++;
    drain();
  }
  general.end();
  fast.end();
  drain();
  expect(fast.format, `${label}: format`).toEqual(general.format);
  return frames;
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
