/**
 * The second thread of a big capture's reading (`loadCapture` in input.ts). First it reads the
 * file's second half into the shared bytes while the reading thread reads the first, and posts
 * how many bytes it read. Then, when the reading thread sends it the parts of an intact .sscap,
 * it takes parts in turn with that thread (the next one not taken, from a shared count), checks
 * and copies each into the shared columns (`readPart`) and posts what it found, until none is
 * left or one is not intact. A file that is not one is never sent: this thread is stopped.
 */
import { closeSync, openSync } from 'node:fs';
import type { CaptureColumns, CapturePart, PartRead } from '../capture/parts.js';
import { readFileRange } from './file-range.js';
import { workerSide } from './waited-worker.js';

/** What `loadCapture` hands this thread when it starts: the file, the shared bytes, and the range of them to read. */
export interface ReadThreadData {
  file: string;
  bytes: Uint8Array;
  from: number;
  to: number;
}

/** What `loadCapture` sends it once the file is read: its parts, the columns and the count of parts taken, all shared. */
export interface ReadThreadParts {
  parts: readonly CapturePart[];
  columns: CaptureColumns;
  /** [0]: the next part to take (Atomics.add); past the last, nothing is left. */
  taken: Int32Array;
}

/** First the bytes it read (fewer than asked: the file ended first); then part `k`'s reading, one per part; or why it could not. */
export type ReadThreadResult = { read: number } | { k: number; ok: PartRead } | { error: string };

const { data, post, next } = workerSide<ReadThreadData>();
try {
  const { file, bytes, from, to } = data;
  const fd = openSync(file, 'r');
  let read: number;
  try {
    read = readFileRange(fd, bytes, from, to);
  } finally {
    closeSync(fd);
  }
  post({ read } satisfies ReadThreadResult);
  const { readPart } = await import('../capture/parts.js');
  const { parts, columns, taken } = (await next()) as ReadThreadParts;
  for (let k = Atomics.add(taken, 0, 1); k < parts.length; k = Atomics.add(taken, 0, 1)) {
    const part = parts[k] as CapturePart;
    const ok = readPart(bytes, part, columns);
    post({ k, ok } satisfies ReadThreadResult);
    if (!ok.intact) break;
  }
} catch (error) {
  post({ error: String(error) } satisfies ReadThreadResult);
}
