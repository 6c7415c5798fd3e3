/**
 * `readCapture`: recognises any supported capture by its content (and, second, its name).
 */
import { isUtf8, utf8Decode } from './text.js';
import { CAPTURE_FILE_EXTENSION, isCaptureMagicPrefix } from './layout.js';
import { CaptureFormatError } from './model.js';
import type { Capture, CaptureKind } from './model.js';
import { importRaw } from './raw.js';
import { looksLikeCaptureMagic } from './header.js';
import { parseCapture, type ReadOptions } from './reader.js';
import { CR, LF, bomLength, csvColumns, importSaleaeCsv, isBlank, quote } from './saleae.js';

/** How much of a file the text check looks at. */
const SNIFF_BYTES = 4096;

/**
 * True when the start of the file reads as text: well-formed UTF-8, no NUL, and at most 1 %
 * other control characters (tab, CR, LF and form feed do not count). Spektrum streams are
 * full of 0x00 (fade counters, channel 0), so real serial dumps fail this at once.
 */
function looksLikeText(bytes: Uint8Array): boolean {
  const end = Math.min(bytes.length, SNIFF_BYTES);
  let controls = 0;
  for (let i = 0; i < end; i++) {
    const b = bytes[i] ?? 0;
    if (b === 0) return false;
    if ((b < 0x20 && b !== 0x09 && b !== 0x0a && b !== 0x0d && b !== 0x0c) || b === 0x7f) controls++;
  }
  return controls * 100 <= end && isUtf8(bytes, 0, end, end < bytes.length);
}

/** Byte range of the first non-blank line within the sniffed sample (BOM and CR excluded). */
function firstLine(bytes: Uint8Array): [number, number] {
  const end = Math.min(bytes.length, SNIFF_BYTES);
  let ls = bomLength(bytes);
  while (ls < end) {
    const nl = bytes.indexOf(LF, ls);
    let le = nl < 0 || nl > end ? end : nl;
    const next = le + 1;
    if (le > ls && bytes[le - 1] === CR) le--;
    if (!isBlank(bytes, ls, le)) return [ls, le];
    ls = next;
  }
  return [end, end];
}

function hasExtension(fileName: string | undefined, ext: string): boolean {
  return fileName?.toLowerCase().endsWith(ext) === true;
}

/**
 * Reads any supported capture file, deciding by content (the name is only a hint):
 *
 * 1. the .sscap signature, even with up to two bits flipped (or a `.sscap` name) → `parseCapture`;
 * 2. text whose first line is a Saleae async-serial header → `importSaleaeCsv`;
 * 3. a `.bin` name, or content that is not text → `importRaw`;
 * 4. any other text (JSON, a README…) → `CaptureFormatError`.
 *
 * `options.shared` puts an .sscap's columns in shared memory (`ReadOptions`); the imports of a
 * CSV or raw bytes ignore it.
 *
 * @throws {CaptureFormatError} for an empty file, a .sscap with nothing to recover (see
 *   `parseCapture`), or text that is not a Saleae async-serial CSV.
 * @throws {TypeError} when `bytes` is not a Uint8Array.
 */
export function readCapture(bytes: Uint8Array, fileName?: string, options: ReadOptions = {}): Capture {
  if (!(bytes instanceof Uint8Array)) throw new TypeError('readCapture expects a Uint8Array');
  const kind = captureKindOf(bytes, fileName);
  return kind === 'sscap' ? parseCapture(bytes, options) : kind === 'saleae-csv' ? importSaleaeCsv(bytes) : importRaw(bytes);
}

/** How many of a file's first bytes `captureKindOf` needs to decide as it would on the whole file. */
export const KIND_BYTES = SNIFF_BYTES + 1;

/**
 * Which reader `readCapture` gives a file, from its first `KIND_BYTES` bytes (or all of a
 * shorter one): a reader that streams a file decides so before it reads the rest.
 * @throws {CaptureFormatError} as `readCapture` does for an empty file or text that is not a capture
 */
export function captureKindOf(head: Uint8Array, fileName?: string): CaptureKind {
  const named = fileName ? ` (${fileName})` : '';
  if (head.length === 0) throw new CaptureFormatError(`empty file${named}: there is nothing to decode`);
  const isBin = hasExtension(fileName, '.bin');
  // A file shorter than the signature that matches its start is a cut-off .sscap, unless named .bin.
  if (looksLikeCaptureMagic(head) || (!isBin && isCaptureMagicPrefix(head)) || hasExtension(fileName, CAPTURE_FILE_EXTENSION))
    return 'sscap';
  const text = looksLikeText(head);
  const [ls, le] = firstLine(head);
  if (text && csvColumns(head, ls, le)) return 'saleae-csv';
  if (isBin || !text) return 'raw';
  throw new CaptureFormatError(
    `unrecognised file${named}: it looks like text but not a Saleae async-serial CSV ` +
      `(its first line is ${quote(utf8Decode(head, ls, le))}; expected a header such as "Time [s],Value,Parity Error,Framing Error")`,
  );
}
