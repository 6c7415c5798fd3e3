/**
 * A file that arrives in order, a piece at a time, read as it comes: the worker reads a long
 * capture once and hands each piece to both halves of its replay pass (replay-split.ts), which
 * walk it with walkDataRecords as they would a File. Reading a File again costs as much as the
 * first time (the browser copies it across processes); a piece posted to a helper does not.
 */
import type { SlicedFile } from '../../capture/record-walk.js';

export class ArrivingFile implements SlicedFile {
  /**
   * The pieces not yet read past, in order, each with its file offset. Offsets are kept apart
   * from the pieces: a piece read past may be transferred away (its length then reads 0).
   */
  #pieces: { bytes: Uint8Array; at: number }[] = [];
  #arrived = 0;
  #failed: unknown = null;
  #waiting: (() => void)[] = [];
  /** Pieces read past, each with its end, until `passed` gives them back (`giveBack`). */
  #readPast: { bytes: Uint8Array; end: number }[] = [];

  /**
   * @param giveBack pieces read past are kept for `passed` (the helper hands them back to the
   *   worker, which reads the file's next pieces into them), not let go
   */
  constructor(
    readonly size: number,
    readonly giveBack = false,
  ) {}

  /** The next bytes of the file (kept, not copied). */
  push(piece: Uint8Array): void {
    if (piece.length === 0) return;
    this.#pieces.push({ bytes: piece, at: this.#arrived });
    this.#arrived += piece.length;
    this.#wake();
  }

  /** The file could not be read: every read waiting or to come fails with `error`. */
  fail(error: unknown): void {
    this.#failed = error ?? new Error('the file could not be read');
    // Nothing more is read: what is held is let go.
    this.#pieces = [];
    this.#readPast = [];
    this.#wake();
  }

  /**
   * The buffers of the pieces that end at or before `offset`, taken out (a file made to give
   * them back): whoever walked the file to `offset` holds no view of them any more.
   */
  passed(offset: number): ArrayBuffer[] {
    const out: ArrayBuffer[] = [];
    while ((this.#readPast[0]?.end ?? Number.POSITIVE_INFINITY) <= offset) out.push(this.#readPast.shift()?.bytes.buffer as ArrayBuffer);
    return out;
  }

  #wake(): void {
    const waiting = this.#waiting;
    this.#waiting = [];
    for (const go of waiting) go();
  }

  /** Bytes [start, end) in a buffer of their own: a whole piece that owns its buffer is that buffer, anything else a copy. */
  slice(start: number, end: number): { arrayBuffer(): Promise<ArrayBuffer> } {
    return {
      arrayBuffer: async () => {
        const bytes = await this.#read(start, end, true);
        return bytes.buffer as ArrayBuffer;
      },
    };
  }

  /** Bytes [start, end): a view of the piece that holds them all, a copy of those of several. */
  view(start: number, end: number): Promise<Uint8Array> {
    return this.#read(start, end, false);
  }

  /**
   * Bytes [start, end) once they have arrived: a view of the piece that holds them all (unless
   * `own`, a buffer of their own, is asked and they are not a whole piece that owns its buffer),
   * else a copy. Reads go forward: pieces before `start` are let go.
   */
  async #read(start: number, end: number, own: boolean): Promise<Uint8Array> {
    const to = Math.min(end, this.size);
    for (;;) {
      if (this.#failed !== null) throw this.#failed;
      if (this.#arrived >= to) break;
      await new Promise<void>((resolve) => this.#waiting.push(resolve));
    }
    const pieces = this.#pieces;
    let drop = 0;
    while (drop < pieces.length && (pieces[drop + 1]?.at ?? this.#arrived) <= start) drop++;
    if (drop > 0) {
      const gone = pieces.splice(0, drop);
      if (this.giveBack)
        for (const [k, { bytes }] of gone.entries()) this.#readPast.push({ bytes, end: gone[k + 1]?.at ?? pieces[0]?.at ?? this.#arrived });
    }
    const first = pieces[0];
    if (first === undefined || start < first.at) throw new RangeError(`bytes ${start}… were let go: reads go forward`);
    const from = start - first.at;
    const length = Math.max(0, to - start);
    if (from + length <= first.bytes.length) {
      const whole =
        from === 0 &&
        length === first.bytes.length &&
        first.bytes.byteOffset === 0 &&
        first.bytes.byteLength === first.bytes.buffer.byteLength;
      if (!own || whole) return first.bytes.subarray(from, from + length);
    }
    const out = new Uint8Array(length);
    for (const { bytes, at } of pieces) {
      if (at >= to) break;
      const a = Math.max(start, at);
      const b = Math.min(to, at + bytes.length);
      if (b > a) out.set(bytes.subarray(a - at, b - at), a - start);
    }
    return out;
  }
}
