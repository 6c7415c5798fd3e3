/**
 * A raw byte dump read a piece at a time: `satscope decode` streams one so, holding a piece, not
 * the file (a 1 GB dump held whole cost 1.1 GB). It has no times, so nothing in it needs the rest
 * of the file to be read; `decode` of an .sscap or a CSV goes to `loadCapture`. (`info`, `report`
 * and `doctor` stream every kind: streamed-file.ts.)
 */
import { closeSync, fstatSync, openSync, readSync } from 'node:fs';
import { basename } from 'node:path';
import { captureKindOf, KIND_BYTES } from '../capture/sniff.js';
import { readFileRange } from './file-range.js';

/** Read at a time. */
const PIECE_BYTES = 1 << 20;

/** An open raw dump: its descriptor (closed by the caller) and size. */
export interface RawFile {
  fd: number;
  size: number;
}

/**
 * `file` opened when `readCapture` would read it as a raw dump, else null (another kind, or a
 * file that cannot be read or is not a capture: `loadCapture` says why).
 */
export function openRawFile(file: string): RawFile | null {
  let fd: number;
  try {
    fd = openSync(file, 'r');
  } catch {
    return null;
  }
  try {
    const size = fstatSync(fd).size;
    const head = new Uint8Array(Math.min(size, KIND_BYTES));
    const read = readFileRange(fd, head, 0, head.length);
    if (read > 0 && captureKindOf(head.subarray(0, read), basename(file)) === 'raw') return { fd, size };
  } catch {
    // Not a capture, or unreadable: loadCapture reads it again and says why.
  }
  closeSync(fd);
  return null;
}

/** The file's bytes from its start, a fresh piece of up to 1 MiB at a time, until it ends. */
export function* rawPieces(raw: RawFile): Generator<Uint8Array, void, undefined> {
  for (let at = 0; ; ) {
    const piece = new Uint8Array(PIECE_BYTES);
    let n = 0;
    for (let got = 1; n < PIECE_BYTES && got > 0; n += got) got = readSync(raw.fd, piece, n, PIECE_BYTES - n, at + n);
    if (n === 0) return;
    at += n;
    yield piece.subarray(0, n);
  }
}
