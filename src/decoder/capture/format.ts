/**
 * The in-memory capture model shared by every importer, and the SatScope binary capture file
 * (".sscap"): its writer and its reader. The byte layout is documented in
 * docs/capture-format.md; the constants below are the single source of truth for it.
 *
 * Pure ECMAScript: no DOM, no Node, no clock. Times are whatever the caller recorded.
 */

import { utf8Decode, utf8Encode } from './utf8.js';

// ---------------------------------------------------------------------------------------------
// Model
// ---------------------------------------------------------------------------------------------

/** A metadata value that is not a list: what the free-form metadata fields may hold. */
export type MetaScalar = string | number | boolean | null;

/** What is known about one serial port of a capture (entry `i` describes port index `i`). */
export interface CapturePortInfo {
  /** A label, e.g. the Saleae analyser name or "satellite A". */
  name?: string;
  baudRate?: number;
  usbVendorId?: number;
  usbProductId?: number;
  [key: string]: MetaScalar | undefined;
}

/**
 * Capture metadata: a JSON object of known optional fields plus free-form scalar fields. The
 * writer stores it verbatim; nothing here is read from a clock, so `createdAt` is whatever the
 * recorder put there.
 */
export interface CaptureMeta {
  /** When recording started, ISO 8601 (e.g. `new Date().toISOString()`). */
  createdAt?: string;
  /** Line rate the port was opened at (115200 for Spektrum satellites, §7.1). */
  baudRate?: number;
  usbVendorId?: number;
  usbProductId?: number;
  /** Where the bytes came from. */
  source?: 'webserial' | 'demo' | 'simulator' | 'saleae-csv' | 'raw' | (string & {});
  /** One entry per port index, when several ports share the file. */
  ports?: CapturePortInfo[];
  /** Free text from the user. */
  note?: string;
  [key: string]: MetaScalar | CapturePortInfo[] | undefined;
}

export type CaptureKind = 'sscap' | 'raw' | 'saleae-csv';

/**
 * How much timing a capture carries:
 * - `per-byte`: `byteTimesUs` holds the time of every byte (logic-analyser exports);
 * - `per-chunk`: `chunkTimesUs` holds the arrival time of each chunk (live recordings);
 * - `none`: no times at all (raw dumps).
 */
export type CaptureTiming = 'per-byte' | 'per-chunk' | 'none';

export type CaptureIssueKind =
  /** .sscap: the file ends inside a record (the usual end of a recording that was cut off). */
  | 'truncated-record'
  /** .sscap: a record whose header or CRC-32 is wrong; skipped up to the next intact record. */
  | 'bad-checksum'
  /** .sscap: bytes that belong to no record (between records, or after the last one). */
  | 'garbage'
  /**
   * .sscap: a damaged file header (signature, version, metadata length, metadata or its CRC). The
   * records are read all the same; the metadata is repaired, kept with a warning, or lost.
   */
  | 'bad-header'
  /** .sscap: metadata fields of the wrong type, dropped. */
  | 'bad-meta'
  /** CSV: a row that cannot be read (too few columns, time or value not a number…). */
  | 'malformed-row'
  /** CSV: a row of another type than async-serial data (Logic 2 `type` column). */
  | 'skipped-row'
  /** CSV: a byte the analyser flagged with a parity or framing error; left out of the data. */
  | 'flagged-byte';

/** Something a reader skipped or distrusted. Readers report these instead of throwing. */
export interface CaptureIssue {
  kind: CaptureIssueKind;
  /**
   * Byte offset in the file where the skipped or distrusted bytes start (for CSV: the start of
   * the line; for CSV passed as a string: an offset in its UTF-8 encoding).
   */
  offset: number;
  /** How many bytes the issue covers (for CSV: the line, without its line end). */
  length: number;
  /** CSV only: 1-based line number. */
  line?: number;
  /** A sentence a person can read. */
  message: string;
}

/** A text event recorded alongside the data, e.g. "port opened", "device lost". */
export interface CaptureEvent {
  /** Time in µs on the same clock as the data chunks; NaN when unknown. */
  timeUs: number;
  port: number;
  text: string;
  /**
   * Number of data chunks recorded before this event (of every port): the event happened
   * between chunk `chunkIndex - 1` and chunk `chunkIndex`.
   */
  chunkIndex: number;
}

/**
 * A capture in memory, whatever file it came from. Data is columnar so that an hour of
 * recording costs a few typed arrays, not a few hundred thousand objects:
 *
 * - `bytes` is every data byte of every port, concatenated in file order;
 * - chunk `i` is `bytes[chunkEnds[i - 1] ?? 0 .. chunkEnds[i])`, received on port
 *   `chunkPorts[i]`; its time `chunkTimesUs[i]` is the arrival time of its LAST byte in µs
 *   (NaN when unknown), which is what a live reader knows about a chunk;
 * - with `timing === 'per-byte'`, `byteTimesUs[j]` is the time of `bytes[j]` in µs, and there
 *   is exactly one chunk per port (ports in increasing order), whose time is that of its last
 *   byte. `byteTimesUs` is absent with any other timing.
 *
 * Use `captureChunks()` to walk the chunks of one port with the time argument a decoder's
 * `push(bytes, time)` expects.
 */
export interface Capture {
  readonly kind: CaptureKind;
  readonly meta: CaptureMeta;
  readonly timing: CaptureTiming;
  readonly bytes: Uint8Array;
  /** Exclusive end offset in `bytes` of each chunk; non-decreasing; the last equals `bytes.length`. */
  readonly chunkEnds: Uint32Array;
  /** Arrival time of each chunk's last byte, µs; NaN when unknown. */
  readonly chunkTimesUs: Float64Array;
  /** Port index of each chunk. */
  readonly chunkPorts: Uint8Array;
  /** Present only when `timing === 'per-byte'`: one time per byte of `bytes`, µs. */
  readonly byteTimesUs?: Float64Array;
  readonly events: readonly CaptureEvent[];
  readonly issues: readonly CaptureIssue[];
}

/** What `parseCapture` returns: a `Capture` of kind `sscap`, plus the header's facts. */
export interface ParsedCapture extends Capture {
  readonly kind: 'sscap';
  /** Format version from the header (1). */
  readonly version: number;
  /** Size of the file header in bytes; the first record starts here. */
  readonly headerLength: number;
}

/**
 * Thrown when a file is not a capture at all (wrong signature, a text file that is not a Saleae
 * export, an empty file), is a .sscap of an unsupported version, or holds nothing to recover
 * (it ends inside its header). Damage inside a capture, its header included, never throws: it
 * is reported in `Capture.issues`.
 */
export class CaptureFormatError extends Error {
  override readonly name = 'CaptureFormatError';
  constructor(message: string) {
    super(message);
  }
}

/** One chunk as `captureChunks()` yields it. The typed arrays are views into the capture (no copies). */
export interface CaptureChunk {
  /** Index of the chunk in the capture's chunk arrays. */
  index: number;
  port: number;
  /** Offset of the chunk's first byte in `capture.bytes`. */
  start: number;
  bytes: Uint8Array;
  /** Arrival time of the chunk's last byte, µs; NaN when unknown. */
  timeUs: number;
  /** Per-byte times (view), when the capture has them. */
  byteTimesUs: Float64Array | undefined;
  /**
   * The time argument for a decoder's `push(bytes, time)`: the per-byte times when there are
   * some, else the chunk time, else `undefined`.
   */
  time: number | Float64Array | undefined;
}

/**
 * The chunks of a capture in file order, optionally only those of one port. Allocates one small
 * object and two views per chunk; that is meant for replay and tools, not a hot path.
 */
export function* captureChunks(capture: Capture, port?: number): Generator<CaptureChunk, void, undefined> {
  const { bytes, chunkEnds, chunkTimesUs, chunkPorts, byteTimesUs } = capture;
  let start = 0;
  for (let i = 0; i < chunkEnds.length; i++) {
    const end = chunkEnds[i] ?? start;
    const p = chunkPorts[i] ?? 0;
    if (port === undefined || p === port) {
      const timeUs = chunkTimesUs[i] ?? NaN;
      const times = byteTimesUs?.subarray(start, end);
      yield {
        index: i,
        port: p,
        start,
        bytes: bytes.subarray(start, end),
        timeUs,
        byteTimesUs: times,
        time: times ?? (Number.isNaN(timeUs) ? undefined : timeUs),
      };
    }
    start = end;
  }
}

/** The port indices that have at least one data chunk, in increasing order. */
export function capturePorts(capture: Capture): number[] {
  const seen = new Uint8Array(256);
  for (let i = 0; i < capture.chunkPorts.length; i++) seen[capture.chunkPorts[i] ?? 0] = 1;
  const ports: number[] = [];
  for (let p = 0; p < 256; p++) if (seen[p] === 1) ports.push(p);
  return ports;
}

// ---------------------------------------------------------------------------------------------
// CRC-32
// ---------------------------------------------------------------------------------------------

/** CRC-32/ISO-HDLC (zlib, PNG, Ethernet): reflected polynomial 0xEDB88320, init and xor-out 0xFFFFFFFF. */
const CRC32_POLY = 0xedb88320;
let crcTable: Uint32Array | undefined;

function buildCrcTable(): Uint32Array {
  const table = new Uint32Array(256);
  for (let n = 0; n < 256; n++) {
    let c = n;
    for (let k = 0; k < 8; k++) c = c & 1 ? CRC32_POLY ^ (c >>> 1) : c >>> 1;
    table[n] = c >>> 0;
  }
  return table;
}

/** CRC-32 (as zlib computes it) of `bytes[start, end)`, as an unsigned 32-bit number. */
export function crc32(bytes: Uint8Array, start = 0, end = bytes.length): number {
  return (crcRun(0xffffffff, bytes, start, end) ^ 0xffffffff) >>> 0;
}

/** Runs the CRC register `c` (before the final XOR) over `bytes[start, end)`. */
function crcRun(c: number, bytes: Uint8Array, start: number, end: number): number {
  // Built on first use rather than at import, so importing the module does no work.
  const table = (crcTable ??= buildCrcTable());
  for (let i = start; i < end; i++) c = (table[(c ^ (bytes[i] as number)) & 0xff] as number) ^ (c >>> 8);
  return c;
}

// CRC-32 is linear over GF(2), so the CRC of `a || b` follows from the CRCs of `a` and `b` and
// the length of `b` (zlib's crc32_combine): crc(a || b) = crc(a) · x^(8·|b|) mod P  ⊕  crc(b).
// The reader uses it to check a long record from two prefix CRCs instead of reading it again.

/** a · b modulo the CRC polynomial, in the reflected bit order the table uses. */
function mulModPoly(a: number, b: number): number {
  if (a === 0) return 0;
  let m = 0x80000000;
  let p = 0;
  for (;;) {
    if (a & m) {
      p ^= b;
      if ((a & (m - 1)) === 0) break;
    }
    m >>>= 1;
    b = b & 1 ? (b >>> 1) ^ CRC32_POLY : b >>> 1;
  }
  return p >>> 0;
}

/** x^(2^k) mod P for k = 0…31, built on first use. */
let crcPowers: Uint32Array | undefined;

/** x^(8·n) mod P: the factor that moves a CRC past n zero bytes. */
function crcShift(n: number): number {
  const powers = (crcPowers ??= (() => {
    const t = new Uint32Array(32);
    let p = 0x40000000; // x^1
    t[0] = p;
    for (let k = 1; k < 32; k++) t[k] = p = mulModPoly(p, p);
    return t;
  })());
  let p = 0x80000000; // x^0
  for (let k = 3; n > 0; k++, n = Math.floor(n / 2)) if (n % 2 === 1) p = mulModPoly(powers[k & 31] as number, p);
  return p;
}

// ---------------------------------------------------------------------------------------------
// File layout (see docs/capture-format.md)
// ---------------------------------------------------------------------------------------------

/** Conventional file name extension. */
export const CAPTURE_FILE_EXTENSION = '.sscap';
/** The format version this code writes and reads. */
export const CAPTURE_FORMAT_VERSION = 1;

/**
 * File signature: 0x89 "SSCAP" CR LF. As in PNG, the high-bit first byte keeps text tools from
 * taking the file for text, and CR LF is mangled by any transfer that rewrites line endings,
 * so such damage is caught at the first bytes.
 */
const MAGIC = [0x89, 0x53, 0x53, 0x43, 0x41, 0x50, 0x0d, 0x0a] as const;
const MAGIC_SIZE = MAGIC.length;
/** Fixed part of the header: magic[8], u16 version, u16 flags, u32 metadata length. */
const HEADER_FIXED_SIZE = 16;
const OFF_VERSION = 8;
const OFF_META_LENGTH = 12;
const CRC_SIZE = 4;
/** Upper bound on the metadata block; a larger announced length means a damaged header. */
export const MAX_META_BYTES = 1 << 20;

/** Record sync marker. Only used to find records again after damage; the CRC confirms them. */
const SYNC0 = 0xa5;
const SYNC1 = 0x5c;
/** Record header: sync[2], u8 type, u8 port, u32 payload length, f64 time (µs). */
const RECORD_HEADER_SIZE = 16;
const REC_OFF_TYPE = 2;
const REC_OFF_PORT = 3;
const REC_OFF_LENGTH = 4;
const REC_OFF_TIME = 8;
/** Bytes a record adds around its payload: header plus trailing CRC-32. */
export const RECORD_OVERHEAD = RECORD_HEADER_SIZE + CRC_SIZE;
/** Largest payload of one record: 16 MiB, the largest read buffer Web Serial allows. */
export const MAX_RECORD_PAYLOAD = 1 << 24;

export const RECORD_TYPE_DATA = 1;
export const RECORD_TYPE_EVENT = 2;

/** True when `bytes` starts with the .sscap signature. */
export function hasCaptureMagic(bytes: Uint8Array): boolean {
  if (bytes.length < MAGIC_SIZE) return false;
  for (let i = 0; i < MAGIC_SIZE; i++) if (bytes[i] !== MAGIC[i]) return false;
  return true;
}

/** True when `bytes` is shorter than the signature and matches its beginning. */
export function isCaptureMagicPrefix(bytes: Uint8Array): boolean {
  if (bytes.length === 0 || bytes.length >= MAGIC_SIZE) return false;
  for (let i = 0; i < bytes.length; i++) if (bytes[i] !== MAGIC[i]) return false;
  return true;
}

// ---------------------------------------------------------------------------------------------
// Metadata checking (shared by the writer, which throws, and the reader, which drops)
// ---------------------------------------------------------------------------------------------

const KNOWN_STRING_FIELDS = ['createdAt', 'source', 'note'] as const;
const KNOWN_NUMBER_FIELDS = ['baudRate', 'usbVendorId', 'usbProductId'] as const;

function isScalar(v: unknown): v is MetaScalar {
  return v === null || typeof v === 'string' || typeof v === 'boolean' || (typeof v === 'number' && Number.isFinite(v));
}

function isPlainObject(v: unknown): v is Record<string, unknown> {
  return typeof v === 'object' && v !== null && !Array.isArray(v);
}

/** Why `value` cannot be field `key` (at `path`), or undefined when it can. */
function fieldProblem(key: string, value: unknown, path: string): string | undefined {
  if (key === '__proto__') return `${path} is not an allowed key`;
  if ((KNOWN_STRING_FIELDS as readonly string[]).includes(key) || key === 'name') {
    return typeof value === 'string' ? undefined : `${path} must be a string`;
  }
  if ((KNOWN_NUMBER_FIELDS as readonly string[]).includes(key)) {
    return typeof value === 'number' && Number.isFinite(value) ? undefined : `${path} must be a finite number`;
  }
  return isScalar(value) ? undefined : `${path} must be a string, a finite number, a boolean or null`;
}

/**
 * A clean copy of `value` as `CaptureMeta`: fields of the wrong type are left out and described
 * in `problems`. Undefined values are left out silently (JSON has no undefined).
 */
function cleanMeta(value: unknown, problems: string[]): CaptureMeta {
  const out: CaptureMeta = {};
  if (!isPlainObject(value)) {
    problems.push('meta must be a plain object');
    return out;
  }
  for (const key of Object.keys(value)) {
    const v = value[key];
    if (v === undefined) continue;
    if (key === 'ports') {
      if (!Array.isArray(v)) {
        problems.push('meta.ports must be an array');
        continue;
      }
      const ports: CapturePortInfo[] = [];
      v.forEach((entry: unknown, i: number) => {
        const port: CapturePortInfo = {};
        if (!isPlainObject(entry)) {
          problems.push(`meta.ports[${i}] must be an object`);
        } else {
          for (const k of Object.keys(entry)) {
            const pv = entry[k];
            if (pv === undefined) continue;
            const problem = fieldProblem(k, pv, `meta.ports[${i}].${k}`);
            if (problem) problems.push(problem);
            else port[k] = pv as MetaScalar;
          }
        }
        // Keep the entry even when emptied, so entry i still describes port i.
        ports.push(port);
      });
      out.ports = ports;
      continue;
    }
    const problem = fieldProblem(key, v, `meta.${key}`);
    if (problem) problems.push(problem);
    else out[key] = v as MetaScalar;
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Writer
// ---------------------------------------------------------------------------------------------

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
  view.setUint32(crcEnd, crc32(target, offset + REC_OFF_TYPE, crcEnd), true);
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
 * `data()` / `event()` call returns, in order.
 *
 * ```ts
 * const w = new CaptureWriter({ createdAt: new Date().toISOString(), baudRate: 115200, source: 'webserial' });
 * await file.write(w.header());
 * await file.write(w.data(chunk, performance.now() * 1000));
 * ```
 */
export class CaptureWriter {
  /** The metadata as stored (a validated copy). */
  readonly meta: CaptureMeta;
  readonly #header: Uint8Array;

  /** @throws {TypeError} when `meta` has a field of the wrong type or is larger than 1 MiB as JSON. */
  constructor(meta: CaptureMeta = {}) {
    const problems: string[] = [];
    this.meta = cleanMeta(meta, problems);
    if (problems.length > 0) throw new TypeError(`invalid capture metadata: ${problems.join('; ')}`);
    this.#header = encodeHeader(this.meta);
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
    const out = new Uint8Array(RECORD_OVERHEAD + bytes.length);
    writeRecord(out, 0, RECORD_TYPE_DATA, checkPort(port), checkTime(timeUs), bytes);
    return out;
  }

  /**
   * One event record (e.g. "port opened", "device lost"). Returns the bytes to append.
   * @throws {TypeError} on a non-string text, an infinite time or a port outside 0–255.
   */
  event(text: string, timeUs: number, port = 0): Uint8Array {
    if (typeof text !== 'string') throw new TypeError('event text must be a string');
    const payload = utf8Encode(text);
    checkPayload(payload.length);
    const out = new Uint8Array(RECORD_OVERHEAD + payload.length);
    writeRecord(out, 0, RECORD_TYPE_EVENT, checkPort(port), checkTime(timeUs), payload);
    return out;
  }
}

/** A record for `encodeCapture`. `port` defaults to 0. */
export type CaptureRecordInput =
  | { type: 'data'; bytes: Uint8Array; timeUs: number; port?: number }
  | { type: 'event'; text: string; timeUs: number; port?: number };

/**
 * A whole .sscap file in one buffer: the same bytes as `CaptureWriter`'s header followed by one
 * record per input, in order.
 * @throws {TypeError} on invalid metadata or records (see `CaptureWriter`).
 */
export function encodeCapture(meta: CaptureMeta, records: readonly CaptureRecordInput[]): Uint8Array {
  const header = new CaptureWriter(meta).header();
  // Validate and encode payloads first, so the output is allocated once at its final size.
  const payloads: Uint8Array[] = [];
  let size = header.length;
  for (const [i, r] of records.entries()) {
    if (!isPlainObject(r)) throw new TypeError(`records[${i}] must be an object`);
    let payload: Uint8Array;
    if (r.type === 'data') {
      if (!(r.bytes instanceof Uint8Array)) throw new TypeError(`records[${i}].bytes must be a Uint8Array`);
      payload = r.bytes;
    } else if (r.type === 'event') {
      if (typeof r.text !== 'string') throw new TypeError(`records[${i}].text must be a string`);
      payload = utf8Encode(r.text);
    } else {
      throw new TypeError(`records[${i}].type must be 'data' or 'event'`);
    }
    checkTime(r.timeUs);
    checkPort(r.port ?? 0);
    checkPayload(payload.length);
    payloads.push(payload);
    size += RECORD_OVERHEAD + payload.length;
  }
  const out = new Uint8Array(size);
  out.set(header, 0);
  let offset = header.length;
  records.forEach((r, i) => {
    const type = r.type === 'data' ? RECORD_TYPE_DATA : RECORD_TYPE_EVENT;
    offset += writeRecord(out, offset, type, r.port ?? 0, r.timeUs, payloads[i] as Uint8Array);
  });
  return out;
}

// ---------------------------------------------------------------------------------------------
// Reader
// ---------------------------------------------------------------------------------------------

function hexPreview(bytes: Uint8Array, count: number): string {
  const parts: string[] = [];
  for (let i = 0; i < Math.min(count, bytes.length); i++) parts.push((bytes[i] ?? 0).toString(16).padStart(2, '0'));
  return parts.join(' ');
}

/**
 * Signature bits that may be flipped before a file stops counting as a capture. Two of 64 keep a
 * damaged signature readable, while another file type matching that closely by chance is
 * practically impossible (its first 8 bytes would have to be within 2 bits of these).
 */
const MAX_MAGIC_BIT_ERRORS = 2;

function magicBitErrors(bytes: Uint8Array): number {
  let errors = 0;
  for (let i = 0; i < MAGIC_SIZE; i++) {
    let x = ((bytes[i] ?? 0) ^ (MAGIC[i] as number)) & 0xff;
    for (; x !== 0; x &= x - 1) errors++;
  }
  return errors;
}

/**
 * True when `bytes` starts with the .sscap signature or with one damaged in at most two bits:
 * what `readCapture` takes for a capture, so a flipped bit in the signature does not turn the
 * file into a "raw dump".
 */
export function looksLikeCaptureMagic(bytes: Uint8Array): boolean {
  return bytes.length >= MAGIC_SIZE && magicBitErrors(bytes) <= MAX_MAGIC_BIT_ERRORS;
}

/** The smallest header: the fixed part, empty metadata, the CRC. No record can start earlier. */
const MIN_HEADER_SIZE = HEADER_FIXED_SIZE + CRC_SIZE;

/**
 * What a reader did, counted: a test hook that shows recovery stays linear in the file size
 * whatever the bytes are (`parseCaptureCounting`).
 */
export interface CaptureReaderWork {
  /** Bytes run through the CRC-32 table: record checks, and the prefix index when one is built. */
  crcBytes: number;
  /** Long ranges whose CRC-32 came from the prefix index instead of their bytes. */
  crcCombines: number;
  /** Positions where a record was looked for. */
  probes: number;
}

/** Results of `RecordProbe.at` that are not a record size. */
const NOT_RECORD = 0; // no sync marker here
const DAMAGED = -1; // sync marker, but an impossible header or a CRC mismatch
const CUT = -2; // a plausible record that the end of the file cuts short

/** Spacing of the prefix CRCs kept by the index (4 bytes of index per 64 bytes of file). */
const CRC_INDEX_STEP = 64;
/** Ranges up to this long are always checked byte by byte: cheaper than two prefix lookups and a combination. */
const CRC_DIRECT_MAX = 2 * CRC_INDEX_STEP;

/**
 * Looks for records. On a clean file each byte is checked once. Damage makes the reader try
 * every sync marker, and a crafted or unlucky file can put a marker every few bytes, each
 * announcing a record that runs to the end of the file: checking each one byte by byte would take
 * time quadratic in the file size (a 1 MiB file took most of a minute). So once byte-by-byte
 * checks have read the file twice over, long ranges are checked from an index of prefix CRCs
 * (one every 64 bytes, built once) and the CRC-32 combination rule: at most 2 × 64 bytes and one
 * combination per candidate, linear overall.
 */
class RecordProbe {
  readonly #bytes: Uint8Array;
  readonly #view: DataView;
  readonly #n: number;
  readonly #work: CaptureReaderWork;
  /** Bytes that may still be checked directly before the index takes over for long ranges. */
  #directBudget: number;
  /** `#index[k]` = crc32(bytes, 0, k · CRC_INDEX_STEP). */
  #index: Uint32Array | null = null;

  constructor(bytes: Uint8Array, view: DataView, work: CaptureReaderWork) {
    this.#bytes = bytes;
    this.#view = view;
    this.#n = bytes.length;
    this.#work = work;
    this.#directBudget = 2 * bytes.length;
  }

  /** What starts at `p`: the size of an intact record, or NOT_RECORD, DAMAGED or CUT. */
  at(p: number): number {
    const bytes = this.#bytes;
    const view = this.#view;
    const avail = this.#n - p;
    this.#work.probes++;
    if (bytes[p] !== SYNC0) return NOT_RECORD;
    if (avail >= 2 && bytes[p + 1] !== SYNC1) return NOT_RECORD;
    if (avail >= 3) {
      const type = bytes[p + REC_OFF_TYPE];
      if (type !== RECORD_TYPE_DATA && type !== RECORD_TYPE_EVENT) return DAMAGED;
    }
    if (avail < RECORD_HEADER_SIZE) {
      if (avail >= REC_OFF_LENGTH + 4 && view.getUint32(p + REC_OFF_LENGTH, true) > MAX_RECORD_PAYLOAD) return DAMAGED;
      return CUT;
    }
    const len = view.getUint32(p + REC_OFF_LENGTH, true);
    if (len > MAX_RECORD_PAYLOAD) return DAMAGED;
    const total = RECORD_OVERHEAD + len;
    if (total > avail) return CUT;
    const crcAt = p + RECORD_HEADER_SIZE + len;
    return this.crc(p + REC_OFF_TYPE, crcAt) === view.getUint32(crcAt, true) ? total : DAMAGED;
  }

  /** The first intact record at or after `from`, or -1. */
  firstIntact(from: number): number {
    const bytes = this.#bytes;
    for (let p = bytes.indexOf(SYNC0, from); p >= 0; p = bytes.indexOf(SYNC0, p + 1)) {
      if (this.at(p) > 0) return p;
    }
    return -1;
  }

  /** crc32(bytes, start, end), directly or from the prefix index (see the class comment). */
  crc(start: number, end: number): number {
    const length = end - start;
    if (length <= CRC_DIRECT_MAX || length <= this.#directBudget) {
      this.#directBudget -= length;
      this.#work.crcBytes += length;
      return crc32(this.#bytes, start, end);
    }
    this.#work.crcCombines++;
    // crc(a..b) follows from crc(0..a) and crc(0..b): crc(0..b) = crc(0..a) · x^(8(b−a)) ⊕ crc(a..b).
    return (this.#prefix(end) ^ mulModPoly(crcShift(length), this.#prefix(start))) >>> 0;
  }

  /** crc32(bytes, 0, i), from the nearest index entry below `i`. */
  #prefix(i: number): number {
    const index = (this.#index ??= this.#buildIndex());
    const k = Math.floor(i / CRC_INDEX_STEP);
    const from = k * CRC_INDEX_STEP;
    this.#work.crcBytes += i - from;
    return (crcRun((index[k] as number) ^ 0xffffffff, this.#bytes, from, i) ^ 0xffffffff) >>> 0;
  }

  #buildIndex(): Uint32Array {
    const n = this.#n;
    const index = new Uint32Array(Math.floor(n / CRC_INDEX_STEP) + 1);
    let c = 0xffffffff;
    for (let k = 1; k < index.length; k++) {
      c = crcRun(c, this.#bytes, (k - 1) * CRC_INDEX_STEP, k * CRC_INDEX_STEP);
      index[k] = (c ^ 0xffffffff) >>> 0;
    }
    this.#work.crcBytes += (index.length - 1) * CRC_INDEX_STEP;
    return index;
  }
}

/** The header as the reader understood it. */
interface HeaderResult {
  meta: CaptureMeta;
  version: number;
  headerLength: number;
}

/**
 * Reads the header. A header that fails its checks loses at most its metadata, never the
 * records: where the records start is then found from the records themselves (the first one
 * intact), the metadata is kept when it still reads, and the damage is reported as a
 * `bad-header` issue.
 */
function readHeader(bytes: Uint8Array, view: DataView, probe: RecordProbe, issues: CaptureIssue[]): HeaderResult {
  const n = bytes.length;
  if (n === 0) throw new CaptureFormatError('not a SatScope capture: the file is empty');
  if (n < MAGIC_SIZE) {
    if (isCaptureMagicPrefix(bytes)) {
      throw new CaptureFormatError(`truncated SatScope capture: the file is only ${n} byte(s) long and ends inside the signature`);
    }
    throw notCapture(bytes);
  }
  const magicOk = looksLikeCaptureMagic(bytes);
  if (n < HEADER_FIXED_SIZE) {
    if (!magicOk) throw notCapture(bytes);
    throw new CaptureFormatError(`truncated SatScope capture: the file ends inside its header (${n} of at least ${MIN_HEADER_SIZE} bytes)`);
  }
  const version = view.getUint16(OFF_VERSION, true);
  const metaLength = view.getUint32(OFF_META_LENGTH, true);
  // The header's length as stated, when it is possible at all.
  const stated = metaLength <= MAX_META_BYTES ? HEADER_FIXED_SIZE + metaLength + CRC_SIZE : -1;
  const statedFits = stated >= 0 && stated <= n;
  // A signature beyond repair is still a capture's when the rest proves it (odds of 2^-32 by
  // chance): the header CRC matches with the signature restored, or an intact record starts
  // where the header says it ends.
  if (!magicOk && !(statedFits && (repairedHeaderMatches(bytes, view, stated) || (stated < n && probe.at(stated) > 0)))) {
    throw notCapture(bytes);
  }
  if (statedFits && crc32(bytes, 0, stated - CRC_SIZE) === view.getUint32(stated - CRC_SIZE, true)) {
    if (version !== CAPTURE_FORMAT_VERSION) {
      // An intact header of another version: a format this reader does not know, not damage.
      throw new CaptureFormatError(
        `unsupported SatScope capture version ${version}: this reader understands version ${CAPTURE_FORMAT_VERSION}` +
          (version > CAPTURE_FORMAT_VERSION ? ' (the file was written by a newer SatScope)' : ''),
      );
    }
    return { meta: readMeta(bytes, HEADER_FIXED_SIZE, stated - CRC_SIZE, issues), version, headerLength: stated };
  }

  // The header is damaged. The records carry their own sync markers and CRCs, so they say where
  // they start: the first intact one. Before it lies the header, perhaps with a damaged first record.
  const first = probe.firstIntact(MIN_HEADER_SIZE);
  // Damage confined to the fixed fields (signature, version, flags, metadata length) is repaired:
  // with the values a version-1 writer puts there, the header CRC matches again.
  for (const end of headerEnds(bytes, first, stated)) {
    if (end < MIN_HEADER_SIZE || end > n || !repairedHeaderMatches(bytes, view, end)) continue;
    const damaged = damagedFixedFields(bytes, view, end);
    issues.push({
      kind: 'bad-header',
      offset: 0,
      length: end,
      message: `damaged header: its ${damaged.join(', ')} ${damaged.length === 1 ? 'is' : 'are'} wrong; repaired (the metadata passes its CRC-32 check)`,
    });
    return { meta: readMeta(bytes, HEADER_FIXED_SIZE, end - CRC_SIZE, issues), version: CAPTURE_FORMAT_VERSION, headerLength: end };
  }
  // Damage in the metadata or the CRC itself. The stated length stands when the records agree
  // with it: a record (intact or not) starts there, or the file ends there.
  const recordsAgree = first < 0 || stated === first || (stated < first && bytes[stated] === SYNC0 && bytes[stated + 1] === SYNC1);
  let headerLength: number;
  if (statedFits && recordsAgree) {
    headerLength = stated;
  } else if (first >= 0) {
    headerLength = first;
  } else if (stated < 0) {
    throw new CaptureFormatError(`damaged SatScope capture header: it announces ${metaLength} bytes of metadata (the limit is ${MAX_META_BYTES}) and no intact record follows`);
  } else {
    throw new CaptureFormatError(`truncated SatScope capture: the file ends inside its header (${n} of ${stated} bytes)`);
  }
  const header: CaptureIssue = { kind: 'bad-header', offset: 0, length: headerLength, message: '' };
  issues.push(header);
  const problems: string[] = [];
  const parsed = parseMetaJson(bytes, HEADER_FIXED_SIZE, Math.max(HEADER_FIXED_SIZE, headerLength - CRC_SIZE));
  const where = headerLength === stated ? '' : ` (records start at offset ${headerLength}, not ${stated < 0 ? 'where its metadata length says' : stated})`;
  if (parsed === undefined) {
    header.message = `damaged header${where}: it fails its CRC-32 check and its metadata cannot be read, so the metadata is lost; the records are checked separately`;
    return { meta: {}, version: CAPTURE_FORMAT_VERSION, headerLength };
  }
  header.message = `damaged header${where}: it fails its CRC-32 check, so the metadata may be wrong; the records are checked separately`;
  const meta = cleanMeta(parsed, problems);
  if (problems.length > 0) pushBadMeta(issues, headerLength, problems);
  return { meta, version: CAPTURE_FORMAT_VERSION, headerLength };
}

/** Closing braces tried as the end of the metadata when neither the stated length nor the first record fits. */
const MAX_BRACE_TRIES = 16;
const CLOSE_BRACE = 0x7d;

/**
 * Where the header may end, most likely first: where the first intact record starts, where the
 * metadata length says; then (the length and the first record both damaged) just after each of
 * the last few '}' before the first intact record, since the metadata is a JSON object and its
 * CRC follows it.
 */
function* headerEnds(bytes: Uint8Array, first: number, stated: number): Generator<number, void, undefined> {
  yield first;
  if (stated !== first) yield stated;
  const limit = Math.min(first >= 0 ? first : bytes.length, MIN_HEADER_SIZE + MAX_META_BYTES);
  let q = bytes.lastIndexOf(CLOSE_BRACE, limit - CRC_SIZE - 1);
  for (let tries = 0; q >= HEADER_FIXED_SIZE && tries < MAX_BRACE_TRIES; tries++, q = bytes.lastIndexOf(CLOSE_BRACE, q - 1)) {
    const end = q + 1 + CRC_SIZE;
    if (end !== first && end !== stated) yield end;
  }
}

function notCapture(bytes: Uint8Array): CaptureFormatError {
  return new CaptureFormatError(
    `not a SatScope capture: the file does not start with the .sscap signature 89 53 53 43 41 50 0d 0a (it starts with ${hexPreview(bytes, MAGIC_SIZE)})`,
  );
}

/** The fixed header fields a version-1 writer would have written for a header `end` bytes long. */
function expectedFixedHeader(end: number): Uint8Array {
  const fixed = new Uint8Array(HEADER_FIXED_SIZE);
  const view = new DataView(fixed.buffer);
  fixed.set(MAGIC, 0);
  view.setUint16(OFF_VERSION, CAPTURE_FORMAT_VERSION, true);
  view.setUint32(OFF_META_LENGTH, end - MIN_HEADER_SIZE, true);
  return fixed;
}

/** Does the header CRC at `end - 4` match once the fixed fields hold what a version-1 writer writes? */
function repairedHeaderMatches(bytes: Uint8Array, view: DataView, end: number): boolean {
  const crcAt = end - CRC_SIZE;
  const fixed = expectedFixedHeader(end);
  const c = crcRun(crcRun(0xffffffff, fixed, 0, HEADER_FIXED_SIZE), bytes, HEADER_FIXED_SIZE, crcAt);
  return ((c ^ 0xffffffff) >>> 0) === view.getUint32(crcAt, true);
}

/** Names of the fixed header fields that differ from what a version-1 writer writes. */
function damagedFixedFields(bytes: Uint8Array, view: DataView, end: number): string[] {
  const fixed = expectedFixedHeader(end);
  const differs = (from: number, to: number): boolean => {
    for (let i = from; i < to; i++) if (bytes[i] !== fixed[i]) return true;
    return false;
  };
  const names: string[] = [];
  if (differs(0, OFF_VERSION)) names.push('signature');
  if (differs(OFF_VERSION, OFF_VERSION + 2)) names.push(`version (${view.getUint16(OFF_VERSION, true)})`);
  if (differs(OFF_VERSION + 2, OFF_META_LENGTH)) names.push('reserved flags');
  if (differs(OFF_META_LENGTH, HEADER_FIXED_SIZE)) names.push(`metadata length (${view.getUint32(OFF_META_LENGTH, true)}, not ${end - MIN_HEADER_SIZE})`);
  return names;
}

/** The metadata JSON in `bytes[start, end)` as a value, or undefined when it is not a JSON object. */
function parseMetaJson(bytes: Uint8Array, start: number, end: number): Record<string, unknown> | undefined {
  try {
    const parsed: unknown = JSON.parse(utf8Decode(bytes, start, end));
    return isPlainObject(parsed) ? parsed : undefined;
  } catch {
    return undefined;
  }
}

function pushBadMeta(issues: CaptureIssue[], end: number, problems: string[]): void {
  issues.push({
    kind: 'bad-meta',
    offset: HEADER_FIXED_SIZE,
    length: end - CRC_SIZE - HEADER_FIXED_SIZE,
    message: `metadata fields of the wrong type were dropped: ${problems.join('; ')}`,
  });
}

/**
 * The metadata of a header whose CRC matched: a clean copy, fields of the wrong type dropped and
 * reported. Metadata that is not a JSON object (another writer's bug) is reported and dropped.
 */
function readMeta(bytes: Uint8Array, start: number, end: number, issues: CaptureIssue[]): CaptureMeta {
  const parsed = parseMetaJson(bytes, start, end);
  if (parsed === undefined) {
    issues.push({
      kind: 'bad-meta',
      offset: start,
      length: end - start,
      message: 'the metadata is not a JSON object (although its CRC-32 matches: the writer made it so); it was dropped',
    });
    return {};
  }
  const problems: string[] = [];
  const meta = cleanMeta(parsed, problems);
  if (problems.length > 0) pushBadMeta(issues, end + CRC_SIZE, problems);
  return meta;
}

/**
 * Reads a .sscap file. Every intact record is recovered, whatever damage surrounds it, a damaged
 * header included: the reader skips what it cannot trust, finds the next record by its sync
 * marker and CRC, and lists what it skipped in `issues`. Its time is linear in the file size
 * whatever the bytes are.
 *
 * @throws {CaptureFormatError} only when the file is not a SatScope capture (its signature is
 *   wrong in more than two bits and neither the header CRC nor a record proves it a capture), is
 *   a capture of an unsupported version (an intact header of another version), or holds nothing
 *   to recover (it ends inside its header).
 * @throws {TypeError} when `bytes` is not a Uint8Array.
 */
export function parseCapture(bytes: Uint8Array): ParsedCapture {
  return readSscap(bytes, { crcBytes: 0, crcCombines: 0, probes: 0 });
}

/**
 * `parseCapture`, and what it did: a test hook (not exported by the package) for checking that
 * reading stays linear on any input.
 */
export function parseCaptureCounting(bytes: Uint8Array): { capture: ParsedCapture; work: CaptureReaderWork } {
  const work: CaptureReaderWork = { crcBytes: 0, crcCombines: 0, probes: 0 };
  return { capture: readSscap(bytes, work), work };
}

/** `array`, or a view of its first `length` elements when that wastes little, else a trimmed copy. */
function fit<T extends Uint8Array | Uint32Array | Float64Array>(array: T, length: number): T {
  // A view avoids holding the file's data twice at the peak; a copy frees a mostly empty buffer.
  return (length >= array.length * 0.75 ? array.subarray(0, length) : array.slice(0, length)) as T;
}

function readSscap(bytes: Uint8Array, work: CaptureReaderWork): ParsedCapture {
  if (!(bytes instanceof Uint8Array)) throw new TypeError('parseCapture expects a Uint8Array');
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const probe = new RecordProbe(bytes, view, work);
  const issues: CaptureIssue[] = [];
  const { meta, version, headerLength } = readHeader(bytes, view, probe, issues);
  const n = bytes.length;

  // Every record takes at least RECORD_OVERHEAD bytes and its payload is part of the file, so
  // these sizes are upper bounds: allocate once, trim once, no growth in the loop.
  const room = n - headerLength;
  const maxRecords = Math.floor(room / RECORD_OVERHEAD);
  const data = new Uint8Array(Math.max(0, room - RECORD_OVERHEAD));
  const chunkEnds = new Uint32Array(maxRecords);
  const chunkTimes = new Float64Array(maxRecords);
  const chunkPorts = new Uint8Array(maxRecords);
  const events: CaptureEvent[] = [];
  let dataLength = 0;
  let chunks = 0;
  let anyTime = false;

  // The region being skipped, if any: where it started and why.
  let skipStart = -1;
  let skipKind: 'garbage' | 'damaged' | 'cut' = 'garbage';
  // Inside a garbage or damaged region, the first place where a record seemed to start but ran
  // past the end of the file. It only matters if nothing intact follows: then the tail from
  // there is reported as a truncated record of its own.
  let cutAt = -1;
  const flushSkip = (end: number, atEof: boolean): void => {
    if (skipStart < 0) return;
    if (atEof && cutAt > skipStart) {
      const tail = cutAt;
      cutAt = -1;
      flushSkip(tail, false);
      skipStart = tail;
      skipKind = 'cut';
    }
    cutAt = -1;
    const length = end - skipStart;
    const at = skipStart;
    if (skipKind === 'garbage') {
      issues.push({ kind: 'garbage', offset: at, length, message: `${length} byte(s) at offset ${at} belong to no record; skipped` });
    } else if (skipKind === 'cut' && atEof) {
      issues.push({
        kind: 'truncated-record',
        offset: at,
        length,
        message: `the file ends inside a record at offset ${at} (${length} byte(s) present): the recording was cut off`,
      });
    } else {
      // A damaged header, a CRC mismatch, or a length running past the end of the file even
      // though intact records follow (so the length itself was damaged).
      issues.push({
        kind: 'bad-checksum',
        offset: at,
        length,
        message: `damaged record at offset ${at} (header or CRC-32 check failed); skipped ${length} byte(s) up to the next intact record`,
      });
    }
    skipStart = -1;
  };

  let p = headerLength;
  while (p < n) {
    const result = probe.at(p);
    if (result > 0) {
      flushSkip(p, false);
      const len = result - RECORD_OVERHEAD;
      const payload = p + RECORD_HEADER_SIZE;
      const timeUs = view.getFloat64(p + REC_OFF_TIME, true);
      const port = bytes[p + REC_OFF_PORT] as number;
      if (bytes[p + REC_OFF_TYPE] === RECORD_TYPE_DATA) {
        // Short chunks (the usual case) are copied by hand: cheaper than making a subarray.
        if (len <= 64) for (let k = 0; k < len; k++) data[dataLength + k] = bytes[payload + k] as number;
        else data.set(bytes.subarray(payload, payload + len), dataLength);
        dataLength += len;
        chunkEnds[chunks] = dataLength;
        chunkTimes[chunks] = timeUs;
        chunkPorts[chunks] = port;
        chunks++;
        if (timeUs === timeUs) anyTime = true; // not NaN
      } else {
        events.push({ timeUs, port, text: utf8Decode(bytes, payload, payload + len), chunkIndex: chunks });
      }
      p += result;
    } else if (result === NOT_RECORD) {
      if (skipStart < 0) {
        skipStart = p;
        skipKind = 'garbage';
      }
      // Jump to the next possible sync byte: indexOf is native and fast.
      const next = bytes.indexOf(SYNC0, p + 1);
      p = next < 0 ? n : next;
    } else {
      // DAMAGED or CUT: skip one byte and look again, since the length may be what is damaged.
      const kind = result === CUT ? 'cut' : 'damaged';
      if (skipStart < 0) {
        skipStart = p;
        skipKind = kind;
      } else if (kind === 'cut') {
        if (skipKind !== 'cut' && cutAt < 0) cutAt = p;
      } else if (skipKind === 'garbage' && plausibleHeader(bytes, view, p, n)) {
        // A whole record header with a failed CRC after garbage: a damaged record of its own.
        flushSkip(p, false);
        skipStart = p;
        skipKind = kind;
      }
      p += 1;
    }
  }
  flushSkip(n, true);

  return {
    kind: 'sscap',
    meta,
    timing: anyTime ? 'per-chunk' : 'none',
    bytes: fit(data, dataLength),
    chunkEnds: fit(chunkEnds, chunks),
    chunkTimesUs: fit(chunkTimes, chunks),
    chunkPorts: fit(chunkPorts, chunks),
    events,
    issues,
    version,
    headerLength,
  };
}

/** A complete record header with a valid type and length (its CRC failed): a damaged record, not a stray sync byte. */
function plausibleHeader(bytes: Uint8Array, view: DataView, p: number, n: number): boolean {
  if (n - p < RECORD_HEADER_SIZE) return false;
  const type = bytes[p + REC_OFF_TYPE];
  return (type === RECORD_TYPE_DATA || type === RECORD_TYPE_EVENT) && view.getUint32(p + REC_OFF_LENGTH, true) <= MAX_RECORD_PAYLOAD;
}
