/**
 * Looking for an intact record at a place in a .sscap file, in time linear in the file however
 * damaged it is: its sync marker, header and CRC (long ranges from an index of prefix CRCs).
 * The salvaging reader (reader.ts) looks for records with it, and every reader's header repair
 * (header.ts) with it finds where the records start.
 */
import { crc32, crcRun, crcShift, mulModPoly } from './crc32.js';
import {
  isRecordType,
  MAX_RECORD_PAYLOAD,
  RECORD_HEADER_SIZE,
  RECORD_OVERHEAD,
  REC_OFF_LENGTH,
  REC_OFF_TYPE,
  SYNC0,
  SYNC1,
} from './layout.js';

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
export const NOT_RECORD = 0; // no sync marker here
const DAMAGED = -1; // sync marker, but an impossible header or a CRC mismatch
export const CUT = -2; // a plausible record that the end of the file cuts short

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
export class RecordProbe {
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
      if (!isRecordType(type)) return DAMAGED;
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
      return crc32(this.#bytes, start, end, this.#view);
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
    return (crcRun((index[k] ?? 0) ^ 0xffffffff, this.#bytes, from, i, this.#view) ^ 0xffffffff) >>> 0;
  }

  #buildIndex(): Uint32Array {
    const n = this.#n;
    const index = new Uint32Array(Math.floor(n / CRC_INDEX_STEP) + 1);
    let c = 0xffffffff;
    for (let k = 1; k < index.length; k++) {
      c = crcRun(c, this.#bytes, (k - 1) * CRC_INDEX_STEP, k * CRC_INDEX_STEP, this.#view);
      index[k] = (c ^ 0xffffffff) >>> 0;
    }
    this.#work.crcBytes += (index.length - 1) * CRC_INDEX_STEP;
    return index;
  }
}
