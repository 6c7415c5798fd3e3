/**
 * A capture file opened to be read a window at a time (`StreamedCapture`): what `satscope info`,
 * `report` and `doctor` decode, so that a file costs what its results hold, not its size (a
 * 200 MB dump held whole cost 470 MB). The file stays open while the command runs: each walk of
 * its windows reads it again. A file that cannot stream (a damaged .sscap, times the time rule
 * must step over: `streamSscap`) gives null, and the command reads it whole (`loadCapture`).
 */
import { closeSync, fstatSync, openSync, readSync } from 'node:fs';
import { basename } from 'node:path';
import type { ByteFile } from '../capture/byte-file.js';
import type { StreamedCapture } from '../capture/capture-windows.js';
import { streamCsv } from '../capture/csv-stream.js';
import { streamRaw } from '../capture/raw-stream.js';
import { captureKindOf, KIND_BYTES } from '../capture/sniff.js';
import { streamSscap } from '../capture/sscap-stream.js';
import { captureSpan, SpanTally } from '../report/capture-span.js';

/** Set to 1 in the environment, every file is read whole, as before streaming (tests/cli-streamed.test.ts). */
export const READ_WHOLE = 'SATSCOPE_READ_WHOLE';

/** An open capture file read a window at a time; `close` when done. */
export interface StreamedFile {
  capture: StreamedCapture;
  close(): void;
}

/**
 * `file` opened to stream, or null: a file that cannot be read, is not a capture, or must be read
 * whole (`loadCapture` then reads it, and says why when it cannot).
 */
export function openStreamed(file: string): StreamedFile | null {
  // The agreement tests read each file both ways and hold the outputs equal byte for byte.
  if (process.env[READ_WHOLE] === '1') return null;
  let fd: number;
  try {
    fd = openSync(file, 'r');
  } catch {
    return null;
  }
  let capture: StreamedCapture | null = null;
  try {
    const size = fstatSync(fd).size;
    const bytes: ByteFile = { size, read: (into, at) => readAt(fd, into, at) };
    const head = new Uint8Array(Math.min(size, KIND_BYTES));
    const read = readAt(fd, head, 0);
    if (read > 0) {
      const kind = captureKindOf(head.subarray(0, read), basename(file));
      capture = kind === 'raw' ? streamRaw(bytes) : kind === 'sscap' ? streamSscap(bytes, new SpanTally()) : streamCsv(bytes);
    }
    // The span is the series' origin and the links' end: found before any port is decoded, in one walk.
    if (capture !== null && capture.span === undefined) capture = { ...capture, span: captureSpan(capture) };
  } catch {
    // Not a capture, or unreadable: loadCapture reads it again and says why.
    capture = null;
  }
  if (capture === null) {
    closeSync(fd);
    return null;
  }
  return { capture, close: () => closeSync(fd) };
}

/** Bytes from file offset `at` into `into`, however many reads it takes; how many (fewer: the file ended). */
function readAt(fd: number, into: Uint8Array, at: number): number {
  let n = 0;
  for (let got = 1; n < into.length && got > 0; n += got) got = readSync(fd, into, n, into.length - n, at + n);
  return n;
}
