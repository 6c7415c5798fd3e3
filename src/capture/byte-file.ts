/**
 * A file the streaming readers read a piece at a time, synchronously: its size and a read at an
 * offset. The library names no file system; the CLI opens one (src/cli/streamed-file.ts).
 */
export interface ByteFile {
  readonly size: number;
  /** Bytes from file offset `at` into `into`, as many as there are up to its length; how many (fewer: the file ends). */
  read(into: Uint8Array, at: number): number;
}

/** Bytes read at a time by the streaming readers: big enough that a read costs nothing, small enough to hold. */
export const PIECE_BYTES = 1 << 20;
