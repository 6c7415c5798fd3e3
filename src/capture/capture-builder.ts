/**
 * A capture put together from its records as they are walked (record-walk.ts), for a reader
 * that walks the file anyway and would otherwise parse it again: the replay decodes a long
 * capture straight from the file's pieces, and keeps it this way (src/worker/replay-split.ts).
 * Fed every record of an intact file, each checked, it is the capture `parseCapture` reads:
 * the same columns, events, timing and header. It cannot tell an intact file from a damaged
 * one; whoever feeds it must know (a walk that ended, every CRC checked).
 */
import type { CaptureEvent, ParsedCapture } from './model.js';
import { copyPayload, trimTo } from './reader.js';
import type { WalkedHeader } from './record-walk.js';
import { utf8Decode } from './text.js';

/** Room for this many records and payload bytes at first: then as `expect` guesses, growing by half as needed. */
const FIRST_RECORDS = 1 << 12;
const FIRST_BYTES = 1 << 16;

export class CaptureBuilder {
  #data = new Uint8Array(FIRST_BYTES);
  #dataView = new DataView(this.#data.buffer);
  /** The slice records are copied from, and a view of it (made once per slice, not per record). */
  #from: Uint8Array | null = null;
  #fromView: DataView<ArrayBufferLike> = new DataView(new ArrayBuffer(0));
  #ends = new Uint32Array(FIRST_RECORDS);
  #times = new Float64Array(FIRST_RECORDS);
  #ports = new Uint8Array(FIRST_RECORDS);
  #dataLength = 0;
  #chunks = 0;
  #anyTime = false;
  #expected = false;
  readonly #events: CaptureEvent[] = [];

  /**
   * The records fed so far came from the first `walked` bytes of a file of `size`: room is made
   * at once for the rest at the same rate (and 3 % more), once, so that the columns are not
   * grown and copied on the way. Growing still covers a guess that falls short.
   */
  expect(walked: number, size: number): void {
    if (this.#expected || walked <= 0 || this.#chunks === 0) return;
    this.#expected = true;
    const scale = (1.03 * size) / walked;
    this.#grow(Math.ceil(this.#dataLength * scale), Math.ceil(this.#chunks * scale));
  }

  /** A data record: its payload `bytes[start, end)`, recorded at `timeUs` on `port`. */
  data(bytes: Uint8Array, start: number, end: number, timeUs: number, port: number): void {
    const len = end - start;
    if (this.#chunks === this.#ends.length || this.#dataLength + len > this.#data.length)
      this.#grow(this.#dataLength + len, this.#chunks + 1);
    if (bytes !== this.#from) {
      this.#from = bytes;
      this.#fromView = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    }
    const at = this.#dataLength;
    copyPayload(this.#data, this.#dataView, at, bytes, this.#fromView, start, len);
    this.#dataLength = at + len;
    const i = this.#chunks++;
    this.#ends[i] = at + len;
    this.#times[i] = timeUs;
    this.#ports[i] = port;
    if (!Number.isNaN(timeUs)) this.#anyTime = true;
  }

  /** An event record: its text (UTF-8) `bytes[start, end)`, recorded at `timeUs` on `port`, among the chunks where it came. */
  event(bytes: Uint8Array, start: number, end: number, timeUs: number, port: number): void {
    this.#events.push({ timeUs, port, text: utf8Decode(bytes, start, end), chunkIndex: this.#chunks });
  }

  /** The capture of every record fed, with `header`'s metadata; the builder is not to be fed after. */
  capture(header: WalkedHeader): ParsedCapture {
    this.#from = null; // the last slice is not held
    const n = this.#chunks;
    return {
      kind: 'sscap',
      meta: header.meta,
      timing: this.#anyTime ? 'per-chunk' : 'none',
      bytes: trimTo(this.#data, this.#dataLength),
      chunkEnds: trimTo(this.#ends, n),
      chunkTimesUs: trimTo(this.#times, n),
      chunkPorts: trimTo(this.#ports, n),
      events: this.#events,
      issues: [],
      version: header.version,
      headerLength: header.headerLength,
    };
  }

  /** Room for at least `bytes` and `records`, by half as much again. */
  #grow(bytes: number, records: number): void {
    if (bytes > this.#data.length) {
      this.#data = copied(new Uint8Array(Math.max(bytes, Math.ceil(this.#data.length * 1.5))), this.#data, this.#dataLength);
      this.#dataView = new DataView(this.#data.buffer);
    }
    if (records > this.#ends.length) {
      const size = Math.max(records, Math.ceil(this.#ends.length * 1.5));
      this.#ends = copied(new Uint32Array(size), this.#ends, this.#chunks);
      this.#times = copied(new Float64Array(size), this.#times, this.#chunks);
      this.#ports = copied(new Uint8Array(size), this.#ports, this.#chunks);
    }
  }
}

function copied<T extends Uint8Array | Uint32Array | Float64Array>(to: T, from: T, length: number): T {
  to.set(from.subarray(0, length));
  return to;
}
