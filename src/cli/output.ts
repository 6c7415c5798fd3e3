/**
 * Text to stdout with backpressure. Writing to a pipe is asynchronous in Node: what the reader
 * has not taken yet is queued in memory, so a decoder that writes as fast as it decodes holds
 * the whole output when the reader is slow (`| wc -l` on a 200 MB capture ran out of heap).
 * Here lines are gathered into blocks, and after a block the stream did not take at once the
 * writer waits for 'drain'. A reader that goes away (`| head`: EPIPE) ends the output normally.
 */
import type { Writable } from 'node:stream';

/** Characters gathered before a write: one write per line would dominate the run time. */
const BLOCK_CHARS = 1 << 16;

export class TextOutput {
  readonly #stream: Writable;
  #parts: string[] = [];
  #size = 0;
  /** The reader went away (EPIPE): the output ended early, which is not an error. */
  #closed = false;
  /** A write failed for another reason (disk full, a closed descriptor…). */
  #error: NodeJS.ErrnoException | null = null;
  /** Resolves the pending wait, if any: on 'drain', or when the stream ends or fails. */
  #wake: (() => void) | null = null;

  constructor(stream: Writable) {
    this.#stream = stream;
    stream.on('drain', () => this.#resume());
    stream.on('close', () => {
      this.#closed = true;
      this.#resume();
    });
    stream.on('error', (error: NodeJS.ErrnoException) => {
      if (error.code === 'EPIPE' || error.code === 'ERR_STREAM_DESTROYED') this.#closed = true;
      else this.#error ??= error;
      this.#resume();
    });
  }

  /** True when nothing more can be written: the reader went away, or a write failed. */
  get stopped(): boolean {
    return this.#closed || this.#error !== null;
  }

  /** The write error that stopped the output, if one did (a reader going away is not one). */
  get error(): NodeJS.ErrnoException | null {
    return this.#error;
  }

  /**
   * Adds one line. Returns true when the caller must `await ready()` before adding more (the
   * stream holds a block it has not written yet, or the output stopped).
   */
  line(text: string): boolean {
    this.#parts.push(text, '\n');
    this.#size += text.length + 1;
    return this.#size >= BLOCK_CHARS ? !this.#flush() : this.stopped;
  }

  /** Adds text as it is (a whole report), in one write. Returns as `line()` does. */
  text(text: string): boolean {
    this.#parts.push(text);
    this.#size += text.length;
    return !this.#flush();
  }

  /** Waits until the stream has taken what it holds, or the output stopped. */
  ready(): Promise<void> {
    if (this.stopped || !this.#stream.writableNeedDrain) return Promise.resolve();
    return new Promise((resolve) => {
      this.#wake = resolve;
    });
  }

  /**
   * Writes what is gathered and waits until the stream has written it, so that a failed last
   * write (a file on a full disk fails after `write()` returned) is known before exiting.
   */
  async end(): Promise<void> {
    const block = this.#parts.join('');
    this.#parts = [];
    this.#size = 0;
    if (this.stopped) return;
    // The callback runs once the block (and everything before it) is written, or on an error.
    await new Promise<void>((resolve) => this.#stream.write(block, () => resolve()));
    await this.ready();
  }

  /** Writes the gathered lines; false when the stream wants a 'drain' first (or has stopped). */
  #flush(): boolean {
    if (this.stopped) {
      this.#parts = [];
      this.#size = 0;
      return false;
    }
    if (this.#parts.length === 0) return !this.#stream.writableNeedDrain;
    const block = this.#parts.join('');
    this.#parts = [];
    this.#size = 0;
    return this.#stream.write(block) && !this.stopped;
  }

  #resume(): void {
    const wake = this.#wake;
    this.#wake = null;
    wake?.();
  }
}
