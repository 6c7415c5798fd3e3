/**
 * An intact .sscap read a window at a time: the capture `parseCapture` makes of it, without the
 * file or its columns held. A first pass walks every record (each CRC-32 checked) for what must be
 * known before decoding: the ports, the events, how many data bytes, whether every time is in
 * line; then each walk of the windows reads the records again and lays each stretch of them out
 * as a window of columns.
 *
 * Only a file the salvaging reader would read as it is streams so: an intact header, records
 * that lead from one to the next to the file's end, every CRC right, and times the time rule
 * leaves alone (all in line, events fitting the data around them, or no time at all). Anything
 * else is damage `parseCapture` must salvage or the rule must step over, with the whole file in
 * view: `streamSscap` says null, and the caller reads the file whole.
 */
import { type ByteFile, PIECE_BYTES } from './byte-file.js';
import type { CaptureWindow, StreamedCapture } from './capture-windows.js';
import { crcFollows } from './crc32.js';
import { readHeader } from './header.js';
import {
  CRC_SIZE,
  HEADER_FIXED_SIZE,
  MAX_META_BYTES,
  OFF_META_LENGTH,
  RECORD_HEADER_SIZE,
  RECORD_TYPE_DATA,
  RECORD_TYPE_EVENT,
  REC_OFF_PORT,
  REC_OFF_TIME,
  REC_OFF_TYPE,
} from './layout.js';
import type { CaptureEvent, CaptureIssue } from './model.js';
import { RecordProbe } from './record-probe.js';
import { recordSize } from './records.js';
import { utf8Decode } from './text.js';
import { TIME_BACK_TOLERANCE_US, timeInLine } from './time-rule.js';

/** A record as the walk hands it over: its type, port and time, its payload `bytes[start, end)`. */
type RecordVisit = (type: number, port: number, timeUs: number, bytes: Uint8Array, start: number, end: number) => void;

/**
 * Every record of the file after its header, in order, a piece of the file at a time (a record
 * longer than a piece is read whole). False when the records do not lead from one to the next to
 * the file's end, or one fails its CRC: a file to salvage. It yields after each piece, so that a
 * reader hands on what it made of the piece before the next is read.
 */
function* walkRecords(file: ByteFile, from: number, visit: RecordVisit, checked: boolean): Generator<void, boolean, undefined> {
  const size = file.size;
  let buf = new Uint8Array(PIECE_BYTES);
  let view = new DataView(buf.buffer);
  /** File offset of buf[0], and how many bytes of buf hold the file. */
  let at = from;
  let have = 0;
  while (at + have < size || have > 0) {
    // Fill the buffer from where it holds the file to its end (or the file's).
    const want = Math.min(buf.length - have, size - at - have);
    if (want > 0) {
      const n = file.read(buf.subarray(have, have + want), at + have);
      if (n !== want) return false;
      have += n;
    }
    let p = 0;
    while (p + RECORD_HEADER_SIZE <= have) {
      const total = recordSize(buf, view, p);
      if (total < 0) return false;
      if (p + total > have) break;
      const end = p + total - CRC_SIZE;
      if (checked && !crcFollows(buf, p + REC_OFF_TYPE, end, view)) return false;
      visit(
        buf[p + REC_OFF_TYPE] ?? 0,
        buf[p + REC_OFF_PORT] ?? 0,
        view.getFloat64(p + REC_OFF_TIME, true),
        buf,
        p + RECORD_HEADER_SIZE,
        end,
      );
      p += total;
    }
    yield;
    if (at + have >= size && p < have) return false;
    // What is left (the start of a record) goes to the front of the buffer, grown for a long
    // record: the one buffer serves the whole walk (what a visit keeps, it copies).
    const rest = have - p;
    const need = rest >= RECORD_HEADER_SIZE ? Math.max(PIECE_BYTES, recordSize(buf, view, p)) : PIECE_BYTES;
    if (need > buf.length) {
      const next = new Uint8Array(need);
      next.set(buf.subarray(p, have));
      buf = next;
      view = new DataView(buf.buffer);
    } else buf.copyWithin(0, p, have);
    at += p;
    have = rest;
    if (rest === 0 && at >= size) break;
  }
  return true;
}

/** Data bytes a window holds (more for a record longer than that: one record a window then). */
const WINDOW_BYTES = 1 << 20;
/** Chunks a window holds at most. */
const WINDOW_CHUNKS = 1 << 15;

/** What the first pass tells the capture's span as it walks (`SpanTally`, in the report's layer, which has the rule). */
export interface SpanSink {
  /** A data chunk of `count` bytes (at least one) that arrived at `arrivalUs`. */
  chunk(arrivalUs: number, count: number): void;
  event(timeUs: number): void;
  readonly span: { startUs: number; endUs: number };
}

/**
 * `file`, an .sscap, as `parseCapture` reads it, a window at a time; null when the salvaging
 * reader or the time rule would change anything (see above): then the file is read whole. With
 * `span`, the first pass finds the capture's span too, and no walk is needed for it.
 */
export function streamSscap(file: ByteFile, span?: SpanSink): StreamedCapture | null {
  const head = new Uint8Array(Math.min(file.size, HEADER_FIXED_SIZE));
  if (file.read(head, 0) < HEADER_FIXED_SIZE) return null;
  const metaLength = new DataView(head.buffer).getUint32(OFF_META_LENGTH, true);
  const headerBytes = new Uint8Array(
    Math.min(file.size, HEADER_FIXED_SIZE + Math.min(metaLength, MAX_META_BYTES) + CRC_SIZE + RECORD_HEADER_SIZE),
  );
  file.read(headerBytes, 0);
  const headerView = new DataView(headerBytes.buffer);
  const issues: CaptureIssue[] = [];
  const { meta, headerLength } = readHeader(
    headerBytes,
    headerView,
    new RecordProbe(headerBytes, headerView, { crcBytes: 0, crcCombines: 0, probes: 0 }),
    issues,
  );
  if (issues.length > 0) return null;

  // The first pass: ports, events, data bytes, and whether the time rule would change a time.
  const chunksByPort = new Float64Array(256);
  const events: CaptureEvent[] = [];
  let chunks = 0;
  let dataBytes = 0;
  let last = NaN;
  let timed = 0;
  let untimed = 0;
  let inLine = true;
  /** Events since the last data chunk with a time to fit between it and the next (`stepOverEvents`). */
  let waiting: CaptureEvent[] = [];
  const intact = walkAll(file, headerLength, (type, port, timeUs, bytes, start, end) => {
    if (type === RECORD_TYPE_DATA) {
      if (Number.isNaN(timeUs)) untimed++;
      else {
        timed++;
        if (!timeInLine(last, timeUs)) inLine = false;
        for (const e of waiting) if (e.timeUs > timeUs + TIME_BACK_TOLERANCE_US) inLine = false;
        waiting = [];
        last = timeUs;
      }
      if (end > start) span?.chunk(timeUs, end - start);
      chunksByPort[port] = (chunksByPort[port] ?? 0) + 1;
      chunks++;
      dataBytes += end - start;
    } else if (type === RECORD_TYPE_EVENT) {
      const e = { timeUs, port, text: utf8Decode(bytes, start, end), chunkIndex: chunks };
      // An event fits when it follows the chunk before it (as a chunk time would) and is no later than the next.
      if (!Number.isNaN(timeUs)) {
        if (!timeInLine(last, timeUs)) inLine = false;
        waiting.push(e);
      }
      events.push(e);
    }
  });
  if (!intact) return null;
  // Times and no times mixed, or times out of line: the rule steps over them (with every time in view).
  if (timed > 0 && (untimed > 0 || !inLine)) return null;
  for (const e of events) span?.event(e.timeUs);
  const ports: number[] = [];
  for (let p = 0; p < 256; p++) if ((chunksByPort[p] ?? 0) > 0) ports.push(p);
  return {
    kind: 'sscap',
    meta,
    timing: timed > 0 ? 'per-chunk' : 'none',
    events,
    issues: [],
    dataBytes,
    ports,
    ...(span !== undefined ? { span: span.span } : {}),
    windows: (port?: number) => sscapWindows(file, headerLength, port),
  };
}

/** The data records of `file` as windows of columns; only `port`'s payloads are copied when given (the others' chunks are there, empty). */
function* sscapWindows(file: ByteFile, headerLength: number, port: number | undefined): Generator<CaptureWindow, void, undefined> {
  const ready: CaptureWindow[] = [];
  let data = new Uint8Array(WINDOW_BYTES);
  let ends = new Uint32Array(WINDOW_CHUNKS);
  let times = new Float64Array(WINDOW_CHUNKS);
  let ports = new Uint8Array(WINDOW_CHUNKS);
  let length = 0;
  let count = 0;
  let firstChunk = 0;
  let byteOffset = 0;
  /** The window's chunks' bytes of every port (its `bytes` hold only `port`'s when one is given). */
  let covered = 0;
  const close = (): void => {
    if (count === 0) return;
    ready.push({
      bytes: data.subarray(0, length),
      chunkEnds: ends.subarray(0, count),
      chunkTimesUs: times.subarray(0, count),
      chunkPorts: ports.subarray(0, count),
      firstChunk,
      byteOffset,
      headBefore: 0,
      tailAfter: 0,
    });
    firstChunk += count;
    byteOffset += covered;
    covered = 0;
    data = new Uint8Array(WINDOW_BYTES);
    ends = new Uint32Array(WINDOW_CHUNKS);
    times = new Float64Array(WINDOW_CHUNKS);
    ports = new Uint8Array(WINDOW_CHUNKS);
    length = 0;
    count = 0;
  };
  // Every CRC was checked by the first pass: the walks after it read the records as they found them.
  const walk = walkRecords(
    file,
    headerLength,
    (type, p, timeUs, bytes, start, end) => {
      if (type !== RECORD_TYPE_DATA) return;
      const n = port === undefined || p === port ? end - start : 0;
      if (count === WINDOW_CHUNKS || length + n > data.length) {
        close();
        if (n > data.length) data = new Uint8Array(n);
      }
      covered += end - start;
      // A record's payload is a few dozen bytes: copied a byte at a time, with no view made for it.
      if (n > 256) data.set(bytes.subarray(start, start + n), length);
      else for (let k = 0; k < n; k++) data[length + k] = bytes[start + k] ?? 0;
      length += n;
      ends[count] = length;
      times[count] = timeUs;
      ports[count] = p;
      count++;
    },
    false,
  );
  // The first pass found the file intact; a file changed since is read as far as it still is.
  for (let r = walk.next(); r.done !== true; r = walk.next()) {
    if (length >= WINDOW_BYTES / 2 || count >= WINDOW_CHUNKS / 2) close();
    yield* ready.splice(0);
  }
  close();
  yield* ready.splice(0);
}

/** `walkRecords` to its end: whether the file is intact. */
function walkAll(file: ByteFile, from: number, visit: RecordVisit): boolean {
  const walk = walkRecords(file, from, visit, true);
  for (;;) {
    const r = walk.next();
    if (r.done === true) return r.value;
  }
}
