/**
 * Reading the capture a command names: the file's bytes through `readCapture`, or why not, in
 * the words and exit codes every command uses (2: the file cannot be read, 1: not a capture).
 *
 * A big .sscap (`PARTS_MIN_BYTES` and up) is read on two threads when it is intact: its bytes
 * and columns in shared memory, each thread checking and copying a part of its records
 * (`planParts`, `readPart`: this thread two fifths, having read the file and planned first). The capture is the one `readCapture` makes; a damaged file, or a
 * part the other thread could not read, is read here alone, salvaging as ever.
 */
import { closeSync, fstatSync, openSync, readSync } from 'node:fs';
import { basename } from 'node:path';
import {
  assembleParts,
  CaptureFormatError,
  partColumns,
  planParts,
  readCapture,
  readPart,
  type Capture,
  type ReadOptions,
} from '../capture/index.js';
import type { ReadThreadData, ReadThreadResult } from './read-thread.js';
import { secondCore, WaitedWorker } from './waited-worker.js';

export type LoadedCapture = { capture: Capture } | { error: string; exitCode: 1 | 2 };

/** Files from this size on are read on two threads when they are intact .sscap captures. */
export const PARTS_MIN_BYTES = 32 << 20;

/** The file's bytes, in shared memory when it is big. @throws what the file system says. */
function readBytes(file: string, big: number): Uint8Array {
  const fd = openSync(file, 'r');
  try {
    const size = fstatSync(fd).size;
    const bytes = new Uint8Array(size >= big ? new SharedArrayBuffer(size) : new ArrayBuffer(size));
    for (let at = 0; at < size; ) {
      const n = readSync(fd, bytes, at, size - at, at);
      if (n === 0) return bytes.subarray(0, at); // shorter than it said: what was there
      at += n;
    }
    return bytes;
  } finally {
    closeSync(fd);
  }
}

/** An intact .sscap read on two threads, or null (not one, or not intact: `readCapture` reads it). */
function readInParts(bytes: Uint8Array): Capture | null {
  // This thread has read the file and planned before the worker starts, so it takes the smaller part.
  const plan = planParts(bytes, [2, 3]);
  const [mine, theirs] = plan?.parts ?? [];
  if (plan === null || mine === undefined || theirs === undefined) return null;
  const columns = partColumns(plan, true);
  const data: ReadThreadData = { bytes, part: theirs, columns };
  const worker = new WaitedWorker<ReadThreadResult>(new URL('./read-thread.js', import.meta.url), data);
  try {
    const here = readPart(bytes, mine, columns);
    const there = here.intact ? worker.result(0) : undefined;
    return there !== undefined && 'ok' in there ? assembleParts(plan, columns, [here, there.ok]) : null;
  } finally {
    worker.close();
  }
}

/**
 * `options.shared`: the columns in shared memory, for a command that hands them to worker
 * threads (`ReadOptions`). Files of `partsMinBytes` and more are read on two threads.
 */
export function loadCapture(file: string, options: ReadOptions = {}, partsMinBytes = PARTS_MIN_BYTES): LoadedCapture {
  let bytes: Uint8Array;
  try {
    bytes = readBytes(file, partsMinBytes);
  } catch (error) {
    const code = (error as NodeJS.ErrnoException).code;
    const why =
      code === 'ENOENT'
        ? 'no such file'
        : code === 'EISDIR'
          ? 'it is a directory'
          : code === 'EACCES'
            ? 'permission denied'
            : String(error);
    return { error: `cannot read ${file}: ${why}`, exitCode: 2 };
  }
  try {
    const parts = bytes.length >= partsMinBytes && secondCore() ? readInParts(bytes) : null;
    return { capture: parts ?? readCapture(bytes, basename(file), options) };
  } catch (error) {
    if (error instanceof CaptureFormatError) return { error: `${file}: ${error.message}`, exitCode: 1 };
    throw error;
  }
}
