/**
 * Reading the capture a command names whole: the file's bytes through `readCapture`, or why not,
 * in the words and exit codes every command uses (2: the file cannot be read, 1: not a capture).
 * `decode` reads an .sscap or a CSV so; `info`, `report` and `doctor` only a file that cannot be
 * streamed (streamed-file.ts), one the reader must repair.
 *
 * A big file (`PARTS_MIN_BYTES` and up) is read on two threads, each half of it by one, into
 * shared memory. When it is an intact .sscap, its records are then cut into parts (`planParts`)
 * that both threads take in turn, each checking and copying the parts it takes (`readPart`).
 * The capture is the one `readCapture` makes; a damaged file, or a part the other thread could
 * not read, is read here alone, salvaging as ever.
 */
import { closeSync, fstatSync, openSync } from 'node:fs';
import { basename } from 'node:path';
import { assembleParts, type CapturePart, partColumns, planParts, readPart, type PartRead } from '../capture/parts.js';
import { CaptureFormatError, type Capture } from '../capture/model.js';
import { readCapture } from '../capture/sniff.js';
import type { ReadOptions } from '../capture/reader.js';
import { readFileRange } from './file-range.js';
import { fileProblem } from './file-problem.js';
import type { ReadThreadData, ReadThreadParts, ReadThreadResult } from './read-thread.js';
import { secondCore, WaitedWorker } from './waited-worker.js';

/** The capture, and how many of the file's bytes and of its parts the second thread read (0: read on this thread alone). */
export type LoadedCapture = { capture: Capture; bytesThere: number; partsThere: number } | { error: string; exitCode: 1 | 2 };

/** Files from this size on are read on two threads when they are intact .sscap captures. */
export const PARTS_MIN_BYTES = 32 << 20;

/**
 * The file's bytes (shorter than its size said: what was there), and for a big file on a
 * machine with a second core, in shared memory, the thread that read its second half while
 * this one read the first, to read the parts with (`readInParts`).
 * @throws what the file system says
 */
function readBytes(file: string, big: number): { bytes: Uint8Array; bytesThere: number; helper: WaitedWorker<ReadThreadResult> | null } {
  const fd = openSync(file, 'r');
  try {
    const size = fstatSync(fd).size;
    if (size < big || !secondCore()) {
      const bytes = new Uint8Array(size);
      return { bytes: bytes.subarray(0, readFileRange(fd, bytes, 0, size)), bytesThere: 0, helper: null };
    }
    const bytes = new Uint8Array(new SharedArrayBuffer(size));
    const half = Math.floor(size / 2);
    const data: ReadThreadData = { file, bytes, from: half, to: size };
    const helper = new WaitedWorker<ReadThreadResult>(new URL('./read-thread.js', import.meta.url), data);
    try {
      const mine = readFileRange(fd, bytes, 0, half);
      const there = helper.result(0);
      const readThere = there !== undefined && 'read' in there ? there.read : null;
      // The other thread could not read its half: read it here.
      const theirs = readThere ?? readFileRange(fd, bytes, half, size);
      return { bytes: bytes.subarray(0, mine < half ? mine : half + theirs), bytesThere: readThere ?? 0, helper };
    } catch (error) {
      helper.close();
      throw error;
    }
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

/**
 * An intact .sscap read on two threads (this one and `helper`, which has read the file's second
 * half and waits for the parts), and how many parts the other read; or null (not one, or not
 * intact: `readCapture` reads it).
 */
function readInParts(bytes: Uint8Array, helper: WaitedWorker<ReadThreadResult>): { capture: Capture; partsThere: number } | null {
  const plan = planParts(bytes, PARTS);
  if (plan === null) return null;
  const { parts } = plan;
  const columns = partColumns(plan, true);
  const taken = new Int32Array(new SharedArrayBuffer(4));
  helper.send({ parts, columns, taken } satisfies ReadThreadParts);
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
  // Then the other thread's, one result per part it took (after the one for its half of the file).
  for (let i = 0; i < parts.length - mine; i++) {
    const there = helper.result(1 + i);
    if (there === undefined || !('ok' in there) || !there.ok.intact) return null;
    reads[there.k] = there.ok;
  }
  const capture = reads.every((r) => r !== undefined) ? assembleParts(plan, columns, reads) : null;
  return capture === null ? null : { capture, partsThere: parts.length - mine };
}

/**
 * `options.shared`: the columns in shared memory, for a command that hands them to worker
 * threads (`ReadOptions`). Files of `partsMinBytes` and more are read on two threads.
 */
export function loadCapture(file: string, options: ReadOptions = {}, partsMinBytes = PARTS_MIN_BYTES): LoadedCapture {
  let read: ReturnType<typeof readBytes>;
  try {
    read = readBytes(file, partsMinBytes);
  } catch (error) {
    return { error: `cannot read ${file}: ${fileProblem(error, 'no such file')}`, exitCode: 2 };
  }
  const { bytes, bytesThere, helper } = read;
  try {
    const parts = helper === null ? null : readInParts(bytes, helper);
    return { bytesThere, ...(parts ?? { capture: readCapture(bytes, basename(file), options), partsThere: 0 }) };
  } catch (error) {
    if (error instanceof CaptureFormatError) return { error: `${file}: ${error.message}`, exitCode: 1 };
    throw error;
  } finally {
    helper?.close();
  }
}
