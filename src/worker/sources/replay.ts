/**
 * Replay: a capture file played back through exactly the live path, chunk by chunk at the
 * recorded times, at 1×, 4× or as fast as possible, with pause and seek. The source clock is
 * the capture's own; a seek starts a fresh decode just before the target and skips ahead.
 */
import type { Capture } from '../../decoder/index.js';

/** Chunk views of one port, with their times. */
interface Chunk {
  bytes: Uint8Array;
  /** Per-byte times (logic-analyser captures): bytes are fed as their own times pass. */
  byteTimes: Float64Array | undefined;
  /** The chunk's arrival (its last byte), µs; NaN without timing. */
  atUs: number;
}

/**
 * The chunks of port 0 straight from the capture's columns: an hour of USB batches is 225 000
 * chunks, so they are read by index when fed, never turned into objects up front.
 */
class Chunks {
  readonly length: number;
  readonly #index: Uint32Array;
  constructor(readonly capture: Capture) {
    const ports = capture.chunkPorts;
    let n = 0;
    const index = new Uint32Array(ports.length);
    for (let i = 0; i < ports.length; i++) if (ports[i] === 0) index[n++] = i;
    this.#index = index.subarray(0, n);
    this.length = n;
  }

  /** Arrival time of chunk k (µs), NaN without timing. */
  atUs(k: number): number {
    const i = this.#index[k] as number;
    const times = this.capture.byteTimesUs;
    if (times !== undefined) return times[(this.capture.chunkEnds[i] as number) - 1] ?? NaN;
    return this.capture.chunkTimesUs[i] as number;
  }

  get(k: number): Chunk {
    const i = this.#index[k] as number;
    const c = this.capture;
    const start = i === 0 ? 0 : (c.chunkEnds[i - 1] as number);
    const end = c.chunkEnds[i] as number;
    return { bytes: c.bytes.subarray(start, end), byteTimes: c.byteTimesUs?.subarray(start, end), atUs: this.atUs(k) };
  }
}

const TICK_MS = 10;
/** Decode for at most this long per tick, then let messages through. */
const SLICE_MS = 12;
/** A seek replays this much before the target so the graphs and failsafe state have history. */
const SEEK_HISTORY_US = 10 * 60e6;

export class ReplaySource {
  readonly chunks: Chunks;
  readonly startUs: number;
  readonly endUs: number;
  #next = 0;
  /** Bytes of chunk #next already fed (per-byte-timed chunks are fed a piece at a time). */
  #nextByte = 0;
  #clockUs: number;
  #wallMs = 0;
  #speed = 1;
  #playing = false;
  #timer: ReturnType<typeof setInterval> | undefined;

  /**
   * @param feed gets each chunk's bytes and time argument, and the chunk's time
   * @param onTick after each tick that moved the clock (the worker sends a batch)
   * @param onEnd when the last chunk has been fed
   */
  #lastFedUs = NaN;

  constructor(
    readonly capture: Capture,
    readonly sink: (bytes: Uint8Array, time: number | Float64Array | undefined, atUs: number) => void,
    readonly onTick: (clockUs: number) => void,
    readonly onEnd: () => void,
  ) {
    this.chunks = new Chunks(capture);
    let first = 0;
    while (first < this.chunks.length && !Number.isFinite(this.chunks.atUs(first))) first++;
    let last = this.chunks.length - 1;
    while (last >= 0 && !Number.isFinite(this.chunks.atUs(last))) last--;
    const timed = first <= last;
    this.startUs = timed ? this.chunks.atUs(first) : 0;
    this.endUs = timed ? this.chunks.atUs(last) : 0;
    this.#clockUs = this.startUs;
    // Untimed captures (raw .bin) play as fast as possible: there is no clock to follow.
    if (!timed) this.#speed = 0;
  }

  /** Hands bytes to the sink and remembers the time of the last one fed. */
  feed(bytes: Uint8Array, time: number | Float64Array | undefined, atUs: number): void {
    if (Number.isFinite(atUs)) this.#lastFedUs = atUs;
    this.sink(bytes, time, atUs);
  }

  get timed(): boolean {
    return this.endUs > this.startUs;
  }

  get playing(): boolean {
    return this.#playing;
  }

  get speed(): number {
    return this.#speed;
  }

  get positionUs(): number {
    return this.#clockUs;
  }

  play(): void {
    if (this.#playing) return;
    if (this.#next >= this.chunks.length) return;
    this.#playing = true;
    this.#wallMs = performance.now();
    this.#timer = setInterval(() => this.#tick(), TICK_MS);
  }

  pause(): void {
    this.#playing = false;
    clearInterval(this.#timer);
    this.#timer = undefined;
  }

  setSpeed(speed: number): void {
    if (!this.timed) return;
    this.#speed = speed;
    this.#wallMs = performance.now();
  }

  /**
   * Moves to `timeUs`: the caller resets its decode state first; the chunks from a while before
   * the target are fed at once so history is there, then playback goes on from the target.
   */
  seek(timeUs: number): void {
    const target = Math.min(Math.max(timeUs, this.startUs), this.endUs);
    this.#next = 0;
    this.#nextByte = 0;
    // Skip what lies before the history window, then feed up to the target at once.
    const from = target - SEEK_HISTORY_US;
    while (this.#next < this.chunks.length && this.chunks.atUs(this.#next) < from) this.#next++;
    this.#feedUntil(target, Infinity);
    this.#clockUs = target;
    this.#wallMs = performance.now();
    this.onTick(this.#clockUs);
  }

  /**
   * Feeds every byte whose time is at or before `clockUs` (a chunk-timed chunk whole once its
   * arrival time has passed; a per-byte-timed one byte range by byte range), for at most
   * `budgetMs` of wall time. Returns whether all chunks have been fed.
   */
  #feedUntil(clockUs: number, budgetMs: number): boolean {
    const started = performance.now();
    while (this.#next < this.chunks.length) {
      if (budgetMs !== Infinity && performance.now() - started > budgetMs) return false;
      const c = this.chunks.get(this.#next);
      if (c.byteTimes === undefined) {
        if (c.atUs > clockUs) return false;
        this.feed(c.bytes, Number.isNaN(c.atUs) ? undefined : c.atUs, c.atUs);
        this.#next++;
        continue;
      }
      // Per-byte times: up to 4096 bytes whose time has come.
      const times = c.byteTimes;
      let end = this.#nextByte;
      const limit = Math.min(times.length, this.#nextByte + 4096);
      while (end < limit && !((times[end] as number) > clockUs)) end++;
      if (end > this.#nextByte) this.feed(c.bytes.subarray(this.#nextByte, end), times.subarray(this.#nextByte, end), times[end - 1] as number);
      this.#nextByte = end;
      if (end === times.length) {
        this.#next++;
        this.#nextByte = 0;
      } else if (end < limit) {
        return false;
      }
    }
    return true;
  }

  stop(): void {
    this.pause();
  }

  #tick(): void {
    const nowMs = performance.now();
    let done: boolean;
    if (this.#speed === 0) {
      // As fast as possible, in slices so the worker stays responsive.
      done = this.#feedUntil(Infinity, SLICE_MS);
      if (this.timed) this.#clockUs = done ? this.endUs : Math.max(this.#clockUs, this.#lastFedUs);
    } else {
      this.#clockUs += (nowMs - this.#wallMs) * 1000 * this.#speed;
      done = this.#feedUntil(this.#clockUs, SLICE_MS);
    }
    this.#wallMs = nowMs;
    if (done) {
      this.#clockUs = Math.max(this.#clockUs, this.endUs);
      this.pause();
      this.onTick(this.#clockUs);
      this.onEnd();
      return;
    }
    this.onTick(this.#clockUs);
  }
}
