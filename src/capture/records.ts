/**
 * The .sscap record layout read at a given place, shared by every reader of the format: the size
 * of the record that starts there, the sizes of a file's records planned from their headers
 * alone, a payload copied into the data column, and the columns trimmed to what they hold.
 * The salvaging reader (reader.ts), the reading in parts (parts.ts), the record walk
 * (record-walk.ts) and a replay's windows (src/worker/replay/capture-file.ts) all read records so.
 */
import {
  isRecordType,
  MAX_RECORD_PAYLOAD,
  RECORD_OVERHEAD,
  RECORD_TYPE_DATA,
  REC_OFF_LENGTH,
  REC_OFF_TYPE,
  SYNC0,
  SYNC1,
} from './layout.js';

/** `array` when it is `length` long, a view of its first `length` elements when that wastes little, else a trimmed copy. */
export function trimTo<T extends Uint8Array | Uint32Array | Float64Array>(array: T, length: number): T {
  if (array.length === length) return array;
  // A view avoids holding the file's data twice at the peak; a copy frees a mostly empty buffer.
  return (length >= array.length * 0.75 ? array.subarray(0, length) : array.slice(0, length)) as T;
}

/** `to` with `from` copied to its start. */
export function grown<T extends Uint8Array | Uint32Array | Float64Array>(to: T, from: T): T {
  to.set(from);
  return to;
}

/**
 * The size of the record whose header starts at `p` (its sync marker, a known type, a length
 * that may be), or -1 when none starts there; whether it fits in `bytes` is the caller's to see.
 * `bytes` must hold the header's first RECORD_HEADER_SIZE bytes.
 */
export function recordSize(bytes: Uint8Array, view: DataView, p: number): number {
  const type = bytes[p + REC_OFF_TYPE];
  const len = view.getUint32(p + REC_OFF_LENGTH, true);
  return bytes[p] === SYNC0 && bytes[p + 1] === SYNC1 && isRecordType(type) && len <= MAX_RECORD_PAYLOAD ? RECORD_OVERHEAD + len : -1;
}

/** Where a run of records starts: its file offset, and the chunk index and data offset it fills from. */
export interface RecordsStart {
  readonly from: number;
  readonly chunk: number;
  readonly dataAt: number;
}

/**
 * The data records and payload bytes of a file whose record headers lead from one to the next
 * right to its end (sync marker, type, a length that fits), or null when they do not: read from
 * the headers alone, before any CRC is checked. `cuts` (ascending shares of the records' bytes,
 * 0–1) ask where the first record at or past each of them starts (`planParts`).
 */
export function plannedSizes(
  bytes: Uint8Array,
  view: DataView,
  headerLength: number,
  cuts: readonly number[] = [],
): { records: number; data: number; starts: RecordsStart[] } | null {
  const n = bytes.length;
  const starts: RecordsStart[] = [];
  let records = 0;
  let data = 0;
  let p = headerLength;
  while (p + RECORD_OVERHEAD <= n) {
    if (starts.length < cuts.length && p - headerLength >= (n - headerLength) * (cuts[starts.length] ?? 1))
      starts.push({ from: p, chunk: records, dataAt: data });
    const size = recordSize(bytes, view, p);
    if (size < 0 || p + size > n) return null;
    if (bytes[p + REC_OFF_TYPE] === RECORD_TYPE_DATA) {
      records++;
      data += size - RECORD_OVERHEAD;
    }
    p += size;
  }
  return p === n ? { records, data, starts } : null;
}

/**
 * A record's `len` payload bytes from `payload` in the file to `at` in the data column. Short
 * chunks (the usual case) are copied by hand, four bytes at a time: cheaper than making a
 * subarray for set().
 */
export function copyPayload(
  data: Uint8Array,
  dataView: DataView,
  at: number,
  bytes: Uint8Array,
  view: DataView,
  payload: number,
  len: number,
): void {
  if (len <= 64) {
    let k = 0;
    for (; k + 4 <= len; k += 4) dataView.setInt32(at + k, view.getInt32(payload + k));
    for (; k < len; k++) data[at + k] = bytes[payload + k] ?? 0;
  } else data.set(bytes.subarray(payload, payload + len), at);
}
