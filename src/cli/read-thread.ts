/**
 * The second thread of a big capture's reading (`loadCapture` in input.ts): checks and copies one part
 * of the file's records into the shared columns (`readPart`) and posts what it found.
 */
import type { CaptureColumns, CapturePart, PartRead } from '../capture/index.js';
import { workerSide } from './waited-worker.js';

/** What `loadCapture` hands this thread: the file's bytes and the columns, both shared. */
export interface ReadThreadData {
  bytes: Uint8Array;
  part: CapturePart;
  columns: CaptureColumns;
}

/** The part's reading, or why there is none (the reading thread then reads the file alone). */
export type ReadThreadResult = { ok: PartRead } | { error: string };

const { data, post } = workerSide<ReadThreadData>();
try {
  const { readPart } = await import('../capture/index.js');
  post({ ok: readPart(data.bytes, data.part, data.columns) } satisfies ReadThreadResult);
} catch (error) {
  post({ error: String(error) } satisfies ReadThreadResult);
}
