/**
 * The frame inspector's memory, kept by the worker for each remote: a log of what the decoder
 * made of the stream (frames, discards, resyncs, locks, format changes), each placed by its
 * stream offset and time, with a copy of its bytes. It is fed only what the decoder reports:
 * each frame `next()` returns (its `bytes` and `timeUs`) and each event (its `timeUs`, and a
 * discard's `bytes`), so the decoder is the one account of where bytes went and when they came.
 * The page asks for a snapshot when the user wants to look; the log itself costs a few stores
 * and a 16-byte copy per frame and allocates nothing while it runs, because it is fed at the
 * decoder's full rate whether anyone looks or not.
 *
 * Stream offsets are the decoder's: 0 is the first byte pushed since the decoder was created or
 * reset. `reset()` the log together with the decoder.
 */
import { FRAME_SIZE } from '../decoder/spec.js';
import type { DecodedFrame, DecoderEvent } from '../decoder/types.js';

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
   * A copy of the bytes (a discard's first `DISCARD_BYTES_CAP` only), or null when the log's
   * byte store has since been filled by newer entries or the entry covers none. Entries of one snapshot share one
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

/** Zero-length events sort before a frame or discard at the same offset: a resync or lock names where the next frame starts. */
function rank(kind: number): number {
  return kind === K_FRAME || kind === K_DISCARDED ? 1 : 0;
}

export class InspectorLog {
  readonly capacity: number;
  /** Bytes of entries kept; the oldest entries lose their bytes first. */
  readonly byteCapacity: number;

  // The entry ring, as columns: no object per frame.
  readonly #kind: Uint8Array;
  readonly #offset: Float64Array;
  readonly #length: Float64Array;
  readonly #time: Float64Array;
  readonly #flags: Uint8Array;
  /** System byte, or -1 for none. */
  readonly #system: Int16Array;
  /** Where the entry's bytes start in the byte store (a position, see #bytes), and how many there are. */
  readonly #at: Float64Array;
  readonly #stored: Uint16Array;
  /** Explanations of locks and format changes (rare; undefined elsewhere). */
  readonly #text: (string | undefined)[];
  /** Ring index of the oldest entry. */
  #first = 0;
  #count = 0;

  /**
   * The byte store, a ring: entries' bytes are appended as they come, and position p lives at
   * p % byteCapacity while p >= #written - byteCapacity.
   */
  readonly #bytes: Uint8Array;
  /** Positions written so far. */
  #written = 0;
  /** Stream offset after the last byte an entry covers. */
  #end = 0;

  /**
   * @param capacity entries kept (frames and events together)
   * @param byteCapacity bytes of entries kept; entries older than this lose their bytes first
   * @throws {RangeError} when either cannot hold one frame
   */
  constructor(capacity = 4096, byteCapacity = 1 << 16) {
    if (!Number.isInteger(capacity) || capacity < 1) throw new RangeError(`capacity must be a positive integer, got ${capacity}`);
    if (!Number.isInteger(byteCapacity) || byteCapacity < FRAME_SIZE)
      throw new RangeError(`byteCapacity must be an integer ≥ ${FRAME_SIZE}, got ${byteCapacity}`);
    this.capacity = capacity;
    this.byteCapacity = byteCapacity;
    this.#kind = new Uint8Array(capacity);
    this.#offset = new Float64Array(capacity);
    this.#length = new Float64Array(capacity);
    this.#time = new Float64Array(capacity);
    this.#flags = new Uint8Array(capacity);
    this.#system = new Int16Array(capacity);
    this.#at = new Float64Array(capacity);
    this.#stored = new Uint16Array(capacity);
    this.#text = new Array<string | undefined>(capacity).fill(undefined);
    this.#bytes = new Uint8Array(byteCapacity);
  }

  /** Entries held. */
  get size(): number {
    return this.#count;
  }

  /** Stream offset after the last byte a frame or discard covered (the decoder's `stats.bytes` once it decided them all). */
  get streamBytes(): number {
    return this.#end;
  }

  /** Forgets everything; call it with `decoder.reset()` (offsets start again at 0). */
  reset(): void {
    this.#first = this.#count = this.#end = this.#written = 0;
    this.#text.fill(undefined);
  }

  /** Each frame `next()` returns, right away (it is borrowed: its numbers and a copy of its bytes are kept). */
  onFrame(frame: DecodedFrame): void {
    let flags = frame.resolution === 2048 ? F_2048 : F_1024;
    flags |= frame.remote === 'internal' ? F_INTERNAL : F_EXTERNAL;
    if (frame.rssi !== null) flags |= F_RSSI;
    const i = this.#add(K_FRAME, frame.offset, FRAME_SIZE, frame.timeUs, flags, frame.system ?? -1, undefined);
    this.#at[i] = this.#write(frame.bytes);
    this.#stored[i] = FRAME_SIZE;
  }

  /** Each decoder event, from the decoder's `onEvent` (a discard's bytes are copied: they are borrowed). */
  onEvent(event: DecoderEvent): void {
    const t = event.timeUs;
    switch (event.type) {
      case 'discarded': {
        const reason = REASONS.indexOf(event.reason);
        // A run of discards (16 bytes at a time before a lock) reads better as one row.
        const last = this.#count > 0 ? (this.#first + this.#count - 1) % this.capacity : -1;
        if (
          last >= 0 &&
          this.#kind[last] === K_DISCARDED &&
          this.#flags[last] === reason &&
          this.#offsetOf(last) + this.#lengthOf(last) === event.offset
        ) {
          this.#length[last] = this.#lengthOf(last) + event.length;
          this.#end = Math.max(this.#end, event.offset + event.length);
          this.#extend(last, event.bytes);
          return;
        }
        const i = this.#add(K_DISCARDED, event.offset, event.length, t, reason, -1, undefined);
        const kept = event.bytes.subarray(0, DISCARD_BYTES_CAP);
        this.#at[i] = this.#write(kept);
        this.#stored[i] = kept.length;
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
      case 'fade-jump':
        return;
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
    // First pass: how many bytes to copy.
    let total = 0;
    for (let k = 0; k < n; k++) {
      const i = (start + k) % cap;
      if (this.#held(i)) total += this.#stored[i] ?? 0;
    }
    const pool = new Uint8Array(total);
    let at = 0;
    const out: InspectEntry[] = new Array<InspectEntry>(n);
    for (let k = 0; k < n; k++) {
      const i = (start + k) % cap;
      const kind = this.#kind[i] ?? K_FRAME;
      const length = this.#lengthOf(i);
      const flags = this.#flags[i] ?? 0;
      let bytes: Uint8Array | null = null;
      if (this.#held(i)) {
        bytes = pool.subarray(at, at + (this.#stored[i] ?? 0));
        this.#read(this.#at[i] ?? 0, bytes);
        at += bytes.length;
      }
      const e: InspectEntry = {
        kind: KINDS[kind] ?? 'frame',
        offset: this.#offsetOf(i),
        length,
        timeUs: this.#time[i] ?? Number.NaN,
        bytes,
      };
      if (kind === K_DISCARDED) {
        e.reason = REASONS[flags];
        if (length > DISCARD_BYTES_CAP) e.truncated = true;
      } else if (kind !== K_RESYNC) {
        if (flags & (F_2048 | F_1024)) e.resolution = flags & F_2048 ? 2048 : 1024;
        if (flags & (F_INTERNAL | F_EXTERNAL)) e.remote = flags & F_INTERNAL ? 'internal' : 'external';
        e.headerMode = flags & F_RSSI ? 'rssi' : 'fades';
        const system = this.#system[i] ?? -1;
        e.system = system < 0 ? null : system;
        const text = this.#text[i];
        if (text !== undefined) e.text = text;
      }
      out[k] = e;
    }
    return out;
  }

  #offsetOf(i: number): number {
    return this.#offset[i] ?? 0;
  }

  #lengthOf(i: number): number {
    return this.#length[i] ?? 0;
  }

  /** Whether entry i has bytes still in the store. */
  #held(i: number): boolean {
    const n = this.#stored[i] ?? 0;
    return n > 0 && (this.#at[i] ?? 0) >= this.#written - this.byteCapacity;
  }

  /**
   * Appends a merged discard's bytes to entry i's, up to `DISCARD_BYTES_CAP`. They must follow
   * its bytes in the store: when newer entries were written after them (an entry that came in
   * out of stream order), the entry's bytes move to the end first (at most the cap, and only
   * until it is full).
   */
  #extend(i: number, bytes: Uint8Array): void {
    const had = this.#stored[i] ?? 0;
    const take = Math.min(bytes.length, DISCARD_BYTES_CAP - had);
    if (take <= 0 || !this.#held(i)) return;
    let at = this.#at[i] ?? 0;
    if (at + had !== this.#written) {
      const copy = new Uint8Array(had);
      this.#read(at, copy);
      at = this.#write(copy);
      this.#at[i] = at;
    }
    this.#write(bytes.subarray(0, take));
    this.#stored[i] = had + take;
  }

  /** Appends `bytes` to the store; returns the position of the first. A loop, not set(): mostly 16 bytes, and no view made. */
  #write(bytes: Uint8Array): number {
    const size = this.byteCapacity;
    const store = this.#bytes;
    const n = bytes.length;
    const start = this.#written;
    // Only the last `size` bytes can stay.
    const skip = n > size ? n - size : 0;
    let at = (start + skip) % size;
    for (let k = skip; k < n; k++) {
      store[at] = bytes[k] ?? 0;
      at = at + 1 === size ? 0 : at + 1;
    }
    this.#written = start + n;
    return start;
  }

  /** Copies the store's bytes from position `position` into `out` (they must still be held). */
  #read(position: number, out: Uint8Array): void {
    const size = this.byteCapacity;
    const at = position % size;
    const first = Math.min(out.length, size - at);
    out.set(this.#bytes.subarray(at, at + first));
    if (first < out.length) out.set(this.#bytes.subarray(0, out.length - first), first);
  }

  /** Appends an entry, keeping stream order; returns its ring index (after any move). */
  #add(kind: number, offset: number, length: number, timeUs: number, flags: number, system: number, text: string | undefined): number {
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
    this.#at[i] = 0;
    this.#stored[i] = 0;
    if (offset + length > this.#end) this.#end = offset + length;
    // The decoder reports in decision order, not always stream order: after a good frame
    // followed by noise it fires the resync (where frames resume) and the discard (the noise
    // after the frame) before next() hands out the frame itself. Such an entry moves back a few
    // places; everything else is appended in order and stops at the first comparison.
    let j = this.#count - 1;
    while (j > 0) {
      const a = (this.#first + j - 1) % cap;
      const b = (this.#first + j) % cap;
      const oa = this.#offsetOf(a);
      const ob = this.#offsetOf(b);
      if (oa < ob || (oa === ob && rank(this.#kind[a] ?? 0) <= rank(this.#kind[b] ?? 0))) break;
      this.#swap(a, b);
      i = a;
      j--;
    }
    return i;
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
    sw(this.#at);
    sw(this.#stored);
    sw(this.#text);
  }
}
