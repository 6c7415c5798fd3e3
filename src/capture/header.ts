/**
 * A .sscap file's header read, and repaired where the records prove it: the signature (a few
 * flipped bits still read), the fixed fields, the metadata and its CRC. Every reader of the
 * format starts here: the salvaging reader (reader.ts), the reading in parts (parts.ts) and the
 * record walk (record-walk.ts).
 */
import { utf8Decode } from './text.js';
import { crcFollows, crcRun } from './crc32.js';
import {
  CAPTURE_FORMAT_VERSION,
  CRC_SIZE,
  HEADER_FIXED_SIZE,
  MAGIC,
  MAGIC_SIZE,
  MAX_META_BYTES,
  OFF_META_LENGTH,
  OFF_VERSION,
  SYNC0,
  SYNC1,
  isCaptureMagicPrefix,
} from './layout.js';
import { cleanMeta, isPlainObject } from './meta.js';
import { CaptureFormatError } from './model.js';
import type { CaptureIssue, CaptureMeta } from './model.js';
import type { RecordProbe } from './record-probe.js';

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
  if (statedFits && crcFollows(bytes, 0, stated - CRC_SIZE, view)) {
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
