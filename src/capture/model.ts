/**
 * The in-memory capture model every importer returns and every consumer reads: bytes with their
 * arrival times, chunk by chunk, per port, plus the events and issues found on the way.
 */
import { byteInChunkUs } from '../decoder/spec.js';

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

/** The file a capture came from: a SatScope .sscap, raw serial bytes, or a Saleae async-serial CSV export. */
export type CaptureKind = 'sscap' | 'raw' | 'saleae-csv';

/**
 * How much timing a capture carries:
 * - `per-byte`: `byteTimesUs` holds the time of every byte (logic-analyser exports);
 * - `per-chunk`: `chunkTimesUs` holds the arrival time of each chunk (live recordings);
 * - `none`: no times at all (raw dumps).
 */
export type CaptureTiming = 'per-byte' | 'per-chunk' | 'none';

/** What kind of damage a reader found in a capture file (docs/capture-format.md, "Reading damaged files"). */
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
  | 'flagged-byte'
  /**
   * Times that jump (non-finite, absurd, far back, or too far forward: time-rule.ts): stepped
   * over, every byte kept. Its offset is that of the first byte it dates in `Capture.bytes`.
   */
  | 'bad-time';

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

/**
 * When the first of a chunk's `count` bytes arrived, for a chunk timed by its last byte's arrival
 * (`chunkTimesUs`), its bytes `byteTimeUs` apart on the line (`byteInChunkUs`). An empty chunk
 * gets a byte time after its arrival: it has no byte to date.
 */
export function chunkFirstByteUs(arrivalUs: number, count: number, byteTimeUs: number): number {
  return byteInChunkUs(arrivalUs, count - 1, byteTimeUs);
}
