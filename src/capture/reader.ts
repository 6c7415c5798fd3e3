/**
 * Reading .sscap files, salvaging every intact record of a damaged or truncated one.
 */
import { utf8Decode } from './text.js';
import {
  isRecordType,
  MAX_RECORD_PAYLOAD,
  RECORD_HEADER_SIZE,
  RECORD_OVERHEAD,
  RECORD_TYPE_DATA,
  RECORD_TYPE_EVENT,
  REC_OFF_LENGTH,
  REC_OFF_PORT,
  REC_OFF_TIME,
  REC_OFF_TYPE,
  SYNC0,
} from './layout.js';
import { copyPayload, grown, plannedSizes, trimTo } from './records.js';
import type { CaptureEvent, CaptureIssue, ParsedCapture } from './model.js';
import { readHeader } from './header.js';
import { CUT, type CaptureReaderWork, NOT_RECORD, RecordProbe } from './record-probe.js';
import { stepOverBadTimes } from './time-rule.js';

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
export function parseCapture(bytes: Uint8Array, options: ReadOptions = {}): ParsedCapture {
  return readSscap(bytes, { crcBytes: 0, crcCombines: 0, probes: 0 }, options.shared === true);
}

/**
 * `parseCapture`, and what it did: a test hook (not exported by the package) for checking that
 * reading stays linear on any input.
 */
export function parseCaptureCounting(bytes: Uint8Array): { capture: ParsedCapture; work: CaptureReaderWork } {
  const work: CaptureReaderWork = { crcBytes: 0, crcCombines: 0, probes: 0 };
  return { capture: readSscap(bytes, work, false), work };
}

/** How `parseCapture` lays out what it reads. */
export interface ReadOptions {
  /**
   * The data bytes and chunk columns in `SharedArrayBuffer`s, so that worker threads read them
   * without a copy (what `satscope report` does on two cores). Default false.
   */
  shared?: boolean;
}

function readSscap(bytes: Uint8Array, work: CaptureReaderWork, shared: boolean): ParsedCapture {
  if (!(bytes instanceof Uint8Array)) throw new TypeError('parseCapture expects a Uint8Array');
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const probe = new RecordProbe(bytes, view, work);
  const issues: CaptureIssue[] = [];
  const { meta, version, headerLength } = readHeader(bytes, view, probe, issues);
  const n = bytes.length;

  // Every record takes at least RECORD_OVERHEAD bytes and its payload is part of the file, so
  // these sizes are upper bounds. A file whose records follow each other to its end (the usual
  // case) is sized exactly from its record headers first, so nothing is allocated twice its
  // need or copied to trim it; should the checks then find more (records inside a damaged one),
  // the columns grow once to the bounds.
  const room = n - headerLength;
  const maxRecords = Math.floor(room / RECORD_OVERHEAD);
  const maxData = Math.max(0, room - RECORD_OVERHEAD);
  const planned = plannedSizes(bytes, view, headerLength);
  const buffer = (size: number): ArrayBufferLike => (shared ? new SharedArrayBuffer(size) : new ArrayBuffer(size));
  let data = new Uint8Array(buffer(planned?.data ?? maxData));
  let dataView = new DataView(data.buffer);
  let chunkEnds = new Uint32Array(buffer(4 * (planned?.records ?? maxRecords)));
  let chunkTimes = new Float64Array(buffer(8 * (planned?.records ?? maxRecords)));
  let chunkPorts = new Uint8Array(buffer(planned?.records ?? maxRecords));
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
      issues.push(truncatedRecord(at, length));
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
      const port = bytes[p + REC_OFF_PORT] ?? 0;
      if (bytes[p + REC_OFF_TYPE] === RECORD_TYPE_DATA) {
        if (chunks === chunkEnds.length || dataLength + len > data.length) {
          // Not in a closure: the columns stay plain locals of this loop.
          data = grown(new Uint8Array(buffer(maxData)), data);
          dataView = new DataView(data.buffer);
          chunkEnds = grown(new Uint32Array(buffer(4 * maxRecords)), chunkEnds);
          chunkTimes = grown(new Float64Array(buffer(8 * maxRecords)), chunkTimes);
          chunkPorts = grown(new Uint8Array(buffer(maxRecords)), chunkPorts);
        }
        copyPayload(data, dataView, dataLength, bytes, view, payload, len);
        dataLength += len;
        chunkEnds[chunks] = dataLength;
        chunkTimes[chunks] = timeUs;
        chunkPorts[chunks] = port;
        chunks++;
        if (!Number.isNaN(timeUs)) anyTime = true;
      } else if (bytes[p + REC_OFF_TYPE] === RECORD_TYPE_EVENT) {
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

  return stepOverBadTimes({
    kind: 'sscap',
    meta,
    timing: anyTime ? 'per-chunk' : 'none',
    bytes: trimTo(data, dataLength),
    chunkEnds: trimTo(chunkEnds, chunks),
    chunkTimesUs: trimTo(chunkTimes, chunks),
    chunkPorts: trimTo(chunkPorts, chunks),
    events,
    issues,
    version,
    headerLength,
  });
}

/** A complete record header with a valid type and length (its CRC failed): a damaged record, not a stray sync byte. */
function plausibleHeader(bytes: Uint8Array, view: DataView, p: number, n: number): boolean {
  if (n - p < RECORD_HEADER_SIZE) return false;
  const type = bytes[p + REC_OFF_TYPE];
  return isRecordType(type) && view.getUint32(p + REC_OFF_LENGTH, true) <= MAX_RECORD_PAYLOAD;
}

/** The issue of a file that ends inside a record starting at `offset`, `length` bytes of it there. */
export function truncatedRecord(offset: number, length: number): CaptureIssue {
  return {
    kind: 'truncated-record',
    offset,
    length,
    message: `the file ends inside a record at offset ${offset} (${length} byte(s) present): the recording was cut off`,
  };
}
