/**
 * A .sscap replayed from its File, never read whole: at open its header, its first and last
 * records (the span, before the rest is read) and its index's totals (the ports); then windows
 * of its records, a few megabytes each, read where the replay plays or seeks. The File stays the
 * one source of the bytes: a week's capture plays in the memory of a few windows.
 */
import { type Capture, CaptureFormatError, type ParsedCapture } from '../../capture/model.js';
import {
  CRC_SIZE,
  HEADER_FIXED_SIZE,
  hasCaptureMagic,
  MAX_META_BYTES,
  OFF_META_LENGTH,
  RECORD_HEADER_SIZE,
  RECORD_TYPE_DATA,
  REC_OFF_TYPE,
} from '../../capture/layout.js';
import { parseCapture } from '../../capture/reader.js';
import { recordSize } from '../../capture/records.js';
import { crcFollows } from '../../capture/crc32.js';
import { recordTimeUs, type SlicedFile } from '../../capture/record-walk.js';
import { readLastTotals } from '../../capture/capture-index.js';
import { capturePorts } from '../../capture/facts.js';
import { captureSpan } from '../../report/capture-span.js';

/**
 * The largest file the page reads whole (raw bytes, a Saleae export, a .sscap that is damaged or
 * has no recorded times): it holds about twice its size in memory. Larger ones are refused with
 * a message; `satscope` on the command line reads them.
 */
export const READ_WHOLE_MAX_BYTES = 512 << 20;

/** Refused: `size` bytes read whole, over READ_WHOLE_MAX_BYTES; the sentence that says so. */
export function tooLargeToReadWhole(size: number, what: string): string | null {
  if (size <= READ_WHOLE_MAX_BYTES) return null;
  return `It is ${(size / (1 << 20)).toFixed(0)} MB, and ${what} is read whole: the page does that up to ${READ_WHOLE_MAX_BYTES >> 20} MB. \`satscope info\`, \`report\` and \`doctor\` on the command line read it.`;
}

/** A window's records: about a minute of two remotes recorded as a USB adapter hands them over, or an hour of a quiet one. */
export const WINDOW_BYTES = 512 << 10;
/** The longest window a seek reads at once (all it will feed, up to its target). */
const MOST_WINDOW_BYTES = 16 << 20;
/** The end read at open, for the last recorded time. */
const TAIL_BYTES = 64 << 10;
/** Read at a time when looking for a record near a file offset (a seek the decode has not reached). */
const PROBE_BYTES = 16 << 10;

/** The records of the file from `offset` to `end`, as a capture of their own. */
export interface CaptureWindow {
  readonly capture: Capture;
  readonly offset: number;
  /** Where the window's last whole record ends: the next window starts here. */
  readonly end: number;
  /** No record follows (the file's end, or bytes that are no record: the decode of the whole file says which). */
  readonly last: boolean;
}

export class CaptureFile {
  private constructor(
    readonly file: SlicedFile,
    /** The header's bytes, put before each window's records so that it reads as a capture. */
    readonly header: Uint8Array,
    /** The file's first records: the ports and timing seen first, and the first window. */
    readonly head: ParsedCapture,
    /** The first and last recorded time, from the file's first and last records. */
    readonly startUs: number,
    readonly endUs: number,
    /** Every port with data (the index's last segment and the records after it, or the whole file read at open); null: not known before a walk. */
    readonly ports: number[] | null,
  ) {}

  /**
   * The capture in `file` ready to be read in windows, or null when it is not one that can be
   * (not a .sscap, its header or first records damaged, no recorded chunk times): read whole.
   */
  static async open(file: SlicedFile): Promise<CaptureFile | null> {
    try {
      // The header (its metadata is at most 1 MiB) and a window of records.
      const fixed = await read(file, 0, HEADER_FIXED_SIZE);
      if (!hasCaptureMagic(fixed) || fixed.length < HEADER_FIXED_SIZE) return null;
      const metaLength = new DataView(fixed.buffer, fixed.byteOffset).getUint32(OFF_META_LENGTH, true);
      if (metaLength > MAX_META_BYTES) return null;
      const start = await read(file, 0, HEADER_FIXED_SIZE + metaLength + CRC_SIZE + WINDOW_BYTES);
      const whole = start.length === file.size;
      const head = parseCapture(start);
      const { headerLength } = head;
      // Damage at the start (anything but the record the read cut) is for the whole file's reader to salvage.
      if (head.timing !== 'per-chunk' || head.issues.some((i) => i.kind !== 'truncated-record')) return null;
      const header = start.slice(0, headerLength);
      const tailFrom = Math.max(headerLength, file.size - TAIL_BYTES);
      const tail = parseCapture(joined(header, await read(file, tailFrom, TAIL_BYTES)));
      const startUs = captureSpan(head).startUs;
      const endUs = whole ? captureSpan(head).endUs : captureSpan(tail).endUs;
      if (!(startUs <= endUs)) return null;
      const ports = whole && head.issues.length === 0 ? capturePorts(head) : await portsOf(file, header);
      return new CaptureFile(file, header, head, startUs, endUs, ports);
    } catch (error) {
      if (error instanceof CaptureFormatError) return null;
      throw error;
    }
  }

  /** Where the records start. */
  get recordsFrom(): number {
    return this.header.length;
  }

  /**
   * The window of records starting at `offset` (a record's start): up to `length` bytes
   * (WINDOW_BYTES, or what a seek will feed, up to MOST_WINDOW_BYTES) of whole records, more when
   * one record is longer.
   */
  async window(offset: number, length = WINDOW_BYTES): Promise<CaptureWindow> {
    const size = this.file.size;
    const first = Number.isFinite(length) ? Math.min(MOST_WINDOW_BYTES, Math.max(WINDOW_BYTES, Math.ceil(length))) : WINDOW_BYTES;
    for (let want = first; ; want *= 2) {
      const bytes = await read(this.file, offset, want);
      const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
      let p = 0;
      let damaged = false;
      while (p + RECORD_HEADER_SIZE <= bytes.length) {
        const total = recordSize(bytes, view, p);
        if (total < 0) {
          damaged = true;
          break;
        }
        if (p + total > bytes.length) break;
        p += total;
      }
      const end = offset + p;
      const atFileEnd = offset + bytes.length >= size;
      // A record longer than the window: read more, up to the file's end.
      if (p === 0 && !damaged && !atFileEnd) continue;
      const capture = parseCapture(joined(this.header, bytes.subarray(0, p)));
      // At the file's end, what follows the last whole record is a record cut short.
      return { capture, offset, end, last: damaged || atFileEnd };
    }
  }

  /**
   * The start of a data record at or a little after `offset` whose CRC checks (so a chance
   * pattern in a payload is not taken for one), with its time; null when none is found before
   * the end of a probe.
   */
  async recordNear(offset: number): Promise<{ offset: number; timeUs: number } | null> {
    const from = Math.max(this.recordsFrom, offset);
    const bytes = await read(this.file, from, PROBE_BYTES);
    const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    for (let p = 0; p + RECORD_HEADER_SIZE <= bytes.length; p++) {
      const total = recordSize(bytes, view, p);
      if (total < 0 || p + total > bytes.length || bytes[p + REC_OFF_TYPE] !== RECORD_TYPE_DATA) continue;
      if (!crcFollows(bytes, p + REC_OFF_TYPE, p + total - CRC_SIZE, view)) continue;
      const timeUs = recordTimeUs(view, p + RECORD_HEADER_SIZE);
      if (Number.isFinite(timeUs)) return { offset: from + p, timeUs };
    }
    return null;
  }

  /**
   * A record's start whose time is at or before `timeUs` and not far before it (a few probes'
   * width of the file), found by bisecting the file by time: where a seek the decode has not
   * reached yet starts reading. The records' times go forward as recorded; where they do not, the
   * bisection still ends at a record, and the seek feeds what lies between.
   */
  async offsetBefore(timeUs: number): Promise<number> {
    let lo = this.recordsFrom;
    let hi = this.file.size;
    while (hi - lo > 4 * PROBE_BYTES) {
      const mid = lo + Math.floor((hi - lo) / 2);
      const found = await this.recordNear(mid);
      if (found === null || found.timeUs > timeUs) hi = mid;
      else lo = found.offset;
    }
    // `lo` is the records' start or a record found checked.
    return lo;
  }
}

/**
 * Every port with data in `file`: those its last index segment counts and those of the records
 * after it (a recording cut short: at most a few megabytes); null without an index (only a
 * walk of the records can tell).
 */
async function portsOf(file: SlicedFile, header: Uint8Array): Promise<number[] | null> {
  const totals = await readLastTotals(file.size, header.length, (offset, length) => read(file, offset, length));
  if (totals === null) return null;
  const ports = new Set(totals.ports.filter((p) => p.records > 0).map((p) => p.port));
  if (!totals.final) for (const p of capturePorts(parseCapture(joined(header, await read(file, totals.coversTo, file.size))))) ports.add(p);
  return [...ports].sort((a, b) => a - b);
}

async function read(file: SlicedFile, from: number, length: number): Promise<Uint8Array> {
  const to = Math.min(file.size, from + length);
  return to <= from ? new Uint8Array(0) : new Uint8Array(await file.slice(from, to).arrayBuffer());
}

function joined(a: Uint8Array, b: Uint8Array): Uint8Array {
  const out = new Uint8Array(a.length + b.length);
  out.set(a);
  out.set(b, a.length);
  return out;
}
