/**
 * A capture's chunk facts (facts.ts) found as its records are walked (record-walk.ts's runs),
 * for a reader that walks the file anyway: a long capture's replay, whose other half keeps the
 * capture (src/worker/replay/replay-split.ts), seeds them into it and plays at once, where each
 * fact was otherwise one pass over eleven million chunks. Fed every record of the file in order,
 * it finds what those passes find over the capture the file reads as, and the earliest and
 * latest time of any byte or event, the span's makings (the analysis's spanBetween says what they
 * make; the line rate chunks are dated by is the caller's).
 *
 * The walk's loop makes no call a record and keeps each branch's times apart: one double
 * variable set in both branches (or to NaN) is boxed, an allocation a record (bench/README.md).
 */
import type { ChunkFacts } from './facts.js';
import {
  RECORD_OVERHEAD,
  RECORD_TYPE_DATA,
  RECORD_TYPE_EVENT,
  REC_OFF_LENGTH,
  REC_OFF_PORT,
  REC_OFF_TIME,
  REC_OFF_TYPE,
} from './layout.js';
import { chunkFirstByteUs } from './model.js';

/** Room for this many of a port's chunks at first when none was guessed, then grown by half as needed (4 bytes a chunk). */
const FIRST_ROOM = 1 << 10;

export class RecordTally {
  /** Data records so far: the next chunk's number. */
  #chunks = 0;
  readonly #counts = new Uint32Array(256);
  /**
   * Each port's chunk numbers so far (`#counts[p]` of them), written as the records come: the
   * port index is ready when the walk ends. A counting sort of eleven million chunks at the end
   * took 0.15 s of the day capture's open, with the walk's other half waiting for it.
   */
  readonly #lists: (Uint32Array | undefined)[] = new Array<Uint32Array | undefined>(256).fill(undefined);
  /** The last chunk's time, the earliest and the latest time of a byte or event: a typed array (a cold walk's double locals are boxed). */
  readonly #times = new Float64Array([Number.NEGATIVE_INFINITY, Number.POSITIVE_INFINITY, Number.NEGATIVE_INFINITY]);
  #inOrder = true;

  /** @param byteTimeUs how far apart a chunk's bytes arrived, for dating its first byte (the line rate's byte time) */
  constructor(readonly byteTimeUs: number) {}

  /**
   * Room for `chunksByPort[p]` chunks of each port at once (a guess from the file's start, before
   * any record is fed): the lists are not grown and copied on the way, eleven million chunks a
   * day. Growing still covers a guess that falls short.
   */
  reserve(chunksByPort: ArrayLike<number>): void {
    if (this.#chunks > 0) return;
    for (let p = 0; p < 256; p++) {
      const n = chunksByPort[p] ?? 0;
      if (n > 0) this.#lists[p] = new Uint32Array(Math.ceil(n));
    }
  }

  /** Records one after the other, `bytes[from, to)` (`view` over `bytes`), whole and in the file's order. */
  records(bytes: Uint8Array, view: DataView, from: number, to: number): void {
    const counts = this.#counts;
    const times = this.#times;
    const byteTimeUs = this.byteTimeUs;
    const lists = this.#lists;
    let chunk = this.#chunks;
    let inOrder = this.#inOrder;
    for (let p = from; p < to; ) {
      const len = view.getUint32(p + REC_OFF_LENGTH, true);
      const timeUs = view.getFloat64(p + REC_OFF_TIME, true);
      // An event is at its time; a chunk from its first byte to its last (an empty one nowhere).
      // Each branch keeps its own times (see the file's comment).
      if (bytes[p + REC_OFF_TYPE] === RECORD_TYPE_DATA) {
        const port = bytes[p + REC_OFF_PORT] ?? 0;
        const n = counts[port] ?? 0;
        let list = lists[port];
        if (list === undefined || n === list.length) list = this.#grow(port, n);
        list[n] = chunk;
        counts[port] = n + 1;
        chunk++;
        // As timesInOrder: never earlier than the chunk before, never NaN.
        if (!(timeUs >= (times[0] ?? Number.NaN))) inOrder = false;
        times[0] = timeUs;
        if (len > 0) {
          const firstUs = chunkFirstByteUs(timeUs, len, byteTimeUs);
          if (firstUs < (times[1] ?? Number.NaN)) times[1] = firstUs;
          if (timeUs > (times[2] ?? Number.NaN)) times[2] = timeUs;
        }
      } else if (bytes[p + REC_OFF_TYPE] === RECORD_TYPE_EVENT) {
        if (timeUs < (times[1] ?? Number.NaN)) times[1] = timeUs;
        if (timeUs > (times[2] ?? Number.NaN)) times[2] = timeUs;
      }
      p += RECORD_OVERHEAD + len;
    }
    this.#chunks = chunk;
    this.#inOrder = inOrder;
  }

  /** Port `port`'s list with room for more than its `count` chunks. */
  #grow(port: number, count: number): Uint32Array {
    const grown = new Uint32Array(Math.max(FIRST_ROOM, count + (count >> 1)));
    const list = this.#lists[port];
    if (list !== undefined) grown.set(list.subarray(0, count));
    this.#lists[port] = grown;
    return grown;
  }

  /** The facts of every record fed, and the earliest and latest time of a byte or event in them (Infinity and -Infinity: none). */
  facts(): ChunkFacts & { firstUs: number; lastUs: number } {
    const counts = this.#counts.slice();
    return {
      chunksByPort: counts,
      timesInOrder: this.#inOrder,
      portIndex: Array.from(this.#lists, (list, p) => list?.subarray(0, counts[p] ?? 0) ?? new Uint32Array(0)),
      firstUs: this.#times[1] ?? Number.NaN,
      lastUs: this.#times[2] ?? Number.NaN,
    };
  }
}
