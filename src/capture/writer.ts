/**
 * Writing .sscap files: incrementally (`CaptureWriter`) or at once (`encodeCapture`).
 */
import { utf8Encode } from './text.js';
import { crc32 } from './crc32.js';
import {
  CAPTURE_FORMAT_VERSION,
  CRC_SIZE,
  HEADER_FIXED_SIZE,
  MAGIC,
  MAX_META_BYTES,
  MAX_RECORD_PAYLOAD,
  OFF_META_LENGTH,
  OFF_VERSION,
  RECORD_HEADER_SIZE,
  RECORD_OVERHEAD,
  RECORD_TYPE_DATA,
  RECORD_TYPE_EVENT,
  REC_OFF_LENGTH,
  REC_OFF_PORT,
  REC_OFF_TIME,
  REC_OFF_TYPE,
  SYNC0,
  SYNC1,
} from './layout.js';
import { IndexBuilder } from './capture-index.js';
import { cleanMeta, isPlainObject } from './meta.js';
import type { CaptureMeta } from './model.js';

function checkTime(timeUs: unknown): number {
  if (typeof timeUs !== 'number' || timeUs === Infinity || timeUs === -Infinity) {
    throw new TypeError(`timeUs must be a finite number of µs, or NaN for "unknown" (got ${String(timeUs)})`);
  }
  return timeUs;
}

function checkPort(port: unknown): number {
  if (typeof port !== 'number' || !Number.isInteger(port) || port < 0 || port > 255) {
    throw new TypeError(`port must be an integer from 0 to 255 (got ${String(port)})`);
  }
  return port;
}

function checkPayload(length: number): void {
  if (length > MAX_RECORD_PAYLOAD) {
    throw new TypeError(`a record holds at most ${MAX_RECORD_PAYLOAD} bytes (got ${length}); split the chunk`);
  }
}

/** Writes one record at `offset` of `target` (which must have room for it); returns its size. */
function writeRecord(target: Uint8Array, offset: number, type: number, port: number, timeUs: number, payload: Uint8Array): number {
  const view = new DataView(target.buffer, target.byteOffset, target.byteLength);
  const len = payload.length;
  target[offset] = SYNC0;
  target[offset + 1] = SYNC1;
  target[offset + REC_OFF_TYPE] = type;
  target[offset + REC_OFF_PORT] = port;
  view.setUint32(offset + REC_OFF_LENGTH, len, true);
  view.setFloat64(offset + REC_OFF_TIME, timeUs, true);
  target.set(payload, offset + RECORD_HEADER_SIZE);
  const crcEnd = offset + RECORD_HEADER_SIZE + len;
  // The CRC covers type through payload; the sync bytes are checked by matching them.
  view.setUint32(crcEnd, crc32(target, offset + REC_OFF_TYPE, crcEnd, view), true);
  return RECORD_OVERHEAD + len;
}

function encodeHeader(meta: CaptureMeta): Uint8Array {
  const json = utf8Encode(JSON.stringify(meta));
  if (json.length > MAX_META_BYTES) {
    throw new TypeError(`meta is ${json.length} bytes as JSON; the limit is ${MAX_META_BYTES}`);
  }
  const out = new Uint8Array(HEADER_FIXED_SIZE + json.length + CRC_SIZE);
  const view = new DataView(out.buffer);
  out.set(MAGIC, 0);
  view.setUint16(OFF_VERSION, CAPTURE_FORMAT_VERSION, true);
  // Bytes 10–11: flags, reserved, written as 0.
  view.setUint32(OFF_META_LENGTH, json.length, true);
  out.set(json, HEADER_FIXED_SIZE);
  const crcAt = HEADER_FIXED_SIZE + json.length;
  view.setUint32(crcAt, crc32(out, 0, crcAt), true);
  return out;
}

/**
 * Encodes a capture a piece at a time, so a recorder can append to a file (or OPFS) as bytes
 * arrive without keeping the capture in memory. Write `header()` first, then the bytes each
 * `data()` / `event()` call returns, in order, and those of `close()` last. The writer indexes
 * the records as it goes (docs/capture-format.md, "Index"): now and then a call returns an
 * index segment after its record, and `close()` returns the final one.
 *
 * ```ts
 * const w = new CaptureWriter({ createdAt: new Date().toISOString(), baudRate: 115200, source: 'webserial' });
 * await file.write(w.header());
 * await file.write(w.data(chunk, performance.now() * 1000));
 * await file.write(w.close());
 * ```
 */
export class CaptureWriter {
  /** The metadata as stored (a validated copy). */
  readonly meta: CaptureMeta;
  readonly #header: Uint8Array;
  readonly #index = new IndexBuilder();
  /** File offset of the next record: the bytes handed out so far. */
  #at: number;
  #closed = false;

  /** @throws {TypeError} when `meta` has a field of the wrong type or is larger than 1 MiB as JSON. */
  constructor(meta: CaptureMeta = {}) {
    const problems: string[] = [];
    this.meta = cleanMeta(meta, problems);
    if (problems.length > 0) throw new TypeError(`invalid capture metadata: ${problems.join('; ')}`);
    this.#header = encodeHeader(this.meta);
    this.#at = this.#header.length;
  }

  /** The file header: the first bytes of the file. A fresh copy on each call. */
  header(): Uint8Array {
    return this.#header.slice();
  }

  /**
   * One data record: `bytes` exactly as received, `timeUs` the arrival time (µs, of the chunk's
   * last byte; NaN if unknown) on the recorder's clock. Returns the bytes to append.
   * @throws {TypeError} on a non-Uint8Array, an infinite time, a port outside 0–255, or a chunk over 16 MiB.
   */
  data(bytes: Uint8Array, timeUs: number, port = 0): Uint8Array {
    if (!(bytes instanceof Uint8Array)) throw new TypeError('bytes must be a Uint8Array');
    checkPayload(bytes.length);
    this.#open();
    const record = new Uint8Array(RECORD_OVERHEAD + bytes.length);
    writeRecord(record, 0, RECORD_TYPE_DATA, checkPort(port), checkTime(timeUs), bytes);
    this.#index.data(this.#at, timeUs, port, bytes.length);
    return this.#out(record);
  }

  /**
   * One event record (e.g. "port opened", "device lost"). Returns the bytes to append.
   * @throws {TypeError} on a non-string text, an infinite time or a port outside 0–255.
   */
  event(text: string, timeUs: number, port = 0): Uint8Array {
    if (typeof text !== 'string') throw new TypeError('event text must be a string');
    const payload = utf8Encode(text);
    checkPayload(payload.length);
    this.#open();
    const record = new Uint8Array(RECORD_OVERHEAD + payload.length);
    writeRecord(record, 0, RECORD_TYPE_EVENT, checkPort(port), checkTime(timeUs), payload);
    this.#index.event();
    return this.#out(record);
  }

  /**
   * The last bytes of the file: the final index segment (the capture's span and counts, and
   * where each stretch of it starts). A file without them is read as before, by a plain scan
   * of what the segments written so far do not cover.
   * @throws {TypeError} when called twice.
   */
  close(): Uint8Array {
    this.#open();
    this.#closed = true;
    return this.#index.segment(this.#at, true);
  }

  #open(): void {
    if (this.#closed) throw new TypeError('the capture is closed: nothing can follow its final index');
  }

  /** `record`, with an index segment after it when one is due. */
  #out(record: Uint8Array): Uint8Array {
    this.#at += record.length;
    if (!this.#index.due(this.#at)) return record;
    const segment = this.#index.segment(this.#at, false);
    const out = new Uint8Array(record.length + segment.length);
    out.set(record, 0);
    out.set(segment, record.length);
    this.#at += segment.length;
    return out;
  }
}

/** A record for `encodeCapture`. `port` defaults to 0. */
export type CaptureRecordInput =
  | { type: 'data'; bytes: Uint8Array; timeUs: number; port?: number }
  | { type: 'event'; text: string; timeUs: number; port?: number };

/**
 * A whole .sscap file in one buffer: the same bytes as a `CaptureWriter` given the records in
 * order and then closed (header, records, index).
 * @throws {TypeError} on invalid metadata or records (see `CaptureWriter`).
 */
export function encodeCapture(meta: CaptureMeta, records: readonly CaptureRecordInput[]): Uint8Array {
  const writer = new CaptureWriter(meta);
  const parts = [writer.header()];
  for (const [i, r] of records.entries()) {
    if (!isPlainObject(r)) throw new TypeError(`records[${i}] must be an object`);
    if (r.type === 'data') {
      if (!(r.bytes instanceof Uint8Array)) throw new TypeError(`records[${i}].bytes must be a Uint8Array`);
      parts.push(writer.data(r.bytes, r.timeUs, r.port ?? 0));
    } else if (r.type === 'event') {
      if (typeof r.text !== 'string') throw new TypeError(`records[${i}].text must be a string`);
      parts.push(writer.event(r.text, r.timeUs, r.port ?? 0));
    } else {
      throw new TypeError(`records[${i}].type must be 'data' or 'event'`);
    }
  }
  parts.push(writer.close());
  const out = new Uint8Array(parts.reduce((n, part) => n + part.length, 0));
  let at = 0;
  for (const part of parts) {
    out.set(part, at);
    at += part.length;
  }
  return out;
}
