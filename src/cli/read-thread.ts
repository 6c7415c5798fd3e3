/**
 * The second thread of a big capture's reading (`loadCapture` in input.ts): takes parts of the
 * file's records in turn with the reading thread (the next one not taken, from a shared count),
 * checks and copies each into the shared columns (`readPart`) and posts what it found, until
 * none is left or one is not intact.
 */
import type { CaptureColumns, CapturePart, PartRead } from '../capture/index.js';
import { workerSide } from './waited-worker.js';

/** What `loadCapture` hands this thread: the file's bytes, its parts, the columns and the count of parts taken, all shared. */
export interface ReadThreadData {
  bytes: Uint8Array;
  parts: readonly CapturePart[];
  columns: CaptureColumns;
  /** [0]: the next part to take (Atomics.add); past the last, nothing is left. */
  taken: Int32Array;
}

/** Part `k`'s reading, or why this thread could not read (the reading thread then reads the file alone). */
export type ReadThreadResult = { k: number; ok: PartRead } | { error: string };

const { data, post } = workerSide<ReadThreadData>();
try {
  const { readPart } = await import('../capture/index.js');
  const { bytes, parts, columns, taken } = data;
  for (let k = Atomics.add(taken, 0, 1); k < parts.length; k = Atomics.add(taken, 0, 1)) {
    const part = parts[k] as CapturePart;
    const ok = readPart(bytes, part, columns);
    post({ k, ok } satisfies ReadThreadResult);
    if (!ok.intact) break;
  }
} catch (error) {
  post({ error: String(error) } satisfies ReadThreadResult);
}
