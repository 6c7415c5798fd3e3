/**
 * A capture's chunk facts (facts.ts) found as its records are walked (record-walk.ts's runs),
 * for a reader that walks the file anyway: a long capture's replay, whose other half keeps the
 * capture (src/worker/replay/replay-split.ts), seeds them into it and plays at once, where each
 * fact was otherwise one pass over eleven million chunks. Fed every record of the file in order,
 * it finds what those passes find over the capture the file reads as; the span is told to a
 * tally of its own (`SpanSink`: the analysis's, which knows the line rate chunks are dated by).
 */
import type { ChunkFacts } from './facts.js';
import { RECORD_OVERHEAD, RECORD_TYPE_DATA, REC_OFF_LENGTH, REC_OFF_PORT, REC_OFF_TIME, REC_OFF_TYPE } from './layout.js';

/** Where the chunks' and events' times go for the capture's span (the analysis's SpanTally). */
export interface SpanSink {
  /** A chunk of `count` bytes that arrived at `arrivalUs`. */
  chunk(arrivalUs: number, count: number): void;
  event(timeUs: number): void;
}

/** Room for this many chunk numbers a port at first, doubled as needed. */
const FIRST_ROOM = 1 << 12;

export class RecordTally<Span extends SpanSink = SpanSink> {
  /** Data records so far: the next chunk's number. */
  #chunks = 0;
  readonly #counts = new Uint32Array(256);
  /** Each port's chunk numbers so far (its first `#counts[port]`). */
  readonly #index: (Uint32Array | undefined)[] = [];
  /** The last chunk's time, in a typed array (see SpanTally: a cold walk's double local is boxed). */
  readonly #last = new Float64Array([Number.NEGATIVE_INFINITY]);
  #inOrder = true;

  /** @param span gets every chunk's and event's time, for the capture's span */
  constructor(readonly span: Span) {}

  /** Records one after the other, `bytes[from, to)` (`view` over `bytes`), whole and in the file's order. */
  records(bytes: Uint8Array, view: DataView, from: number, to: number): void {
    const counts = this.#counts;
    const last = this.#last;
    let chunk = this.#chunks;
    let inOrder = this.#inOrder;
    for (let p = from; p < to; ) {
      const len = view.getUint32(p + REC_OFF_LENGTH, true);
      const timeUs = view.getFloat64(p + REC_OFF_TIME, true);
      if (bytes[p + REC_OFF_TYPE] === RECORD_TYPE_DATA) {
        const port = bytes[p + REC_OFF_PORT] ?? 0;
        const k = counts[port] ?? 0;
        let index = this.#index[port];
        if (index === undefined || k === index.length) index = this.#grow(port, k);
        index[k] = chunk;
        counts[port] = k + 1;
        chunk++;
        // As timesInOrder: never earlier than the chunk before, never NaN.
        if (!(timeUs >= (last[0] ?? Number.NaN))) inOrder = false;
        last[0] = timeUs;
        if (len > 0) this.span.chunk(timeUs, len);
      } else this.span.event(timeUs);
      p += RECORD_OVERHEAD + len;
    }
    this.#chunks = chunk;
    this.#inOrder = inOrder;
  }

  #grow(port: number, count: number): Uint32Array {
    const old = this.#index[port];
    const grown = new Uint32Array(old === undefined ? FIRST_ROOM : old.length * 2);
    if (old !== undefined) grown.set(old.subarray(0, count));
    this.#index[port] = grown;
    return grown;
  }

  /** The facts of every record fed. */
  facts(): ChunkFacts {
    const counts = this.#counts.slice();
    const portIndex = Array.from(counts, (n, port) => this.#index[port]?.subarray(0, n) ?? new Uint32Array(0));
    return { chunksByPort: counts, timesInOrder: this.#inOrder, portIndex };
  }
}
