/**
 * A File read forward a piece at a time, each piece into a buffer handed back from an earlier
 * one where there is one: a long capture's pieces go round between the worker and its helper
 * (replay-split.ts), so that reading the file does not map hundreds of megabytes afresh. Reads
 * through the File's byte stream into the given buffer (a BYOB reader) where the browser has
 * one, else a slice at a time into a new buffer; and a slice at a time from a read of the stream
 * that never answers on.
 */

/** What is read: a Blob or File, or a stand-in with the same reads (tests). */
export type ReadableFile = Pick<Blob, 'size' | 'slice' | 'stream'>;

/**
 * A read of the byte stream that has brought nothing for this long is given up: the stream is
 * cancelled and the file read a slice at a time from the piece that stalled: a browser's stream
 * of a File in a worker has been seen never to answer a read, where slices always did
 * (bench/README.md).
 */
const STALL_MS = 500;

export class PieceReader {
  #at = 0;
  /** The file's byte stream, read into the buffers given; null: read a slice at a time. */
  #reader: ReadableStreamBYOBReader | null;

  constructor(
    readonly file: ReadableFile,
    readonly pieceBytes: number,
    readonly stallMs = STALL_MS,
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
    let piece = reader === null ? null : await this.#readInto(reader, spare, length);
    if (piece === null) {
      // No byte stream, or it stalled: given up on (cancelled), the piece read again from its start.
      if (reader !== null) this.stop();
      piece = new Uint8Array(await this.file.slice(this.#at, this.#at + length).arrayBuffer());
    }
    if (piece.length < length) throw new Error(`the file ended after ${this.#at + piece.length} of ${size} bytes`);
    this.#at += piece.length;
    return piece;
  }

  /** `length` bytes of the stream, in `spare` when it fits (else a new buffer); null when a read stalled. */
  async #readInto(reader: ReadableStreamBYOBReader, spare: ArrayBuffer | undefined, length: number): Promise<Uint8Array | null> {
    let buffer = spare !== undefined && spare.byteLength === this.pieceBytes ? spare : new ArrayBuffer(this.pieceBytes);
    let filled = 0;
    while (filled < length) {
      // Each read takes the buffer over and gives it back with what it read.
      const read = await answered(reader.read(new Uint8Array(buffer, filled, length - filled)), this.stallMs);
      if (read === null) return null;
      const { value, done } = read;
      if (value !== undefined) buffer = value.buffer as ArrayBuffer;
      if (done || value === undefined) break;
      filled += value.byteLength;
    }
    return new Uint8Array(buffer, 0, filled);
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

/** What `read` settles to, or null if it has not within `ms`. */
async function answered<T>(read: Promise<T>, ms: number): Promise<T | null> {
  let timer: ReturnType<typeof setTimeout> | undefined;
  const stalled = new Promise<null>((resolve) => {
    timer = setTimeout(() => resolve(null), ms);
  });
  try {
    return await Promise.race([read, stalled]);
  } finally {
    clearTimeout(timer);
  }
}
