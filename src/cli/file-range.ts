/**
 * A range of a file read into memory, however many reads it takes: both threads of a big
 * capture's reading (input.ts, read-thread.ts) read their half so.
 */
import { readSync } from 'node:fs';

/** The most one read asks for: Node refuses a length of 2 GiB or more. */
const MAX_READ = 1 << 30;

/** Bytes `[from, to)` of the open file `fd` into `bytes` at the same offsets; how many there were (fewer: the file ended first). */
export function readFileRange(fd: number, bytes: Uint8Array, from: number, to: number): number {
  let at = from;
  for (let n = 1; at < to && n > 0; at += n) n = readSync(fd, bytes, at, Math.min(to - at, MAX_READ), at);
  return at - from;
}
