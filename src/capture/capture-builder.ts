/**
 * A capture put together from its records as they are walked (record-walk.ts), for a reader
 * that walks the file anyway and would otherwise parse it again: the replay decodes a long
 * capture straight from the file's pieces, and keeps it this way (src/worker/replay/replay-split.ts).
 * Fed every record of an intact file, each checked, it is the capture `parseCapture` reads:
 * the same columns, events, timing and header. It cannot tell an intact file from a damaged
 * one; whoever feeds it must know (a walk that ended, every CRC checked).
 */
import {
  RECORD_HEADER_SIZE,
  RECORD_OVERHEAD,
  RECORD_TYPE_DATA,
  RECORD_TYPE_EVENT,
  REC_OFF_LENGTH,
  REC_OFF_PORT,
  REC_OFF_TIME,
  REC_OFF_TYPE,
} from './layout.js';
import type { CaptureEvent, ParsedCapture } from './model.js';
import type { HeaderResult } from './header.js';
import { copyPayload, grown, trimTo } from './records.js';
import { utf8Decode } from './text.js';
import { stepOverBadTimes } from './time-rule.js';

/** Room for this many records and payload bytes at first: then as `expect` guesses, growing by half as needed. */
const FIRST_RECORDS = 1 << 12;
const FIRST_BYTES = 1 << 16;

export class CaptureBuilder {
  #data = new Uint8Array(FIRST_BYTES);
  #dataView = new DataView(this.#data.buffer);
  #ends = new Uint32Array(FIRST_RECORDS);
  #times = new Float64Array(FIRST_RECORDS);
  #ports = new Uint8Array(FIRST_RECORDS);
  #dataLength = 0;
  #chunks = 0;
  #anyTime = false;
  #expected = false;
  readonly #events: CaptureEvent[] = [];

  /**
   * Room for `records` chunks of `dataBytes` in all (a guess from the file's start, before any
   * record is fed), made now and every page of it written once: the system maps a column's
   * memory where it is first written, and doing that here, while the walk waits for the file,
   * keeps it off the walk (about 0.2 s of the day capture's 0.4 GB of columns). Instead of
   * `expect`; growing still covers a guess that falls short.
   */
  reserve(records: number, dataBytes: number): void {
    if (this.#chunks > 0 || !(records > 0 && dataBytes > 0)) return;
    this.#expected = true;
    this.#grow(Math.ceil(dataBytes), Math.ceil(records));
    for (const column of [this.#data, this.#ends, this.#times, this.#ports]) {
      const step = 4096 / column.BYTES_PER_ELEMENT;
      for (let i = 0; i < column.length; i += step) column[i] = 0;
    }
  }

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

  /**
   * Records one after the other, `bytes[from, to)` (`view` over `bytes`), their headers read
   * intact: each data record's payload goes to the columns, each event to the events.
   */
  records(bytes: Uint8Array, view: DataView, from: number, to: number): void {
    let data = this.#data;
    let dataView = this.#dataView;
    let ends = this.#ends;
    let times = this.#times;
    let ports = this.#ports;
    let at = this.#dataLength;
    let i = this.#chunks;
    let anyTime = this.#anyTime;
    for (let p = from; p < to; ) {
      const len = view.getUint32(p + REC_OFF_LENGTH, true);
      const timeUs = view.getFloat64(p + REC_OFF_TIME, true);
      const port = bytes[p + REC_OFF_PORT] ?? 0;
      const payload = p + RECORD_HEADER_SIZE;
      if (bytes[p + REC_OFF_TYPE] === RECORD_TYPE_DATA) {
        if (i === ends.length || at + len > data.length) {
          this.#dataLength = at;
          this.#chunks = i;
          this.#grow(at + len, i + 1);
          ({ data, dataView, ends, times, ports } = this.#columns());
        }
        copyPayload(data, dataView, at, bytes, view, payload, len);
        at += len;
        ends[i] = at;
        times[i] = timeUs;
        ports[i] = port;
        i++;
        if (!Number.isNaN(timeUs)) anyTime = true;
      } else if (bytes[p + REC_OFF_TYPE] === RECORD_TYPE_EVENT) {
        this.#events.push({ timeUs, port, text: utf8Decode(bytes, payload, payload + len), chunkIndex: i });
      }
      p += RECORD_OVERHEAD + len;
    }
    this.#dataLength = at;
    this.#chunks = i;
    this.#anyTime = anyTime;
  }

  #columns() {
    return { data: this.#data, dataView: this.#dataView, ends: this.#ends, times: this.#times, ports: this.#ports };
  }

  /** The capture of every record fed, with `header`'s metadata; the builder is not to be fed after. */
  capture(header: HeaderResult): ParsedCapture {
    const n = this.#chunks;
    return stepOverBadTimes({
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
    });
  }

  /** Room for at least `bytes` and `records`, by half as much again. */
  #grow(bytes: number, records: number): void {
    if (bytes > this.#data.length) {
      this.#data = grown(new Uint8Array(Math.max(bytes, Math.ceil(this.#data.length * 1.5))), this.#data.subarray(0, this.#dataLength));
      this.#dataView = new DataView(this.#data.buffer);
    }
    if (records > this.#ends.length) {
      const size = Math.max(records, Math.ceil(this.#ends.length * 1.5));
      this.#ends = grown(new Uint32Array(size), this.#ends.subarray(0, this.#chunks));
      this.#times = grown(new Float64Array(size), this.#times.subarray(0, this.#chunks));
      this.#ports = grown(new Uint8Array(size), this.#ports.subarray(0, this.#chunks));
    }
  }
}
