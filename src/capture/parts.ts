/**
 * Reading an intact .sscap in parts, each on a thread of its own: `planParts` cuts the records
 * into runs at record boundaries and says where each run's chunks and data go, `readPart` checks
 * and copies one run into columns every part shares, `assembleParts` makes the capture. The
 * capture is the one `parseCapture` returns (same columns, same events): this is only for a
 * file whose header and records are all intact. Anything else (a damaged header, a record whose
 * CRC fails, bytes between records) makes the plan or a part say so, and the file goes to
 * `parseCapture`, which salvages.
 */
import {
  RECORD_HEADER_SIZE,
  RECORD_OVERHEAD,
  RECORD_TYPE_DATA,
  RECORD_TYPE_EVENT,
  REC_OFF_PORT,
  REC_OFF_TIME,
  REC_OFF_TYPE,
} from './layout.js';
import type { CaptureEvent, CaptureMeta, ParsedCapture } from './model.js';
import { readHeader } from './header.js';
import { RecordProbe } from './record-probe.js';
import { copyPayload, plannedSizes } from './records.js';
import { utf8Decode } from './text.js';
import { stepOverBadTimes } from './time-rule.js';

/** One run of records: file offsets [from, to), and the first chunk index and data offset it fills. */
export interface CapturePart {
  readonly from: number;
  readonly to: number;
  readonly chunk: number;
  readonly dataAt: number;
}

/** An intact capture's header and its records cut into parts. */
export interface CapturePlan {
  readonly meta: CaptureMeta;
  readonly version: number;
  readonly headerLength: number;
  /** Data records and their payload bytes, in the whole file. */
  readonly records: number;
  readonly data: number;
  readonly parts: readonly CapturePart[];
}

/** The columns every part writes its own rows of. */
export interface CaptureColumns {
  readonly bytes: Uint8Array;
  readonly chunkEnds: Uint32Array;
  readonly chunkTimesUs: Float64Array;
  readonly chunkPorts: Uint8Array;
}

/** What reading a part found: whether every record was intact, and its events. */
export interface PartRead {
  readonly intact: boolean;
  readonly events: CaptureEvent[];
  readonly anyTime: boolean;
}

const noWork = () => ({ crcBytes: 0, crcCombines: 0, probes: 0 });

/**
 * Parts cut at record boundaries, as many as `shares` and each about its share of the file (2:
 * two equal halves; [2, 3]: two fifths and three), when the header is intact and the record
 * headers lead from one to the next right to the end of the file; null otherwise (or when the
 * file is not a capture: `parseCapture` says why).
 * @throws {TypeError} for shares that are not positive numbers
 */
export function planParts(bytes: Uint8Array, shares: number | readonly number[]): CapturePlan | null {
  const weights = typeof shares === 'number' ? new Array<number>(shares).fill(1) : shares;
  if (weights.length === 0 || !weights.every((w) => w > 0 && Number.isFinite(w)))
    throw new TypeError(`parts need positive shares, not ${String(shares)}`);
  const total = weights.reduce((a, b) => a + b, 0);
  const count = weights.length;
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const issues: Parameters<typeof readHeader>[3] = [];
  let header: ReturnType<typeof readHeader>;
  try {
    header = readHeader(bytes, view, new RecordProbe(bytes, view, noWork()), issues);
  } catch {
    return null;
  }
  if (issues.length > 0) return null;
  // Where each part but the last ends at the earliest, as a share of the records' bytes.
  const cuts: number[] = [];
  for (let i = 0, sum = 0; i < count - 1; i++) cuts.push((sum += weights[i] ?? 0) / total);
  const planned = plannedSizes(bytes, view, header.headerLength, cuts);
  if (planned === null) return null;
  const starts = [{ from: header.headerLength, chunk: 0, dataAt: 0 }, ...planned.starts];
  const parts = starts.map((start, i): CapturePart => ({ ...start, to: starts[i + 1]?.from ?? bytes.length }));
  return {
    meta: header.meta,
    version: header.version,
    headerLength: header.headerLength,
    records: planned.records,
    data: planned.data,
    parts,
  };
}

/** Columns for `plan`'s capture, in shared memory when `shared` (so that threads fill them). */
export function partColumns(plan: CapturePlan, shared: boolean): CaptureColumns {
  const buffer = (size: number): ArrayBufferLike => (shared ? new SharedArrayBuffer(size) : new ArrayBuffer(size));
  return {
    bytes: new Uint8Array(buffer(plan.data)),
    chunkEnds: new Uint32Array(buffer(4 * plan.records)),
    chunkTimesUs: new Float64Array(buffer(8 * plan.records)),
    chunkPorts: new Uint8Array(buffer(plan.records)),
  };
}

/** Checks every record of `part` (its CRC-32) and copies it into `columns`; stops at the first that is not intact. */
export function readPart(bytes: Uint8Array, part: CapturePart, columns: CaptureColumns): PartRead {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const probe = new RecordProbe(bytes, view, noWork());
  const { bytes: data, chunkEnds, chunkTimesUs, chunkPorts } = columns;
  const dataView = new DataView(data.buffer, data.byteOffset, data.byteLength);
  const events: CaptureEvent[] = [];
  let dataLength = part.dataAt;
  let chunks = part.chunk;
  let anyTime = false;
  for (let p = part.from; p < part.to; ) {
    const result = probe.at(p);
    if (result <= 0) return { intact: false, events, anyTime };
    const len = result - RECORD_OVERHEAD;
    const payload = p + RECORD_HEADER_SIZE;
    const timeUs = view.getFloat64(p + REC_OFF_TIME, true);
    const port = bytes[p + REC_OFF_PORT] ?? 0;
    if (bytes[p + REC_OFF_TYPE] === RECORD_TYPE_DATA) {
      copyPayload(data, dataView, dataLength, bytes, view, payload, len);
      dataLength += len;
      chunkEnds[chunks] = dataLength;
      chunkTimesUs[chunks] = timeUs;
      chunkPorts[chunks] = port;
      chunks++;
      if (!Number.isNaN(timeUs)) anyTime = true;
    } else if (bytes[p + REC_OFF_TYPE] === RECORD_TYPE_EVENT) {
      events.push({ timeUs, port, text: utf8Decode(bytes, payload, payload + len), chunkIndex: chunks });
    }
    p += result;
  }
  return { intact: true, events, anyTime };
}

/** The capture, when every part was read intact (`reads` in the order of `plan.parts`); else null. */
export function assembleParts(plan: CapturePlan, columns: CaptureColumns, reads: readonly PartRead[]): ParsedCapture | null {
  if (reads.length !== plan.parts.length || reads.some((r) => !r.intact)) return null;
  return stepOverBadTimes({
    kind: 'sscap',
    meta: plan.meta,
    timing: reads.some((r) => r.anyTime) ? 'per-chunk' : 'none',
    bytes: columns.bytes,
    chunkEnds: columns.chunkEnds,
    chunkTimesUs: columns.chunkTimesUs,
    chunkPorts: columns.chunkPorts,
    events: reads.flatMap((r) => r.events),
    issues: [],
    version: plan.version,
    headerLength: plan.headerLength,
  });
}
