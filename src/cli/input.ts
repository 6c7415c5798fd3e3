/**
 * Reading the capture a command names: the file's bytes through `readCapture`, or why not, in
 * the words and exit codes every command uses (2: the file cannot be read, 1: not a capture).
 *
 * A big .sscap (`PARTS_MIN_BYTES` and up) is read on two threads when it is intact: its bytes
 * and columns in shared memory, its records cut into parts (`planParts`) that both threads take
 * in turn, each checking and copying the parts it takes (`readPart`). The capture is the one
 * `readCapture` makes; a damaged file, or a part the other thread could not read, is read here
 * alone, salvaging as ever.
 */
import { closeSync, fstatSync, openSync, readSync } from 'node:fs';
import { basename } from 'node:path';
import {
  assembleParts,
  CaptureFormatError,
  type CapturePart,
  partColumns,
  planParts,
  readCapture,
  readPart,
  type Capture,
  type PartRead,
  type ReadOptions,
} from '../capture/index.js';
import type { ReadThreadData, ReadThreadResult } from './read-thread.js';
import { secondCore, WaitedWorker } from './waited-worker.js';

/** The capture, and how many of its parts the second thread read (0: read on this thread alone). */
export type LoadedCapture = { capture: Capture; partsThere: number } | { error: string; exitCode: 1 | 2 };

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

/**
 * Parts the records are cut into for two threads to take in turn: enough that neither waits long
 * for the other at the end (the other thread starts later, and machines differ), few enough that
 * taking one costs nothing.
 */
const PARTS = 16;

/** An intact .sscap read on two threads, and how many parts the other read; or null (not one, or not intact: `readCapture` reads it). */
function readInParts(bytes: Uint8Array): { capture: Capture; partsThere: number } | null {
  const plan = planParts(bytes, PARTS);
  if (plan === null) return null;
  const { parts } = plan;
  const columns = partColumns(plan, true);
  const taken = new Int32Array(new SharedArrayBuffer(4));
  const data: ReadThreadData = { bytes, parts, columns, taken };
  const worker = new WaitedWorker<ReadThreadResult>(new URL('./read-thread.js', import.meta.url), data);
  try {
    // Both threads take the next part not taken until none is left; one that is not intact stops both.
    const reads: (PartRead | undefined)[] = new Array(parts.length);
    let mine = 0;
    for (let k = Atomics.add(taken, 0, 1); k < parts.length; k = Atomics.add(taken, 0, 1)) {
      const read = readPart(bytes, parts[k] as CapturePart, columns);
      if (!read.intact) {
        Atomics.store(taken, 0, parts.length);
        return null;
      }
      reads[k] = read;
      mine++;
    }
    // Then the other thread's, one result per part it took.
    for (let i = 0; i < parts.length - mine; i++) {
      const there = worker.result(i);
      if (there === undefined || !('ok' in there) || !there.ok.intact) return null;
      reads[there.k] = there.ok;
    }
    const capture = reads.every((r) => r !== undefined) ? assembleParts(plan, columns, reads) : null;
    return capture === null ? null : { capture, partsThere: parts.length - mine };
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
    return parts ?? { capture: readCapture(bytes, basename(file), options), partsThere: 0 };
  } catch (error) {
    if (error instanceof CaptureFormatError) return { error: `${file}: ${error.message}`, exitCode: 1 };
    throw error;
  }
}
