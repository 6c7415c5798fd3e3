/**
 * A file that arrives in order, a piece at a time, read as it comes: the worker reads a long
 * capture once and hands each piece to both halves of its replay pass (replay-split.ts), which
 * walk it with walkDataRecords as they would a File. Reading a File again costs as much as the
 * first time (the browser copies it across processes); a piece posted to a helper does not.
 */
import type { SlicedFile } from '../capture/index.js';

export class ArrivingFile implements SlicedFile {
  /** The pieces not yet read past, in order, and the file offset of the first. */
  #pieces: Uint8Array[] = [];
  #firstAt = 0;
  #arrived = 0;
  #failed: unknown = null;
  #waiting: (() => void)[] = [];

  constructor(readonly size: number) {}

  /** The next bytes of the file (kept, not copied). */
  push(piece: Uint8Array): void {
    if (piece.length === 0) return;
    this.#pieces.push(piece);
    this.#arrived += piece.length;
    this.#wake();
  }

  /** The file could not be read: every read waiting or to come fails with `error`. */
  fail(error: unknown): void {
    this.#failed = error ?? new Error('the file could not be read');
    // Nothing more is read: what is held is let go.
    this.#pieces = [];
    this.#wake();
  }

  slice(start: number, end: number): { arrayBuffer(): Promise<ArrayBuffer> } {
    return { arrayBuffer: () => this.#read(start, Math.min(end, this.size)) };
  }

  #wake(): void {
    const waiting = this.#waiting;
    this.#waiting = [];
    for (const go of waiting) go();
  }

  /** Bytes [start, end) once they have arrived, copied. Reads go forward: pieces before `start` are let go. */
  async #read(start: number, end: number): Promise<ArrayBuffer> {
    for (;;) {
      if (this.#failed !== null) throw this.#failed;
      if (this.#arrived >= end) break;
      await new Promise<void>((resolve) => this.#waiting.push(resolve));
    }
    while (this.#pieces.length > 0 && this.#firstAt + (this.#pieces[0]?.length ?? 0) <= start) {
      this.#firstAt += this.#pieces.shift()?.length ?? 0;
    }
    if (start < this.#firstAt) throw new RangeError(`bytes ${start}… were let go: reads go forward`);
    // A read of exactly one piece that owns its buffer (one transferred here) is that buffer.
    const first = this.#pieces[0];
    if (
      first !== undefined &&
      start === this.#firstAt &&
      end - start === first.length &&
      first.byteOffset === 0 &&
      first.byteLength === first.buffer.byteLength
    )
      return first.buffer as ArrayBuffer;
    const out = new Uint8Array(Math.max(0, end - start));
    let at = this.#firstAt;
    for (const piece of this.#pieces) {
      if (at >= end) break;
      const from = Math.max(start, at);
      const to = Math.min(end, at + piece.length);
      if (to > from) out.set(piece.subarray(from - at, to - at), from - start);
      at += piece.length;
    }
    return out.buffer;
  }
}
