/**
 * Damage for decoder tests: lost and stray bytes applied to a clean stream, with the map back to
 * the clean stream's offsets, and the clean stream's frames as the oracle of what was sent.
 */
import { SpektrumDecoder, type DecoderOptions } from '../src/decoder/decoder.js';
import type { DecodedFrame } from '../src/decoder/types.js';

export interface SentFrame {
  offset: number;
  bytes: string;
  /** What a reader sees: remote, system, resolution, fades or RSSI, channels. */
  reading: string;
  fadesDelta: number;
}

export const reading = (f: DecodedFrame): string =>
  `${f.remote}|${f.system}|${f.resolution}|${f.fades}|${f.rssi}|${Array.from(f.ids.subarray(0, f.count))}|${Array.from(f.positions.subarray(0, f.count))}|${f.vtx?.raw ?? ''}`;
export const hex = (b: Uint8Array): string => Array.from(b, (x) => x.toString(16).padStart(2, '0')).join('');

/** Decodes whole (or in `chunk`-byte pushes) and returns every frame as plain data. */
export function framesOf(bytes: Uint8Array, options: DecoderOptions = {}, chunk = 0): SentFrame[] {
  const d = new SpektrumDecoder(options);
  const out: SentFrame[] = [];
  const drain = () => {
    for (let f = d.next(); f; f = d.next())
      out.push({ offset: f.offset, bytes: hex(f.bytes), reading: reading(f), fadesDelta: f.fadesDelta });
  };
  const step = chunk > 0 ? chunk : bytes.length;
  for (let i = 0; i < bytes.length; i += step) {
    d.push(bytes.subarray(i, i + step));
    drain();
  }
  d.end();
  drain();
  return out;
}

export interface Edit {
  /** Position in the clean stream (taken modulo its length). */
  at: number;
  kind: 'delete' | 'insert';
  /** 1–40 bytes. */
  length: number;
  /** Inserted bytes: random values from this seed, or (copy) a stretch of the stream itself. */
  seed: number;
  copy: boolean;
}

export interface Damaged {
  bytes: Uint8Array;
  /** For each damaged byte, its offset in the clean stream, or -1 for an inserted byte. */
  origin: Int32Array;
  /** Clean offsets damage spans: [first lost byte, after the last) of a deletion, [at, at + 1) of an insertion. */
  places: [number, number][];
}

/** Applies the edits (non-overlapping: later ones that overlap earlier ones are dropped). */
export function damage(clean: Uint8Array, edits: readonly Edit[]): Damaged {
  const bytes: number[] = [];
  const origin: number[] = [];
  const sorted = edits.map((e) => ({ ...e, at: e.at % clean.length })).sort((a, b) => a.at - b.at);
  const places: [number, number][] = [];
  let i = 0;
  for (const e of sorted) {
    if (e.at < i) continue;
    for (; i < e.at; i++) {
      bytes.push(clean[i]!);
      origin.push(i);
    }
    if (e.kind === 'delete') {
      i = Math.min(clean.length, e.at + e.length);
      places.push([e.at, i]);
    } else {
      places.push([e.at, e.at + 1]);
      let s = e.seed >>> 0;
      for (let k = 0; k < e.length; k++) {
        s = (Math.imul(s, 1103515245) + 12345) >>> 0;
        bytes.push(e.copy ? clean[(e.at + 7 + k) % clean.length]! : s >>> 24);
        origin.push(-1);
      }
    }
  }
  for (; i < clean.length; i++) {
    bytes.push(clean[i]!);
    origin.push(i);
  }
  return { bytes: Uint8Array.from(bytes), origin: Int32Array.from(origin), places };
}

/**
 * Equal readings, or the same but for byte 0 where one side was not yet sure whether it is
 * fades or RSSI (both null): the frame's bytes are the receiver's either way, and which reading
 * is sure first depends on where acquisition began.
 */
export function sameReading(sent: string, got: string): boolean {
  if (sent === got) return true;
  const g = got.split('|');
  const s = sent.split('|');
  const unsure = (x: string[]) => x[3] === 'null' && x[4] === 'null';
  if (!unsure(g) && !unsure(s)) return false;
  return s[0] === g[0] && s[1] === g[1] && s[2] === g[2] && s.slice(5).join('|') === g.slice(5).join('|');
}

export interface Verdict {
  /** Emitted frames whose bytes or reading match no frame the receiver sent. */
  invented: string[];
  /** Frames sent, untouched and not beside damage, that did not come out. */
  lost: number[];
  /** Frames whose SPM4649T RSSI byte was a stray byte (no content rule can tell). */
  rssiSwaps: number;
  /** Fades counted on the damaged stream beyond those counted on the clean one. */
  extraFades: number;
}

/**
 * Judges the damaged decode against the clean one. A frame may be lost when damage touches it,
 * or the frame before or after it (the bar: "no frame lost beyond those the damage touches plus
 * one"), or within the first `settle` frames (acquisition).
 */
export function judge(
  sent: readonly SentFrame[],
  got: readonly SentFrame[],
  d: Damaged,
  settle = 5,
  starts?: ReadonlySet<number>,
): Verdict {
  const byOffset = new Map(sent.map((f) => [f.offset, f]));
  const invented: string[] = [];
  let rssiSwaps = 0;
  const seen = new Set<number>();
  for (const f of got) {
    const start = d.origin[f.offset] ?? -1;
    const end = d.origin[f.offset + 15] ?? -1;
    const s = byOffset.get(start);
    if (s !== undefined && end === start + 15 && s.bytes === f.bytes && sameReading(s.reading, f.reading)) {
      seen.add(start);
      continue;
    }
    // The same bytes and reading as a frame sent elsewhere (a lost byte equal to the one beside it).
    if (sent.some((x) => x.bytes === f.bytes && sameReading(x.reading, f.reading))) continue;
    // A frame the clean decode did not give (it started elsewhere), but the receiver sent: its
    // bytes stand unbroken in the clean stream from where the simulator started a frame.
    if (s === undefined && starts?.has(start) === true && end === start + 15) continue;
    // A stray byte just before an SPM4649T frame's system byte reads as its RSSI: RSSI wanders
    // from frame to frame, so nothing can tell it from the receiver's own (as with a flipped bit).
    // Where the decoder does not yet know fades from RSSI it claims nothing from byte 0.
    const [, , , fades, rssiValue] = f.reading.split('|');
    const rssi = rssiValue !== 'null' || fades === 'null';
    if (
      rssi &&
      sent.some(
        (x) => x.bytes.slice(2) === f.bytes.slice(2) && x.reading.split('|').slice(5).join() === f.reading.split('|').slice(5).join(),
      )
    ) {
      rssiSwaps++;
      continue;
    }
    invented.push(`${f.offset}: ${f.bytes} ${f.reading}`);
  }
  const lost: number[] = [];
  for (const [k, f] of sent.entries()) {
    if (k < settle || seen.has(f.offset)) continue;
    const near = d.places.some(([a, b]) => b > f.offset - 16 && a < f.offset + 32);
    if (!near) lost.push(f.offset);
  }
  const sum = (fs: readonly SentFrame[]) => fs.reduce((n, f) => n + f.fadesDelta, 0);
  return { invented, rssiSwaps, lost, extraFades: Math.max(0, sum(got) - sum(sent)) };
}

/** Clean streams of every system type, both remotes, X-Plus, VTX, RSSI, empty slots, lying system bytes. */
export const CLEAN_PRESETS: readonly string[] = [
  'dsm2-22ms-1024-internal',
  'dsm2-22ms-1024-external',
  'dsm2-11ms-2048-internal',
  'dsm2-11ms-2048-external',
  'dsmx-22ms-2048-internal',
  'dsmx-22ms-2048-external',
  'dsmx-11ms-2048-internal',
  'dsmx-11ms-2048-external',
  'clone-zero-header',
  'lying-b2-with-1024-data',
  'lying-01-with-2048-data',
  'rssi-spm4649t',
  'xplus-dx9',
  'xplus-8',
  'vtx',
  'empty-slots-12ch',
  'empty-slots-22ms-5ch',
  'fade-wrap-internal',
  'fade-wrap-external',
];
