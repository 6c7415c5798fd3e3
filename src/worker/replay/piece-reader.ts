/**
 * A File read forward a piece at a time, each piece into a buffer handed back from an earlier
 * one where there is one: a long capture's pieces go round between the worker and its helper
 * (replay-split.ts), so that reading the file does not map hundreds of megabytes afresh. Reads
 * through the File's byte stream into the given buffer (a BYOB reader) where the browser has
 * one, else a slice at a time into a new buffer.
 */

/** What is read: a Blob or File, or a stand-in with the same reads (tests). */
export type ReadableFile = Pick<Blob, 'size' | 'slice' | 'stream'>;

export class PieceReader {
  #at = 0;
  /** The file's byte stream, read into the buffers given; null: read a slice at a time. */
  #reader: ReadableStreamBYOBReader | null;

  constructor(
    readonly file: ReadableFile,
    readonly pieceBytes: number,
  ) {
    this.#reader = byobReader(file);
  }

  /** How far the file is read. */
  get at(): number {
    return this.#at;
  }

  /**
   * The next piece (`pieceBytes`, the last one shorter), in `spare` when it is a buffer of
   * `pieceBytes` (it is taken over), else in a new one; null at the end of the file.
   * @throws when the file cannot be read, or ends before its size
   */
  async next(spare?: ArrayBuffer): Promise<Uint8Array | null> {
    const size = this.file.size;
    const length = Math.min(this.pieceBytes, size - this.#at);
    if (length <= 0) return null;
    const reader = this.#reader;
    let piece: Uint8Array;
    if (reader === null) {
      piece = new Uint8Array(await this.file.slice(this.#at, this.#at + length).arrayBuffer());
    } else {
      let buffer = spare !== undefined && spare.byteLength === this.pieceBytes ? spare : new ArrayBuffer(this.pieceBytes);
      let filled = 0;
      while (filled < length) {
        // Each read takes the buffer over and gives it back with what it read.
        const { value, done } = await reader.read(new Uint8Array(buffer, filled, length - filled));
        if (value !== undefined) buffer = value.buffer as ArrayBuffer;
        if (done || value === undefined) break;
        filled += value.byteLength;
      }
      piece = new Uint8Array(buffer, 0, filled);
    }
    if (piece.length < length) throw new Error(`the file ended after ${this.#at + piece.length} of ${size} bytes`);
    this.#at += piece.length;
    return piece;
  }

  /** Nothing more is read. */
  stop(): void {
    this.#reader?.cancel().catch(() => undefined);
    this.#reader = null;
  }
}

/** A reader into given buffers of `file`'s byte stream, or null when there is none (a browser without it). */
function byobReader(file: ReadableFile): ReadableStreamBYOBReader | null {
  try {
    return file.stream().getReader({ mode: 'byob' });
  } catch {
    return null;
  }
}
