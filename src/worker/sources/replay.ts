/**
 * Replay: a capture file played back through exactly the live path, chunk by chunk at the
 * recorded times, at 1×, 4× or as fast as possible, with pause and seek. The source clock is
 * the capture's own; a seek starts a fresh decode just before the target and skips ahead.
 */
import { captureChunks, type Capture } from '../../decoder/index.js';

/** Chunk views of one port, with the time argument the decoder takes. */
interface Chunk {
  bytes: Uint8Array;
  time: number | Float64Array | undefined;
  /** Arrival time of the chunk's last byte, µs (for scheduling); NaN without timing. */
  atUs: number;
}

const TICK_MS = 10;
/** At full speed, decode for this long per tick, then let messages through. */
const SLICE_MS = 12;
/** A seek replays this much before the target so the graphs and failsafe state have history. */
const SEEK_HISTORY_US = 10 * 60e6;

export class ReplaySource {
  readonly chunks: Chunk[] = [];
  readonly startUs: number;
  readonly endUs: number;
  #next = 0;
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
  constructor(
    readonly capture: Capture,
    readonly feed: (bytes: Uint8Array, time: number | Float64Array | undefined, atUs: number) => void,
    readonly onTick: (clockUs: number) => void,
    readonly onEnd: () => void,
  ) {
    for (const c of captureChunks(capture, 0)) {
      const atUs = c.byteTimesUs !== undefined ? (c.byteTimesUs[c.byteTimesUs.length - 1] ?? NaN) : c.timeUs;
      if (c.byteTimesUs !== undefined && c.bytes.length > 4096) {
        // Per-byte captures are one chunk: cut them into pieces that play at their times.
        for (let i = 0; i < c.bytes.length; i += 64) {
          const end = Math.min(c.bytes.length, i + 64);
          const times = c.byteTimesUs.subarray(i, end);
          this.chunks.push({ bytes: c.bytes.subarray(i, end), time: times, atUs: times[times.length - 1] as number });
        }
      } else {
        this.chunks.push({ bytes: c.bytes, time: c.time, atUs });
      }
    }
    const timed = this.chunks.filter((c) => Number.isFinite(c.atUs));
    this.startUs = timed.length > 0 ? (timed[0] as Chunk).atUs : 0;
    this.endUs = timed.length > 0 ? (timed[timed.length - 1] as Chunk).atUs : 0;
    this.#clockUs = this.startUs;
    // Untimed captures (raw .bin) play as fast as possible: there is no clock to follow.
    if (timed.length === 0) this.#speed = 0;
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
    const from = target - SEEK_HISTORY_US;
    let i = 0;
    while (i < this.chunks.length && (this.chunks[i] as Chunk).atUs < from) i++;
    for (; i < this.chunks.length && (this.chunks[i] as Chunk).atUs <= target; i++) {
      const c = this.chunks[i] as Chunk;
      this.feed(c.bytes, c.time, c.atUs);
    }
    this.#next = i;
    this.#clockUs = target;
    this.#wallMs = performance.now();
    this.onTick(this.#clockUs);
  }

  stop(): void {
    this.pause();
  }

  #tick(): void {
    const nowMs = performance.now();
    if (this.#speed === 0) {
      // As fast as possible, in slices so the worker stays responsive.
      while (this.#next < this.chunks.length && performance.now() - nowMs < SLICE_MS) {
        const c = this.chunks[this.#next++] as Chunk;
        this.feed(c.bytes, c.time, c.atUs);
        if (Number.isFinite(c.atUs)) this.#clockUs = c.atUs;
      }
    } else {
      this.#clockUs += (nowMs - this.#wallMs) * 1000 * this.#speed;
      while (this.#next < this.chunks.length && !((this.chunks[this.#next] as Chunk).atUs > this.#clockUs)) {
        const c = this.chunks[this.#next++] as Chunk;
        this.feed(c.bytes, c.time, c.atUs);
      }
    }
    this.#wallMs = nowMs;
    if (this.#next >= this.chunks.length) {
      this.#clockUs = Math.max(this.#clockUs, this.endUs);
      this.pause();
      this.onTick(this.#clockUs);
      this.onEnd();
      return;
    }
    this.onTick(this.#clockUs);
  }
}
