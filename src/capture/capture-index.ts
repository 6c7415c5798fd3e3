/**
 * The .sscap index (docs/capture-format.md, "Index"): where, per port, the records of each
 * stretch of capture time start, and the capture's span and counts so far. The writer adds it
 * as INDEX records, in segments while recording (so a recording cut short keeps most of it)
 * and a final one at close. A reader finds the last segment from the end of the file, follows
 * the segments back to the first, and checks each; anything that does not check out gives no
 * index, and the file takes one plain scan as before. The index never replaces the records: it
 * only says where to read them.
 */
import { crc32 } from './crc32.js';
import { CRC_SIZE, RECORD_HEADER_SIZE, RECORD_OVERHEAD, RECORD_TYPE_INDEX, REC_OFF_LENGTH, REC_OFF_TYPE, SYNC0, SYNC1 } from './layout.js';

/** The index layout this code writes and reads (payload offset 0). */
export const INDEX_VERSION = 1;
/** A port's next entry: its first data record this much capture time after the last entry… */
export const INDEX_STRETCH_US = 1_000_000;
/** …or this many data bytes after it, whichever comes first (untimed and bursty captures). */
export const INDEX_STRETCH_BYTES = 64 * 1024;
/** A segment is written when this many entries wait, or SEGMENT_BYTES of file passed since the last one. */
const SEGMENT_ENTRIES = 64;
const SEGMENT_BYTES = 1 << 20;
/** How far back from the end a reader looks for the last segment of a recording cut short. */
const SEARCH_BACK_BYTES = 4 * SEGMENT_BYTES;
/** Segments a reader follows back at most: a week of three ports writes about 28,000. */
const MAX_SEGMENTS = 100_000;
/** Tags tried on the way back: a real segment is among the first few; crafted bytes cost no more than these. */
const SEARCH_BACK_TAGS = 64;

const FLAG_FINAL = 1;
/**
 * Payload: u16 version, u16 flags, u32 entries, f64 previous segment, f64 data and event records
 * before, f64 first and last data time, u32 ports, u32 zero.
 */
const HEAD_SIZE = 56;
/** A port's totals before the segment: f64 data records, f64 data bytes, u8 port, 7 zero bytes. */
const PORT_SIZE = 24;
/** An entry: f64 file offset, f64 time, f64 port's data bytes before, u32 port's data records before, u8 port, 3 zero bytes. */
const ENTRY_SIZE = 32;
/** Payload end: u32 payload length, then the tag, so that a reader at the end of the file finds the record's start. */
const TAIL_SIZE = 8;
const TAG = [0x53, 0x53, 0x49, 0x58] as const; // "SSIX"
/** The largest segment: every port and a full segment's entries, and one more entry (the record that made it due). */
const MAX_SEGMENT_PAYLOAD = HEAD_SIZE + 256 * PORT_SIZE + (SEGMENT_ENTRIES + 1) * ENTRY_SIZE + TAIL_SIZE;

/** Where one stretch of one port's records starts. */
export interface IndexEntry {
  /** File offset of the port's first data record in the stretch. */
  readonly offset: number;
  /** That record's time, µs (NaN when unknown). */
  readonly timeUs: number;
  /** Data bytes of the port before that record: the decoder's stream offset of its first byte. */
  readonly streamOffset: number;
  /** Data records of the port before that record. */
  readonly chunk: number;
  readonly port: number;
}

/** A port's data before the last segment. */
export interface IndexPort {
  readonly port: number;
  readonly records: number;
  readonly bytes: number;
}

/** A file's index, read and checked. */
export interface CaptureIndex {
  /** Written at close: the records end where the index ends. Otherwise records after `coversTo` take a plain scan. */
  readonly final: boolean;
  /** File offset where the last segment ends: every record before it is indexed. */
  readonly coversTo: number;
  /** Data and event records before the last segment, and the first and last data time (µs, NaN when none). */
  readonly dataRecords: number;
  readonly eventRecords: number;
  readonly firstUs: number;
  readonly lastUs: number;
  /** Each port's data records and bytes before the last segment, ports in increasing order. */
  readonly ports: readonly IndexPort[];
  /** Every entry, in file order. */
  readonly entries: readonly IndexEntry[];
}

/** A closed capture's span and counts, from its final index segment. */
export type CaptureTotals = Pick<CaptureIndex, 'dataRecords' | 'eventRecords' | 'firstUs' | 'lastUs' | 'ports'>;

/** What a writer keeps to index its records: entries not yet written, and each port's stretch. */
export class IndexBuilder {
  #pending: IndexEntry[] = [];
  #ports = new Map<number, { records: number; bytes: number; entryUs: number; entryBytes: number }>();
  #dataRecords = 0;
  #eventRecords = 0;
  #firstUs = Number.NaN;
  #lastUs = Number.NaN;
  #previous = -1;
  #lastSegmentEnd = 0;

  /** Notes a data record of `length` payload bytes at file offset `offset`. */
  data(offset: number, timeUs: number, port: number, length: number): void {
    let p = this.#ports.get(port);
    if (p === undefined) {
      p = { records: 0, bytes: 0, entryUs: Number.NaN, entryBytes: 0 };
      this.#ports.set(port, p);
    }
    const stretchOver =
      p.records === 0 ||
      p.bytes - p.entryBytes >= INDEX_STRETCH_BYTES ||
      (Number.isFinite(timeUs) && !(timeUs - p.entryUs < INDEX_STRETCH_US && timeUs >= p.entryUs));
    if (stretchOver) {
      this.#pending.push({ offset, timeUs, streamOffset: p.bytes, chunk: p.records, port });
      p.entryUs = timeUs;
      p.entryBytes = p.bytes;
    }
    p.records++;
    p.bytes += length;
    this.#dataRecords++;
    if (Number.isFinite(timeUs)) {
      if (Number.isNaN(this.#firstUs)) this.#firstUs = timeUs;
      this.#lastUs = timeUs;
    }
  }

  event(): void {
    this.#eventRecords++;
  }

  /** Whether a segment is due before the file grows past `offset`. */
  due(offset: number): boolean {
    return this.#pending.length >= SEGMENT_ENTRIES || offset - this.#lastSegmentEnd >= SEGMENT_BYTES;
  }

  /** The INDEX record to write at file offset `offset`: the entries since the last one (`final`: at close). */
  segment(offset: number, final: boolean): Uint8Array {
    const entries = this.#pending;
    const ports = [...this.#ports].sort((a, b) => a[0] - b[0]);
    const length = HEAD_SIZE + PORT_SIZE * ports.length + ENTRY_SIZE * entries.length + TAIL_SIZE;
    const out = new Uint8Array(RECORD_OVERHEAD + length);
    const view = new DataView(out.buffer);
    out[0] = SYNC0;
    out[1] = SYNC1;
    out[REC_OFF_TYPE] = RECORD_TYPE_INDEX;
    view.setUint32(REC_OFF_LENGTH, length, true);
    view.setFloat64(8, this.#lastUs, true);
    const h = RECORD_HEADER_SIZE;
    view.setUint16(h, INDEX_VERSION, true);
    view.setUint16(h + 2, final ? FLAG_FINAL : 0, true);
    view.setUint32(h + 4, entries.length, true);
    view.setFloat64(h + 8, this.#previous, true);
    view.setFloat64(h + 16, this.#dataRecords, true);
    view.setFloat64(h + 24, this.#eventRecords, true);
    view.setFloat64(h + 32, this.#firstUs, true);
    view.setFloat64(h + 40, this.#lastUs, true);
    view.setUint32(h + 48, ports.length, true);
    let e = h + HEAD_SIZE;
    for (const [port, p] of ports) {
      view.setFloat64(e, p.records, true);
      view.setFloat64(e + 8, p.bytes, true);
      out[e + 16] = port;
      e += PORT_SIZE;
    }
    for (const entry of entries) {
      view.setFloat64(e, entry.offset, true);
      view.setFloat64(e + 8, entry.timeUs, true);
      view.setFloat64(e + 16, entry.streamOffset, true);
      view.setUint32(e + 24, entry.chunk, true);
      out[e + 28] = entry.port;
      e += ENTRY_SIZE;
    }
    view.setUint32(e, length, true);
    out.set(TAG, e + 4);
    const crcAt = h + length;
    view.setUint32(crcAt, crc32(out, REC_OFF_TYPE, crcAt, view), true);
    this.#pending = [];
    this.#previous = offset;
    this.#lastSegmentEnd = offset + out.length;
    return out;
  }
}

/** Reads `length` bytes at file offset `offset` (fewer only past the end of the file). */
export type ReadAt = (offset: number, length: number) => Promise<Uint8Array> | Uint8Array;

/** One segment as read: its place, its own fields, its entries. */
interface Segment {
  readonly at: number;
  readonly end: number;
  readonly final: boolean;
  readonly previous: number;
  readonly dataRecords: number;
  readonly eventRecords: number;
  readonly firstUs: number;
  readonly lastUs: number;
  readonly ports: IndexPort[];
  readonly entries: IndexEntry[];
}

/**
 * The totals of a .sscap file's last index segment that checks out, the final one or (a
 * recording cut short) the last before the end, with where it ends: the records after
 * `coversTo` are not counted. Null when there is none. Two or three reads, not the whole index.
 */
export async function readLastTotals(
  size: number,
  recordsFrom: number,
  read: ReadAt,
): Promise<(CaptureTotals & Pick<CaptureIndex, 'final' | 'coversTo'>) | null> {
  const last = (await segmentEndingAt(size, recordsFrom, read)) ?? (await lastSegmentBefore(size, recordsFrom, read));
  return last !== null && fitsBefore(last, recordsFrom) ? { ...last, coversTo: last.end } : null;
}

/** Whether the records a segment counts fit in the file before it (a count no file can hold is damage). */
function fitsBefore(s: Segment, recordsFrom: number): boolean {
  const bytes = s.ports.reduce((n, p) => n + p.bytes, 0);
  return bytes + RECORD_OVERHEAD * (s.dataRecords + s.eventRecords) <= s.at - recordsFrom;
}

/**
 * The index of a .sscap file of `size` bytes whose records start at `recordsFrom` (the header's
 * length), or null when it has none or one that does not check out (then read the file plainly).
 * Reads the end of the file, then each segment back to the first (at most MAX_SEGMENTS).
 */
export async function readCaptureIndex(size: number, recordsFrom: number, read: ReadAt): Promise<CaptureIndex | null> {
  let last = await segmentEndingAt(size, recordsFrom, read);
  if (last === null) last = await lastSegmentBefore(size, recordsFrom, read);
  if (last === null || !fitsBefore(last, recordsFrom)) return null;
  const segments: Segment[] = [last];
  for (let s = last; s.previous >= 0; ) {
    if (s.previous < recordsFrom || s.previous >= s.at || segments.length >= MAX_SEGMENTS) return null;
    const before = await segmentAt(s.previous, recordsFrom, read);
    if (before === null || before.final) return null;
    segments.push(before);
    s = before;
  }
  segments.reverse();
  const entries: IndexEntry[] = [];
  const ports = new Map<number, IndexEntry>();
  let from = recordsFrom;
  let counts = { dataRecords: 0, eventRecords: 0 };
  const totals = new Map<number, IndexPort>();
  for (const s of segments) {
    if (s.dataRecords < counts.dataRecords || s.eventRecords < counts.eventRecords) return null;
    counts = s;
    // A port's totals only grow, and a port once seen stays.
    for (const [port, before] of totals) {
      const now = s.ports.find((p) => p.port === port);
      if (now === undefined || now.records < before.records || now.bytes < before.bytes) return null;
    }
    for (const p of s.ports) totals.set(p.port, p);
    for (const e of s.entries) {
      // Entries lie between the segment before and this one, in file order; a port's go forward.
      const before = ports.get(e.port);
      if (e.offset < from || e.offset + RECORD_OVERHEAD > s.at) return null;
      if (before !== undefined && (e.chunk <= before.chunk || e.streamOffset < before.streamOffset)) return null;
      const total = totals.get(e.port);
      if (total === undefined || e.chunk >= total.records || e.streamOffset > total.bytes) return null;
      from = e.offset + RECORD_OVERHEAD;
      ports.set(e.port, e);
      entries.push(e);
    }
    from = Math.max(from, s.end);
  }
  return {
    final: last.final,
    coversTo: last.end,
    dataRecords: last.dataRecords,
    eventRecords: last.eventRecords,
    firstUs: last.firstUs,
    lastUs: last.lastUs,
    ports: last.ports,
    entries,
  };
}

/** The segment whose record ends at file offset `end` (found from its tail), or null. */
async function segmentEndingAt(end: number, recordsFrom: number, read: ReadAt): Promise<Segment | null> {
  if (end - recordsFrom < RECORD_OVERHEAD + HEAD_SIZE + TAIL_SIZE) return null;
  const tail = await read(end - TAIL_SIZE - CRC_SIZE, TAIL_SIZE);
  if (tail.length < TAIL_SIZE || !tagAt(tail, 4)) return null;
  const length = new DataView(tail.buffer, tail.byteOffset, tail.length).getUint32(0, true);
  const at = end - RECORD_OVERHEAD - length;
  return at >= recordsFrom ? segmentAt(at, recordsFrom, read) : null;
}

/**
 * The last segment of a file that does not end with one (a recording cut short): the nearest
 * tag before the end that ends an intact segment, within SEARCH_BACK_BYTES. Segments are
 * written at least every SEGMENT_BYTES, so one lies there unless the recording was short.
 */
async function lastSegmentBefore(size: number, recordsFrom: number, read: ReadAt): Promise<Segment | null> {
  const from = Math.max(recordsFrom, size - SEARCH_BACK_BYTES);
  const bytes = await read(from, size - from);
  let tries = 0;
  for (let i = bytes.length - TAIL_SIZE / 2 - CRC_SIZE; i >= TAIL_SIZE / 2 && tries < SEARCH_BACK_TAGS; i--) {
    if (bytes[i] !== TAG[0] || !tagAt(bytes, i)) continue;
    tries++;
    const segment = await segmentEndingAt(from + i + TAIL_SIZE / 2 + CRC_SIZE, recordsFrom, read);
    if (segment !== null) return segment;
  }
  return null;
}

function tagAt(bytes: Uint8Array, i: number): boolean {
  return bytes[i] === TAG[0] && bytes[i + 1] === TAG[1] && bytes[i + 2] === TAG[2] && bytes[i + 3] === TAG[3];
}

/** The segment whose record starts at file offset `at`, checked (sync, type, length, CRC, version, tail), or null. */
async function segmentAt(at: number, recordsFrom: number, read: ReadAt): Promise<Segment | null> {
  const head = await read(at, RECORD_HEADER_SIZE);
  if (head.length < RECORD_HEADER_SIZE || head[0] !== SYNC0 || head[1] !== SYNC1 || head[REC_OFF_TYPE] !== RECORD_TYPE_INDEX) return null;
  const length = new DataView(head.buffer, head.byteOffset, head.length).getUint32(REC_OFF_LENGTH, true);
  if (length > MAX_SEGMENT_PAYLOAD || length < HEAD_SIZE + TAIL_SIZE) return null;
  const record = await read(at, RECORD_OVERHEAD + length);
  if (record.length < RECORD_OVERHEAD + length) return null;
  const view = new DataView(record.buffer, record.byteOffset, record.length);
  const crcAt = RECORD_HEADER_SIZE + length;
  if (crc32(record, REC_OFF_TYPE, crcAt, view) !== view.getUint32(crcAt, true)) return null;
  const h = RECORD_HEADER_SIZE;
  const count = view.getUint32(h + 4, true);
  const portCount = view.getUint32(h + 48, true);
  if (
    view.getUint16(h, true) !== INDEX_VERSION ||
    portCount > 256 ||
    length !== HEAD_SIZE + PORT_SIZE * portCount + ENTRY_SIZE * count + TAIL_SIZE
  )
    return null;
  if (view.getUint32(crcAt - TAIL_SIZE, true) !== length || !tagAt(record, crcAt - TAIL_SIZE / 2)) return null;
  const previous = view.getFloat64(h + 8, true);
  const dataRecords = view.getFloat64(h + 16, true);
  const eventRecords = view.getFloat64(h + 24, true);
  if (!(previous === -1 || (Number.isInteger(previous) && previous >= recordsFrom))) return null;
  if (!Number.isInteger(dataRecords) || dataRecords < 0 || !Number.isInteger(eventRecords) || eventRecords < 0) return null;
  const ports: IndexPort[] = [];
  let e = h + HEAD_SIZE;
  for (let k = 0; k < portCount; k++, e += PORT_SIZE) {
    const port = { port: record[e + 16] ?? 0, records: view.getFloat64(e, true), bytes: view.getFloat64(e + 8, true) };
    if (!Number.isInteger(port.records) || port.records < 0 || !Number.isInteger(port.bytes) || port.bytes < 0) return null;
    if (k > 0 && port.port <= (ports[k - 1]?.port ?? 0)) return null;
    ports.push(port);
  }
  if (ports.reduce((n, p) => n + p.records, 0) !== dataRecords) return null;
  const entries: IndexEntry[] = [];
  for (let k = 0; k < count; k++, e += ENTRY_SIZE) {
    const offset = view.getFloat64(e, true);
    const streamOffset = view.getFloat64(e + 16, true);
    if (!Number.isInteger(offset) || !Number.isInteger(streamOffset) || streamOffset < 0) return null;
    entries.push({
      offset,
      timeUs: view.getFloat64(e + 8, true),
      streamOffset,
      chunk: view.getUint32(e + 24, true),
      port: record[e + 28] ?? 0,
    });
  }
  return {
    at,
    end: at + record.length,
    final: (view.getUint16(h + 2, true) & FLAG_FINAL) !== 0,
    previous,
    dataRecords,
    eventRecords,
    firstUs: view.getFloat64(h + 32, true),
    lastUs: view.getFloat64(h + 40, true),
    ports,
    entries,
  };
}
