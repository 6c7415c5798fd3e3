/**
 * The bytes a decoder holds and when they arrived: the first of the decoder's three parts.
 *
 * Bytes are appended as pushed and consumed from the head; the stream offset of every byte is
 * kept (`base + index`). Times are kept per pushed chunk, not per byte: each chunk's end offset
 * and its time (or NaN), and per-byte times only for chunks pushed with them. A byte's time is
 * its own, or its chunk's time less one byte time (86.8 µs at 115200 baud) for each byte after
 * it in the chunk (`byteInChunkUs`, the one rule for when a byte arrived). Bytes pushed
 * without times of their own have NaN in the per-byte times, once any chunk came with them.
 */
import { byteInChunkUs } from './spec.js';

const INITIAL_CAPACITY = 4096;
const INITIAL_CHUNKS = 64;

/** A window's bytes and chunk records as plain data (`snapshot()`), for a decoder checkpoint. */
export interface WindowSnapshot {
  /** The bytes not yet consumed, from stream offset `base`, and their per-byte times (null when none came). */
  readonly bytes: Uint8Array;
  readonly byteTimes: Float64Array | null;
  readonly base: number;
  /** The records of the chunks those bytes came in (their ends are stream offsets). */
  readonly chunkEnds: Float64Array;
  readonly chunkTimes: Float64Array;
  readonly chunkPerByte: Uint8Array;
  readonly ended: boolean;
}

export class ByteWindow {
  buf = new Uint8Array(INITIAL_CAPACITY);
  /** `buf` as 32-bit words: a frame that starts at a multiple of 4 is copied in four moves. */
  buf32 = new Uint32Array(this.buf.buffer);
  #view = new DataView(this.buf.buffer);
  /** The last range source and its DataView (kept while it is fed from): short ranges are copied four bytes at a time. */
  #source: Uint8Array | null = null;
  #sourceView: DataView | null = null;
  #chunkEnds = new Float64Array(INITIAL_CHUNKS);
  #chunkTimes = new Float64Array(INITIAL_CHUNKS);
  #chunkPerByte = new Uint8Array(INITIAL_CHUNKS);
  #chunkHead = 0;
  #chunkTail = 0;
  #byteTimes: Float64Array | null = null;
  /**
   * Doubles handed between calls go in typed-array slots, never as arguments or results: a
   * double passed to or returned from a call that is not inlined is boxed (an allocation).
   * `at[0]`: the time of the chunk being pushed; `when[0]`: what `dateNext` or `dateAny` dated.
   */
  readonly at = new Float64Array(1);
  readonly when = new Float64Array(1);
  /** Index in `buf` of the first byte not consumed. */
  head = 0;
  /** Index in `buf` after the last byte pushed. */
  tail = 0;
  /** Stream offset of `buf[0]`. */
  base = 0;
  ended = false;

  /** Appends [start, end) of `bytes`, timed `at[0]` (its last byte's time, µs). */
  pushTimed(bytes: Uint8Array, start: number, end: number): void {
    this.#check(bytes, start, end);
    const i = this.#append(bytes, null, start, end);
    if (i >= 0) this.#chunkTimes[i] = this.at[0] ?? Number.NaN;
  }

  /** Appends [start, end) of `bytes` with per-byte times (indexed like `bytes`), or none. */
  pushOther(bytes: Uint8Array, start: number, end: number, time: Float64Array | undefined): void {
    this.#check(bytes, start, end);
    const perByte = time instanceof Float64Array;
    if (perByte && time.length !== bytes.length) {
      throw new TypeError(`per-byte times have length ${time.length}, bytes ${bytes.length}`);
    }
    const i = this.#append(bytes, perByte ? time : null, start, end);
    if (i >= 0) this.#chunkTimes[i] = Number.NaN;
  }

  /** @throws {TypeError} after `end()`, and for a range that is not one of `bytes` */
  #check(bytes: Uint8Array, start: number, end: number): void {
    if (this.ended === true) throw new TypeError('push() after end(): call reset() to decode a new stream');
    if (!(start >= 0 && start <= end && end <= bytes.length && (start | 0) === start && (end | 0) === end))
      throw new TypeError(`[${start}, ${end}) is not a range of ${bytes.length} bytes`);
  }

  /** No more bytes will come. */
  end(): void {
    this.ended = true;
    this.#source = this.#sourceView = null;
  }

  /**
   * Copies a chunk's bytes (and per-byte times) in, compacting first and growing (doubling)
   * only when full, and records the chunk's end. Returns the chunk's index, for the caller to
   * store its time, or -1 for no bytes. One method for every kind of chunk and too big to be
   * inlined, so that the push paths that call it stay small enough to be.
   */
  #append(bytes: Uint8Array, byteTimes: Float64Array | null, start: number, end: number): number {
    const n = end - start;
    if (n === 0) return -1;
    let times = this.#byteTimes;
    if (this.head > 0 && (this.tail + n > this.buf.length || this.head >= this.buf.length >> 1)) {
      this.buf.copyWithin(0, this.head, this.tail);
      times?.copyWithin(0, this.head, this.tail);
      this.base += this.head;
      this.tail -= this.head;
      this.head = 0;
    }
    if (this.tail + n > this.buf.length) {
      // Doubled, or what this push needs (in whole 4 kB) when that is more: a stream pushed
      // whole takes its own size, not the next power of two.
      this.#grow(Math.max(this.buf.length * 2, Math.ceil((this.tail + n) / 4096) * 4096));
      times = this.#byteTimes;
    }
    const at = this.tail;
    const whole = start === 0 && end === bytes.length;
    if (whole) this.buf.set(bytes, at);
    else if (n <= 64) {
      // A capture's chunk, the usual range: copied four bytes at a time, cheaper than a view for set().
      if (bytes !== this.#source) {
        this.#source = bytes;
        this.#sourceView = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
      }
      const from = this.#sourceView as DataView;
      const to = this.#view;
      let k = 0;
      for (; k + 4 <= n; k += 4) to.setInt32(at + k, from.getInt32(start + k));
      for (; k < n; k++) this.buf[at + k] = bytes[start + k] as number;
    } else this.buf.set(bytes.subarray(start, end), at);
    if (byteTimes !== null) {
      if (times === null) this.#byteTimes = times = new Float64Array(this.buf.length);
      times.set(whole ? byteTimes : byteTimes.subarray(start, end), at);
    } else if (times !== null) times.fill(Number.NaN, at, at + n);
    if (this.#chunkTail === this.#chunkEnds.length) this.#roomForChunk();
    const i = this.#chunkTail++;
    this.#chunkEnds[i] = this.base + at + n;
    this.#chunkPerByte[i] = byteTimes !== null ? 1 : 0;
    this.tail = at + n;
    return i;
  }

  #grow(capacity: number): void {
    const buf = new Uint8Array(capacity);
    buf.set(this.buf.subarray(0, this.tail));
    this.buf = buf;
    this.buf32 = new Uint32Array(buf.buffer);
    this.#view = new DataView(buf.buffer);
    if (this.#byteTimes !== null) {
      const grown = new Float64Array(capacity);
      grown.set(this.#byteTimes.subarray(0, this.tail));
      this.#byteTimes = grown;
    }
  }

  /** The chunk records are full: compacted when mostly done with, else doubled. */
  #roomForChunk(): void {
    const head = this.#chunkHead;
    const live = this.#chunkTail - head;
    if (head >= live) {
      this.#chunkEnds.copyWithin(0, head, this.#chunkTail);
      this.#chunkTimes.copyWithin(0, head, this.#chunkTail);
      this.#chunkPerByte.copyWithin(0, head, this.#chunkTail);
    } else {
      this.#setChunks(
        this.#chunkEnds.subarray(head, this.#chunkTail),
        this.#chunkTimes.subarray(head, this.#chunkTail),
        this.#chunkPerByte.subarray(head, this.#chunkTail),
        this.#chunkEnds.length * 2,
      );
    }
    this.#chunkTail = live;
    this.#chunkHead = 0;
  }

  /** New chunk records of `size` holding the given ones. */
  #setChunks(ends: Float64Array, times: Float64Array, perByte: Uint8Array, size: number): void {
    this.#chunkEnds = new Float64Array(size);
    this.#chunkTimes = new Float64Array(size);
    this.#chunkPerByte = new Uint8Array(size);
    this.#chunkEnds.set(ends);
    this.#chunkTimes.set(times);
    this.#chunkPerByte.set(perByte);
    this.#chunkTail = ends.length;
    this.#chunkHead = 0;
  }

  /**
   * Dates the byte at stream offset `x`, held in chunk `i`, into `when[0]`: its own time, or
   * its chunk's time less one byte time for each byte after it in the chunk (NaN without times).
   */
  #dateInChunk(x: number, i: number): void {
    const byteTimes = this.#byteTimes;
    this.when[0] =
      this.#chunkPerByte[i] === 1 && byteTimes !== null
        ? byteTimes[x - this.base]!
        : byteInChunkUs(this.#chunkTimes[i]!, this.#chunkEnds[i]! - 1 - x);
  }

  /**
   * Dates the byte at stream offset `x` into `when[0]` and forgets the records of chunks before
   * its own: bytes are dated in stream order as frames are emitted.
   */
  dateNext(x: number): void {
    this.#dateInChunk(x, this.dropChunksBefore(x));
  }

  /**
   * Dates the byte at stream offset `x` into `when[0]`, keeping every record (events are rare:
   * the records are searched). NaN when the byte is not held or has not arrived yet.
   */
  dateAny(x: number): void {
    this.when[0] = Number.NaN;
    if (x < this.base || x >= this.base + this.tail) return;
    for (let i = this.#chunkHead; i < this.#chunkTail; i++) {
      if ((this.#chunkEnds[i] ?? 0) > x) {
        this.#dateInChunk(x, i);
        return;
      }
    }
  }

  /**
   * Whether two bytes next to each other among the `n` from buffer index `o`, both with times
   * of their own (per-byte times: a logic analyser's), came more than `gapUs` apart. Chunk times
   * say nothing of this (an adapter may hold a frame's last bytes back a while).
   */
  silenceWithin(o: number, n: number, gapUs: number): boolean {
    const t = this.#byteTimes;
    if (t === null) return false;
    const end = Math.min(o + n, this.tail);
    for (let i = o + 1; i < end; i++) if ((t[i] as number) - (t[i - 1] as number) > gapUs) return true;
    return false;
  }

  /** Forgets the records of chunks that end at or before stream offset `x` (keeps the last one); returns the first kept. */
  dropChunksBefore(x: number): number {
    const ends = this.#chunkEnds;
    const last = this.#chunkTail - 1;
    let i = this.#chunkHead;
    while (i < last && ends[i]! <= x) i++;
    this.#chunkHead = i;
    return i;
  }

  /** Consumes bytes up to buffer index `o`; a stream that never locks must lose its chunk records with its bytes. */
  consumeTo(o: number): void {
    this.head = o;
    this.dropChunksBefore(this.base + o);
  }

  /** Empty, as new. */
  clear(): void {
    this.head = this.tail = this.base = 0;
    this.#chunkHead = this.#chunkTail = 0;
    this.ended = false;
    this.#source = this.#sourceView = null;
  }

  snapshot(): WindowSnapshot {
    const h = this.#chunkHead;
    const t = this.#chunkTail;
    return {
      bytes: this.buf.slice(this.head, this.tail),
      byteTimes: this.#byteTimes === null ? null : this.#byteTimes.slice(this.head, this.tail),
      base: this.base + this.head,
      chunkEnds: this.#chunkEnds.slice(h, t),
      chunkTimes: this.#chunkTimes.slice(h, t),
      chunkPerByte: this.#chunkPerByte.slice(h, t),
      ended: this.ended,
    };
  }

  /** Back to `snapshot`'s bytes and records (copied: it can be restored again). */
  restore(snapshot: WindowSnapshot): void {
    const n = snapshot.bytes.length;
    let capacity = INITIAL_CAPACITY;
    while (capacity < n) capacity *= 2;
    this.#byteTimes = null;
    this.tail = 0;
    this.#grow(capacity);
    this.buf.set(snapshot.bytes);
    if (snapshot.byteTimes !== null) {
      this.#byteTimes = new Float64Array(capacity);
      this.#byteTimes.set(snapshot.byteTimes);
    }
    this.head = 0;
    this.tail = n;
    this.base = snapshot.base;
    this.ended = snapshot.ended;
    this.#source = this.#sourceView = null;
    let size = INITIAL_CHUNKS;
    while (size < snapshot.chunkEnds.length) size *= 2;
    this.#setChunks(snapshot.chunkEnds, snapshot.chunkTimes, snapshot.chunkPerByte, size);
  }
}
