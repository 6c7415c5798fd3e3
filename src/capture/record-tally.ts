/**
 * A capture's chunk facts (facts.ts) found as its records are walked (record-walk.ts's runs),
 * for a reader that walks the file anyway: a long capture's replay, whose other half keeps the
 * capture (src/worker/replay/replay-split.ts), seeds them into it and plays at once, where each
 * fact was otherwise one pass over eleven million chunks. Fed every record of the file in order,
 * it finds what those passes find over the capture the file reads as, and the earliest and
 * latest time of any byte or event, the span's makings (the analysis's spanBetween says what they
 * make; the line rate chunks are dated by is the caller's).
 *
 * The walk's loop makes no call a record and keeps each branch's times apart. In Chromium 150,
 * one double variable set in both branches (or to NaN) made a heap number a record (316 MB of
 * garbage in the worker over the day capture, by the page bench's figure), and the span tally's
 * methods, called a chunk, were not inlined (46 ms of the worker's CPU profile).
 */
import { type ChunkFacts, indexByPort } from './facts.js';
import { RECORD_OVERHEAD, RECORD_TYPE_DATA, REC_OFF_LENGTH, REC_OFF_PORT, REC_OFF_TIME, REC_OFF_TYPE } from './layout.js';
import { chunkFirstByteUs } from './model.js';

/** Room for this many chunks' ports at first, then doubled as needed (one byte a chunk). */
const FIRST_ROOM = 1 << 12;

export class RecordTally {
  /** Data records so far: the next chunk's number. */
  #chunks = 0;
  readonly #counts = new Uint32Array(256);
  /** Each chunk's port, sorted into each port's chunk numbers at the end (`indexByPort`). */
  #ports: Uint8Array = new Uint8Array(FIRST_ROOM);
  /** The last chunk's time, the earliest and the latest time of a byte or event: a typed array (a cold walk's double locals are boxed). */
  readonly #times = new Float64Array([Number.NEGATIVE_INFINITY, Number.POSITIVE_INFINITY, Number.NEGATIVE_INFINITY]);
  #inOrder = true;

  /** @param byteTimeUs how far apart a chunk's bytes arrived, for dating its first byte (the line rate's byte time) */
  constructor(readonly byteTimeUs: number) {}

  /**
   * Room for `records` chunks at once (a guess from the file's start, before any record is fed):
   * the column is not grown and copied on the way, eleven million chunks a day. Growing still
   * covers a guess that falls short.
   */
  reserve(records: number): void {
    if (this.#chunks === 0 && records > this.#ports.length) this.#ports = new Uint8Array(Math.ceil(records));
  }

  /** Records one after the other, `bytes[from, to)` (`view` over `bytes`), whole and in the file's order. */
  records(bytes: Uint8Array, view: DataView, from: number, to: number): void {
    const counts = this.#counts;
    const times = this.#times;
    const byteTimeUs = this.byteTimeUs;
    let ports = this.#ports;
    let chunk = this.#chunks;
    let inOrder = this.#inOrder;
    for (let p = from; p < to; ) {
      const len = view.getUint32(p + REC_OFF_LENGTH, true);
      const timeUs = view.getFloat64(p + REC_OFF_TIME, true);
      // An event is at its time; a chunk from its first byte to its last (an empty one nowhere).
      // Each branch keeps its own times: one double variable set in both (or to NaN) was a heap
      // number a record in Chromium 150.
      if (bytes[p + REC_OFF_TYPE] === RECORD_TYPE_DATA) {
        const port = bytes[p + REC_OFF_PORT] ?? 0;
        if (chunk === ports.length) ports = this.#grow(chunk);
        ports[chunk] = port;
        counts[port] = (counts[port] ?? 0) + 1;
        chunk++;
        // As timesInOrder: never earlier than the chunk before, never NaN.
        if (!(timeUs >= (times[0] ?? Number.NaN))) inOrder = false;
        times[0] = timeUs;
        if (len > 0) {
          const firstUs = chunkFirstByteUs(timeUs, len, byteTimeUs);
          if (firstUs < (times[1] ?? Number.NaN)) times[1] = firstUs;
          if (timeUs > (times[2] ?? Number.NaN)) times[2] = timeUs;
        }
      } else {
        if (timeUs < (times[1] ?? Number.NaN)) times[1] = timeUs;
        if (timeUs > (times[2] ?? Number.NaN)) times[2] = timeUs;
      }
      p += RECORD_OVERHEAD + len;
    }
    this.#chunks = chunk;
    this.#inOrder = inOrder;
  }

  #grow(count: number): Uint8Array {
    const grown = new Uint8Array(this.#ports.length * 2);
    grown.set(this.#ports.subarray(0, count));
    this.#ports = grown;
    return grown;
  }

  /** The facts of every record fed, and the earliest and latest time of a byte or event in them (Infinity and -Infinity: none). */
  facts(): ChunkFacts & { firstUs: number; lastUs: number } {
    const counts = this.#counts.slice();
    return {
      chunksByPort: counts,
      timesInOrder: this.#inOrder,
      portIndex: indexByPort(this.#ports.subarray(0, this.#chunks), counts),
      firstUs: this.#times[1] ?? Number.NaN,
      lastUs: this.#times[2] ?? Number.NaN,
    };
  }
}
