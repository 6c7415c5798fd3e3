/**
 * Reading .sscap files, salvaging every intact record of a damaged or truncated one.
 */
import { utf8Decode } from './text.js';
import { crc32, crcRun, crcShift, mulModPoly } from './crc32.js';
import {
  CAPTURE_FORMAT_VERSION,
  CRC_SIZE,
  HEADER_FIXED_SIZE,
  MAGIC,
  MAGIC_SIZE,
  MAX_META_BYTES,
  MAX_RECORD_PAYLOAD,
  OFF_META_LENGTH,
  OFF_VERSION,
  RECORD_HEADER_SIZE,
  RECORD_OVERHEAD,
  RECORD_TYPE_DATA,
  RECORD_TYPE_EVENT,
  REC_OFF_LENGTH,
  REC_OFF_PORT,
  REC_OFF_TIME,
  REC_OFF_TYPE,
  SYNC0,
  SYNC1,
  isCaptureMagicPrefix,
} from './layout.js';
import { cleanMeta, isPlainObject } from './meta.js';
import { copyPayload, grown, plannedSizes, trimTo } from './records.js';
import { CaptureFormatError } from './model.js';
import type { CaptureEvent, CaptureIssue, CaptureMeta, ParsedCapture } from './model.js';

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
    let x = ((bytes[i] ?? 0) ^ (MAGIC[i] ?? 0)) & 0xff;
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

/** The header as the reader understood it. */
export interface HeaderResult {
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
export function readHeader(bytes: Uint8Array, view: DataView, probe: RecordProbe, issues: CaptureIssue[]): HeaderResult {
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
  if (statedFits && crc32(bytes, 0, stated - CRC_SIZE, view) === view.getUint32(stated - CRC_SIZE, true)) {
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
    throw new CaptureFormatError(
      `damaged SatScope capture header: it announces ${metaLength} bytes of metadata (the limit is ${MAX_META_BYTES}) and no intact record follows`,
    );
  } else {
    throw new CaptureFormatError(`truncated SatScope capture: the file ends inside its header (${n} of ${stated} bytes)`);
  }
  const header: CaptureIssue = { kind: 'bad-header', offset: 0, length: headerLength, message: '' };
  issues.push(header);
  const problems: string[] = [];
  const parsed = parseMetaJson(bytes, HEADER_FIXED_SIZE, Math.max(HEADER_FIXED_SIZE, headerLength - CRC_SIZE));
  const where =
    headerLength === stated
      ? ''
      : ` (records start at offset ${headerLength}, not ${stated < 0 ? 'where its metadata length says' : stated})`;
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
  return (c ^ 0xffffffff) >>> 0 === view.getUint32(crcAt, true);
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
  if (differs(OFF_META_LENGTH, HEADER_FIXED_SIZE))
    names.push(`metadata length (${view.getUint32(OFF_META_LENGTH, true)}, not ${end - MIN_HEADER_SIZE})`);
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
    bytes: trimTo(data, dataLength),
    chunkEnds: trimTo(chunkEnds, chunks),
    chunkTimesUs: trimTo(chunkTimes, chunks),
    chunkPorts: trimTo(chunkPorts, chunks),
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
