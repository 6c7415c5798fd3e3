/**
 * The frame inspector's memory, kept by the worker for each remote: the most recent raw stream
 * bytes and a log of what the decoder made of them (frames, discards, resyncs, locks, format
 * changes), each placed by its stream offset. The page asks for a snapshot when the user wants
 * to look; the log itself costs a few stores per frame and allocates nothing while it runs,
 * because it is fed at the decoder's full rate whether anyone looks or not.
 *
 * Stream offsets are the decoder's: 0 is the first byte pushed since the decoder was created or
 * reset. The log must see exactly the bytes the decoder sees (`onBytes` with every `push`), and
 * be `reset()` together with the decoder.
 */
import { BYTE_TIME_US, FRAME_SIZE, type DecodedFrame, type DecoderEvent } from '../decoder/index.js';

export type InspectKind = 'frame' | 'discarded' | 'resync' | 'locked' | 'format-changed';

/** One row of the inspector: plain data, cheap to structured-clone to the page. */
export interface InspectEntry {
  kind: InspectKind;
  /** Stream offset of the first byte (of the frame, of the discarded run, where frames resume). */
  offset: number;
  /** Bytes covered: 16 for a frame, the run for a discard, 0 for the other events. */
  length: number;
  /** Time of the first byte in the source's clock (µs), NaN when unknown. */
  timeUs: number;
  /**
   * A copy of the bytes (a discard's first `DISCARD_BYTES_CAP` only), or null when they have
   * scrolled out of the raw ring or the entry covers none. Entries of one snapshot share one
   * ArrayBuffer (one copy for the whole snapshot; transfer `bytes.buffer` once if at all).
   */
  bytes: Uint8Array | null;
  /** A discard longer than `DISCARD_BYTES_CAP`: `bytes` holds only its start. */
  truncated?: boolean;
  /** Why bytes were discarded: 'before-lock', 'noise', 'truncated-frame', 'end-of-stream'. */
  reason?: string;
  /** Frames, and locks / format changes once a resolution is decided. */
  resolution?: 1024 | 2048;
  remote?: 'internal' | 'external';
  headerMode?: 'fades' | 'rssi';
  /** A frame's system byte (internal remote), null for an external one. */
  system?: number | null;
  /** Locks and format changes: the decoder's explanation of the format. */
  text?: string;
}

/** The most bytes of one discarded run a snapshot carries (noise before a lock can run for seconds). */
export const DISCARD_BYTES_CAP = 256;

const KINDS: readonly InspectKind[] = ['frame', 'discarded', 'resync', 'locked', 'format-changed'];
const K_FRAME = 0;
const K_DISCARDED = 1;
const K_RESYNC = 2;
const K_LOCKED = 3;
const K_FORMAT = 4;

const REASONS = ['before-lock', 'noise', 'truncated-frame', 'end-of-stream'] as const;

// Bits of an entry's flags byte (frames, locks, format changes). A discard keeps its reason's
// index there instead.
const F_2048 = 1;
const F_1024 = 2;
const F_INTERNAL = 4;
const F_EXTERNAL = 8;
const F_RSSI = 16;

/** Chunk times remembered for placing events in time (events lie a few chunks behind the newest). */
const CHUNKS = 1024;

/** Zero-length events sort before a frame or discard at the same offset: a resync or lock names where the next frame starts. */
function rank(kind: number): number {
  return kind === K_FRAME || kind === K_DISCARDED ? 1 : 0;
}

export class InspectorLog {
  readonly capacity: number;
  readonly rawBytes: number;

  // The entry ring, as columns: no object per frame.
  readonly #kind: Uint8Array;
  readonly #offset: Float64Array;
  readonly #length: Float64Array;
  readonly #time: Float64Array;
  readonly #flags: Uint8Array;
  /** System byte, or -1 for none. */
  readonly #system: Int16Array;
  /** Explanations of locks and format changes (rare; undefined elsewhere). */
  readonly #text: (string | undefined)[];
  /** Ring index of the oldest entry. */
  #first = 0;
  #count = 0;

  // The raw byte ring: stream offset x lives at x % rawBytes while x >= #end - rawBytes.
  readonly #raw: Uint8Array;
  /** Per-byte times beside the raw ring, made the first time a chunk brings them (captures). */
  #rawTime: Float64Array | null = null;
  /** Stream offset after the last byte seen. */
  #end = 0;

  // Chunk ends (stream offsets) and times, a ring, to time the events.
  readonly #chunkEnd = new Float64Array(CHUNKS);
  readonly #chunkTime = new Float64Array(CHUNKS);
  /** 1 where the chunk came with per-byte times (kept in #rawTime). */
  readonly #chunkPerByte = new Uint8Array(CHUNKS);
  #chunks = 0;

  /**
   * @param capacity entries kept (frames and events together)
   * @param rawBytes raw stream bytes kept; entries older than this lose their bytes first
   */
  constructor(capacity = 4096, rawBytes = 1 << 16) {
    if (!Number.isInteger(capacity) || capacity < 1) throw new RangeError(`capacity must be a positive integer, got ${capacity}`);
    if (!Number.isInteger(rawBytes) || rawBytes < FRAME_SIZE)
      throw new RangeError(`rawBytes must be an integer ≥ ${FRAME_SIZE}, got ${rawBytes}`);
    this.capacity = capacity;
    this.rawBytes = rawBytes;
    this.#kind = new Uint8Array(capacity);
    this.#offset = new Float64Array(capacity);
    this.#length = new Float64Array(capacity);
    this.#time = new Float64Array(capacity);
    this.#flags = new Uint8Array(capacity);
    this.#system = new Int16Array(capacity);
    this.#text = new Array<string | undefined>(capacity).fill(undefined);
    this.#raw = new Uint8Array(rawBytes);
  }

  /** Entries held. */
  get size(): number {
    return this.#count;
  }

  /** Stream offset after the last byte seen (equals the decoder's `stats.bytes`). */
  get streamBytes(): number {
    return this.#end;
  }

  /** Forgets everything; call it with `decoder.reset()` (offsets start again at 0). */
  reset(): void {
    this.#first = this.#count = this.#end = this.#chunks = 0;
    this.#text.fill(undefined);
  }

  /**
   * Every chunk pushed to the decoder, in order, with the time given to `push` (a chunk time:
   * that of its last byte; or per-byte times, kept beside the bytes). Times only place the
   * events; frames bring their own.
   */
  onBytes(bytes: Uint8Array, time?: number | Float64Array): void {
    const n = bytes.length;
    if (n === 0) return;
    const raw = this.#raw;
    const size = this.rawBytes;
    // Only the last `size` bytes of a huge chunk can stay.
    const skip = n > size ? n - size : 0;
    const perByte = time instanceof Float64Array;
    if (perByte && this.#rawTime === null) this.#rawTime = new Float64Array(size);
    let at = (this.#end + skip) % size;
    let from = skip;
    while (from < n) {
      const take = Math.min(n - from, size - at);
      raw.set(bytes.subarray(from, from + take), at);
      if (perByte) (this.#rawTime as Float64Array).set(time.subarray(from, from + take), at);
      from += take;
      at = 0;
    }
    this.#end += n;
    const i = this.#chunks++ % CHUNKS;
    this.#chunkEnd[i] = this.#end;
    this.#chunkTime[i] = typeof time === 'number' ? time : perByte ? (time[n - 1] as number) : NaN;
    this.#chunkPerByte[i] = perByte ? 1 : 0;
  }

  /** Each frame `next()` returns, right away (it is borrowed: only numbers are kept). */
  onFrame(frame: DecodedFrame): void {
    let flags = frame.resolution === 2048 ? F_2048 : F_1024;
    flags |= frame.remote === 'internal' ? F_INTERNAL : F_EXTERNAL;
    if (frame.rssi !== null) flags |= F_RSSI;
    this.#add(K_FRAME, frame.offset, FRAME_SIZE, frame.timeUs, flags, frame.system ?? -1, undefined);
  }

  /**
   * Each decoder event, from the decoder's `onEvent`. `timeUs` overrides the time the log
   * works out from the chunk times given to `onBytes`.
   */
  onEvent(event: DecoderEvent, timeUs?: number): void {
    const t = timeUs ?? this.#timeAt(event.offset);
    switch (event.type) {
      case 'discarded': {
        const reason = REASONS.indexOf(event.reason);
        // A run of discards (16 bytes at a time before a lock) reads better as one row.
        const last = this.#count > 0 ? (this.#first + this.#count - 1) % this.capacity : -1;
        if (
          last >= 0 &&
          this.#kind[last] === K_DISCARDED &&
          this.#flags[last] === reason &&
          (this.#offset[last] as number) + (this.#length[last] as number) === event.offset
        ) {
          this.#length[last] = (this.#length[last] as number) + event.length;
          return;
        }
        this.#add(K_DISCARDED, event.offset, event.length, t, reason, -1, undefined);
        return;
      }
      case 'resync':
        this.#add(K_RESYNC, event.offset, 0, t, 0, -1, undefined);
        return;
      case 'locked':
      case 'format-changed': {
        const f = event.format;
        let flags = f.resolution === 2048 ? F_2048 : f.resolution === 1024 ? F_1024 : 0;
        flags |= f.remote === 'internal' ? F_INTERNAL : f.remote === 'external' ? F_EXTERNAL : 0;
        if (f.headerMode === 'rssi') flags |= F_RSSI;
        this.#add(event.type === 'locked' ? K_LOCKED : K_FORMAT, event.offset, 0, t, flags, f.system ?? -1, f.explanation);
        return;
      }
    }
  }

  /**
   * The newest `limit` entries in stream order, with copies of their bytes. Allocates one
   * ArrayBuffer for all the bytes and one small object per entry.
   */
  snapshot(limit: number): InspectEntry[] {
    const n = Number.isNaN(limit) ? 0 : Math.max(0, Math.min(Math.floor(limit), this.#count));
    const cap = this.capacity;
    const start = this.#first + this.#count - n;
    const oldest = this.#end - this.rawBytes;
    // First pass: how many bytes to copy.
    let total = 0;
    for (let k = 0; k < n; k++) {
      const i = (start + k) % cap;
      const o = this.#offset[i] as number;
      const len = Math.min(this.#length[i] as number, DISCARD_BYTES_CAP);
      if (len > 0 && o >= oldest) total += len;
    }
    const pool = new Uint8Array(total);
    let at = 0;
    const out: InspectEntry[] = new Array<InspectEntry>(n);
    for (let k = 0; k < n; k++) {
      const i = (start + k) % cap;
      const kind = this.#kind[i] as number;
      const offset = this.#offset[i] as number;
      const length = this.#length[i] as number;
      const flags = this.#flags[i] as number;
      const len = Math.min(length, DISCARD_BYTES_CAP);
      let bytes: Uint8Array | null = null;
      if (len > 0 && offset >= oldest) {
        bytes = pool.subarray(at, at + len);
        this.#copy(offset, bytes);
        at += len;
      }
      const e: InspectEntry = { kind: KINDS[kind] as InspectKind, offset, length, timeUs: this.#time[i] as number, bytes };
      if (kind === K_DISCARDED) {
        e.reason = REASONS[flags];
        if (length > DISCARD_BYTES_CAP) e.truncated = true;
      } else if (kind !== K_RESYNC) {
        if (flags & (F_2048 | F_1024)) e.resolution = flags & F_2048 ? 2048 : 1024;
        if (flags & (F_INTERNAL | F_EXTERNAL)) e.remote = flags & F_INTERNAL ? 'internal' : 'external';
        e.headerMode = flags & F_RSSI ? 'rssi' : 'fades';
        const system = this.#system[i] as number;
        e.system = system < 0 ? null : system;
        const text = this.#text[i];
        if (text !== undefined) e.text = text;
      }
      out[k] = e;
    }
    return out;
  }

  /** Appends an entry, keeping stream order. */
  #add(kind: number, offset: number, length: number, timeUs: number, flags: number, system: number, text: string | undefined): void {
    const cap = this.capacity;
    let i: number;
    if (this.#count === cap) {
      i = this.#first;
      this.#first = (this.#first + 1) % cap;
    } else {
      i = (this.#first + this.#count) % cap;
      this.#count++;
    }
    this.#kind[i] = kind;
    this.#offset[i] = offset;
    this.#length[i] = length;
    this.#time[i] = timeUs;
    this.#flags[i] = flags;
    this.#system[i] = system;
    this.#text[i] = text;
    // The decoder reports in decision order, not always stream order: after a good frame
    // followed by noise it fires the resync (where frames resume) and the discard (the noise
    // after the frame) before next() hands out the frame itself. Such an entry moves back a few
    // places; everything else is appended in order and stops at the first comparison.
    let j = this.#count - 1;
    while (j > 0) {
      const a = (this.#first + j - 1) % cap;
      const b = (this.#first + j) % cap;
      const oa = this.#offset[a] as number;
      const ob = this.#offset[b] as number;
      if (oa < ob || (oa === ob && rank(this.#kind[a] as number) <= rank(this.#kind[b] as number))) break;
      this.#swap(a, b);
      j--;
    }
  }

  #swap(a: number, b: number): void {
    const sw = <T extends { [k: number]: unknown }>(col: T) => {
      const t = col[a];
      col[a] = col[b];
      col[b] = t;
    };
    sw(this.#kind);
    sw(this.#offset);
    sw(this.#length);
    sw(this.#time);
    sw(this.#flags);
    sw(this.#system);
    sw(this.#text);
  }

  /** Copies the raw bytes from stream offset `offset` into `out` (they must be in the ring). */
  #copy(offset: number, out: Uint8Array): void {
    const size = this.rawBytes;
    const at = offset % size;
    const first = Math.min(out.length, size - at);
    out.set(this.#raw.subarray(at, at + first));
    if (first < out.length) out.set(this.#raw.subarray(0, out.length - first), first);
  }

  /**
   * Time of the byte at stream offset `x`: its own time when it came with one, else its chunk's
   * time less a byte time for each byte after it, as the decoder times frames. NaN when that
   * chunk had no time or is no longer remembered.
   */
  #timeAt(x: number): number {
    // The oldest remembered chunk's start is the end of one already overwritten: not usable.
    const stop = this.#chunks > CHUNKS ? this.#chunks - CHUNKS + 1 : 0;
    for (let c = this.#chunks - 1; c >= stop; c--) {
      const i = c % CHUNKS;
      const end = this.#chunkEnd[i] as number;
      const prevEnd = c > 0 ? (this.#chunkEnd[(c - 1) % CHUNKS] as number) : 0;
      if (x >= prevEnd && x < end) {
        if (this.#chunkPerByte[i] === 1 && this.#rawTime !== null && x >= this.#end - this.rawBytes)
          return this.#rawTime[x % this.rawBytes] as number;
        return (this.#chunkTime[i] as number) - (end - 1 - x) * BYTE_TIME_US;
      }
      if (x >= end) return NaN;
    }
    return NaN;
  }
}
