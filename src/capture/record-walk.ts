/**
 * The data records of an intact .sscap, read from a Blob (a File) a slice at a time and handed
 * over where they lie in the slice: no payload copied, no columns kept, and the CRC checked only
 * of the records the reader asks for. A walk that throws leaves the file to the salvaging
 * reader: the replay walks a capture's records this way from its File, every CRC checked, to
 * decode it once without reading it whole (src/worker/replay/replay-session.ts).
 */
import {
  CRC_SIZE,
  HEADER_FIXED_SIZE,
  MAX_META_BYTES,
  MAX_RECORD_PAYLOAD,
  OFF_META_LENGTH,
  RECORD_HEADER_SIZE,
  RECORD_OVERHEAD,
  RECORD_TYPE_DATA,
  RECORD_TYPE_EVENT,
  REC_OFF_LENGTH,
  REC_OFF_PORT,
  REC_OFF_TIME,
  REC_OFF_TYPE,
} from './layout.js';
import { crcFollows } from './crc32.js';
import { CaptureFormatError } from './model.js';
import { type HeaderResult, readHeader } from './header.js';
import { RecordProbe } from './record-probe.js';
import { recordSize } from './records.js';

/** Read at a time: the header (its metadata is at most 1 MiB) and a few hundred thousand records. */
const SLICE_BYTES = 16 << 20;

/** What is read: a Blob or File (the library takes no DOM types). */
export interface SlicedFile {
  readonly size: number;
  slice(start: number, end: number): { arrayBuffer(): Promise<ArrayBuffer> };
  /**
   * Bytes [start, end) read another way (on another thread: src/worker/replay/slice-reader.ts):
   * the walk reads through this when it is there. (Not `bytes`: a Blob's own `bytes()` reads the
   * whole of it.)
   */
  view?(start: number, end: number): Promise<Uint8Array>;
}

/**
 * One data record: its payload is `bytes[start, end)` (`view` over `bytes`), recorded on `port` at
 * `recordTimeUs(view, start)`; `bytes[0]` is the file's byte `at`, so the record starts at file
 * offset `at + start - RECORD_HEADER_SIZE`. The time is read where it is used, not handed over:
 * a double handed to a call that is not inlined is boxed (an allocation a record).
 */
export type RecordSink = (bytes: Uint8Array, view: DataView, start: number, end: number, port: number, at: number) => void;

/** The time (µs) of the data record whose payload starts at `start` of `view` (a RecordSink's). */
export function recordTimeUs(view: DataView, start: number): number {
  return view.getFloat64(start - RECORD_HEADER_SIZE + REC_OFF_TIME, true);
}

/** What a walk to the end found: the data records (the capture's chunks) and their payload bytes, and the header. */
export interface WalkedRecords {
  chunks: number;
  dataBytes: number;
  /** The file's header, as parseCapture reads it. */
  header: HeaderResult;
  /**
   * The file ends inside a record starting here (a recording cut off): the records before it are
   * all that was walked. Whether the rest is a cut record or something else is for the reader
   * to say (parseCapture's `truncated-record`).
   */
  cutAt?: number;
}

/** How a walk goes. */
export interface WalkOptions {
  /** Asked after each slice, with the file offset walked to: false stops the walk (it resolves null). Default: on to the end. */
  goOn?: (walkedTo: number) => boolean | Promise<boolean>;
  /** Whether a data record on `port` has its CRC-32 checked. Default: none is. */
  checked?: (port: number) => boolean;
  /** Whether event records have their CRC-32 checked. Default: they are skipped unread. */
  eventsChecked?: boolean;
  /**
   * Gets each event record in the file's order among the data records (its text is
   * `bytes[start, end)`, UTF-8; its time `recordTimeUs`), after its CRC-32 was checked: set, it
   * makes `eventsChecked` true (an event from a damaged record is never told).
   */
  events?: RecordSink;
  /**
   * Gets each run of whole records walked, events too: `bytes[from, to)` of a slice, records one
   * after the other, their headers checked (and their CRCs, as asked), after `sink` has had them.
   */
  runs?: (bytes: Uint8Array, view: DataView, from: number, to: number) => void;
  /** Read at a time (tests). Default 16 MiB. */
  sliceBytes?: number;
  /** Slices asked for ahead of the one walked. Default 1. */
  readAhead?: number;
}

/**
 * Hands every data record of `file` to `sink`, in the file's order (events are not chunks; the
 * runs of records, `options.runs`, hold them too).
 * @throws {CaptureFormatError} when the header is damaged, the records do not lead from one to
 *   the next to the end of the file (or to where it ends inside one: `cutAt`), or a record
 *   checked fails its CRC (the file is not intact: parseCapture salvages it)
 */
export async function walkDataRecords(file: SlicedFile, sink: RecordSink, options: WalkOptions = {}): Promise<WalkedRecords | null> {
  const { goOn = () => true, checked = () => false, events, runs, sliceBytes = SLICE_BYTES, readAhead = 1 } = options;
  const eventsChecked = options.eventsChecked === true || events !== undefined;
  const size = file.size;
  const read = async (from: number, length: number): Promise<Uint8Array> => {
    const to = Math.min(size, from + length);
    const bytes = file.view === undefined ? new Uint8Array(await file.slice(from, to).arrayBuffer()) : await file.view(from, to);
    // The slices asked for ahead follow on from this one: a short read would leave a hole.
    if (bytes.length !== to - from) throw new Error(`a read of the file gave ${bytes.length} bytes of ${to - from} at ${from}`);
    return bytes;
  };
  // The first read holds the whole header, as long as its fixed part says it is.
  const fixed = await read(0, HEADER_FIXED_SIZE);
  const metaLength = fixed.length < HEADER_FIXED_SIZE ? 0 : new DataView(fixed.buffer, fixed.byteOffset).getUint32(OFF_META_LENGTH, true);
  let bytes = await read(0, Math.max(sliceBytes, HEADER_FIXED_SIZE + Math.min(metaLength, MAX_META_BYTES) + CRC_SIZE));
  let view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const issues: Parameters<typeof readHeader>[3] = [];
  const { meta, version, headerLength } = readHeader(
    bytes,
    view,
    new RecordProbe(bytes, view, { crcBytes: 0, crcCombines: 0, probes: 0 }),
    issues,
  );
  if (issues.length > 0) throw new CaptureFormatError(`the capture's header is damaged: ${issues[0]?.message ?? ''}`);
  /** File offset of bytes[0], and how far the file is asked for (the next slices are read while this one is walked). */
  let at = 0;
  let readTo = bytes.length;
  const inFlight: Promise<Uint8Array>[] = [];
  const ahead = (): Promise<Uint8Array> | null => {
    while (inFlight.length < readAhead && readTo < size) {
      const slice = read(readTo, sliceBytes);
      // A walk that stops or fails before it needs the slice leaves no unhandled rejection.
      slice.catch(() => undefined);
      inFlight.push(slice);
      readTo = Math.min(size, readTo + sliceBytes);
    }
    return inFlight.shift() ?? null;
  };
  let moreAt = readTo;
  let next = ahead();
  /** A slice to go on with, after the record joined across its start. */
  let queued: { bytes: Uint8Array; at: number; p: number } | null = null;
  let p = headerLength;
  const count: WalkCount = { chunks: 0, dataBytes: 0 };
  for (;;) {
    const n = bytes.length;
    const run = p;
    p = walkRun(bytes, view, p, at, sink, checked, eventsChecked, count, events);
    if (p > run) runs?.(bytes, view, run, p);
    if (queued !== null) {
      if (p !== n) throw new CaptureFormatError(`no intact record at offset ${at + p}`);
      ({ bytes, at, p } = queued);
      queued = null;
      view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
      continue;
    }
    if (next === null) {
      const walked = { chunks: count.chunks, dataBytes: count.dataBytes, header: { meta, version, headerLength } };
      return p === n ? walked : { ...walked, cutAt: at + p };
    }
    if (!(await goOn(at + p))) return null;
    const more = await next;
    const slicedAt = moreAt;
    moreAt += more.length;
    next = ahead();
    const rest = n - p;
    const total = rest === 0 ? 0 : straddling(bytes, p, rest, more);
    if (rest === 0) {
      bytes = more;
      at = slicedAt;
    } else if (total - rest <= more.length) {
      // The record not yet whole at the end of this slice, joined with its end from the next
      // (a few dozen bytes, not the next slice copied); the next slice goes on after it.
      const record = new Uint8Array(total);
      record.set(bytes.subarray(p));
      record.set(more.subarray(0, total - rest), rest);
      queued = { bytes: more, at: slicedAt, p: total - rest };
      bytes = record;
      at += p;
    } else {
      // A record longer than what is read so far: the two joined, and read on.
      const joined = new Uint8Array(rest + more.length);
      joined.set(bytes.subarray(p));
      joined.set(more, rest);
      bytes = joined;
      at += p;
    }
    view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    p = 0;
  }
}

/** The data records walked so far and their payload bytes. */
interface WalkCount {
  chunks: number;
  dataBytes: number;
}

/**
 * The whole records of a slice, `bytes` from `from` on (`at`: the slice's file offset), each
 * checked and handed to `sink` as walkDataRecords says, counted into `count`; returns where the
 * first record not whole in the slice starts. The walk's hot loop, in a function of its own,
 * called once a slice: the async walk's code between slices (run for the first time at a
 * slice's end) threw the loop's optimised code away with it, and it was compiled again. Nothing
 * follows the loop but the return: code after a loop has not run when the loop is first
 * optimised, and reaching it threw that code away too.
 */
function walkRun(
  bytes: Uint8Array,
  view: DataView,
  from: number,
  at: number,
  sink: RecordSink,
  checked: (port: number) => boolean,
  eventsChecked: boolean,
  count: WalkCount,
  events: RecordSink | undefined,
): number {
  const n = bytes.length;
  let p = from;
  while (p + RECORD_HEADER_SIZE <= n) {
    const total = recordSize(bytes, view, p);
    if (total < 0) throw new CaptureFormatError(`no intact record header at offset ${at + p}`);
    if (p + total > n) return p;
    const type = bytes[p + REC_OFF_TYPE];
    const data = type === RECORD_TYPE_DATA;
    const port = bytes[p + REC_OFF_PORT] ?? 0;
    const end = p + total - CRC_SIZE;
    if ((data ? checked(port) : eventsChecked) && !crcFollows(bytes, p + REC_OFF_TYPE, end, view))
      throw new CaptureFormatError(`damaged record at offset ${at + p} (its CRC-32 check failed)`);
    if (data) {
      sink(bytes, view, p + RECORD_HEADER_SIZE, end, port, at);
      count.chunks++;
      count.dataBytes += total - RECORD_OVERHEAD;
    } else if (type === RECORD_TYPE_EVENT) events?.(bytes, view, p + RECORD_HEADER_SIZE, end, port, at);
    p += total;
  }
  return p;
}

/**
 * The size of the record starting at `p` whose first `rest` bytes end `bytes`, its length field
 * read across into `more` if need be; Infinity when it cannot be known (no length there, or one
 * too large: the walk then finds the header damaged).
 */
function straddling(bytes: Uint8Array, p: number, rest: number, more: Uint8Array): number {
  const at = (i: number): number => (i < rest ? (bytes[p + i] ?? 0) : (more[i - rest] ?? 0));
  if (rest + more.length < REC_OFF_LENGTH + 4) return Number.POSITIVE_INFINITY;
  const len = (at(REC_OFF_LENGTH) | (at(REC_OFF_LENGTH + 1) << 8) | (at(REC_OFF_LENGTH + 2) << 16) | (at(REC_OFF_LENGTH + 3) << 24)) >>> 0;
  return len > MAX_RECORD_PAYLOAD ? Number.POSITIVE_INFINITY : RECORD_OVERHEAD + len;
}
