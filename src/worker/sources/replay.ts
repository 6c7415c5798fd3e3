/**
 * Replay: a capture file played back through exactly the live path, chunk by chunk at the
 * recorded times, at 1×, 4× or as fast as possible, with pause and seek. A capture may hold
 * several ports (remotes) with one common clock: each port feeds its own decode, and all of
 * them advance with the one replay clock.
 */
import { capturePorts, type Capture } from '../../decoder/index.js';

/** One chunk's bytes with their times. */
interface Chunk {
  bytes: Uint8Array;
  /** Per-byte times (logic-analyser captures): bytes are fed as their own times pass. */
  byteTimes: Float64Array | undefined;
  /** The chunk's arrival (its last byte), µs; NaN without timing. */
  atUs: number;
}

/**
 * The chunks of one port straight from the capture's columns: an hour of USB batches is 225 000
 * chunks, so they are read by index when fed, never turned into objects up front.
 */
class PortChunks {
  readonly length: number;
  readonly #index: Uint32Array;
  /** Next chunk to feed, and bytes of it already fed (per-byte-timed chunks go piece by piece). */
  next = 0;
  nextByte = 0;

  constructor(readonly capture: Capture, readonly port: number) {
    const ports = capture.chunkPorts;
    let n = 0;
    const index = new Uint32Array(ports.length);
    for (let i = 0; i < ports.length; i++) if (ports[i] === port) index[n++] = i;
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

  get done(): boolean {
    return this.next >= this.length;
  }
}

export type ReplaySink = (port: number, bytes: Uint8Array, time: number | Float64Array | undefined, atUs: number) => void;

const TICK_MS = 10;
/** Decode for at most this long per tick, then let messages through. */
const SLICE_MS = 12;
/** The most wall time one tick may move the replay clock by. */
const MAX_STEP_MS = 100;
/** A seek replays this much before the target so the graphs and failsafe state have history. */
const SEEK_HISTORY_US = 10 * 60e6;

export class ReplaySource {
  readonly ports: readonly number[];
  readonly #chunks: PortChunks[];
  readonly startUs: number;
  readonly endUs: number;
  #clockUs: number;
  #wallMs = 0;
  #speed = 1;
  #playing = false;
  #lastFedUs = NaN;
  #timer: ReturnType<typeof setInterval> | undefined;

  /**
   * @param sink gets each piece of a port's bytes with its time argument and arrival time
   * @param onTick after each tick that moved the clock (the worker sends batches)
   * @param onEnd when every port's last chunk has been fed
   */
  constructor(
    readonly capture: Capture,
    readonly sink: ReplaySink,
    readonly onTick: (clockUs: number) => void,
    readonly onEnd: () => void,
  ) {
    this.ports = capturePorts(capture);
    this.#chunks = this.ports.map((p) => new PortChunks(capture, p));
    let start = Infinity;
    let end = -Infinity;
    for (const c of this.#chunks) {
      for (let k = 0; k < c.length; k++) {
        const t = c.atUs(k);
        if (Number.isFinite(t)) {
          start = Math.min(start, t);
          break;
        }
      }
      for (let k = c.length - 1; k >= 0; k--) {
        const t = c.atUs(k);
        if (Number.isFinite(t)) {
          end = Math.max(end, t);
          break;
        }
      }
    }
    const timed = start <= end;
    this.startUs = timed ? start : 0;
    this.endUs = timed ? end : 0;
    this.#clockUs = this.startUs;
    // Untimed captures (raw .bin) play as fast as possible: there is no clock to follow.
    if (!timed) this.#speed = 0;
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
    if (this.#playing || this.#chunks.every((c) => c.done)) return;
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
    this.#lastFedUs = NaN;
    const from = target - SEEK_HISTORY_US;
    for (const c of this.#chunks) {
      c.next = 0;
      c.nextByte = 0;
      while (c.next < c.length && c.atUs(c.next) < from) c.next++;
    }
    this.#feedUntil(target, Infinity);
    this.#clockUs = target;
    this.#wallMs = performance.now();
    this.onTick(this.#clockUs);
  }

  stop(): void {
    this.pause();
  }

  #feed(port: number, bytes: Uint8Array, time: number | Float64Array | undefined, atUs: number): void {
    if (Number.isFinite(atUs) && !(atUs <= this.#lastFedUs)) this.#lastFedUs = atUs;
    this.sink(port, bytes, time, atUs);
  }

  /**
   * Feeds every byte whose time is at or before `clockUs`, port by port (a chunk-timed chunk
   * whole once its arrival has passed; a per-byte-timed one range by range), for at most
   * `budgetMs` of wall time. Returns whether everything has been fed.
   */
  #feedUntil(clockUs: number, budgetMs: number): boolean {
    const started = performance.now();
    for (const c of this.#chunks) {
      while (c.next < c.length) {
        if (budgetMs !== Infinity && performance.now() - started > budgetMs) return false;
        const chunk = c.get(c.next);
        if (chunk.byteTimes === undefined) {
          if (chunk.atUs > clockUs) break;
          this.#feed(c.port, chunk.bytes, Number.isNaN(chunk.atUs) ? undefined : chunk.atUs, chunk.atUs);
          c.next++;
          continue;
        }
        const times = chunk.byteTimes;
        const limit = Math.min(times.length, c.nextByte + 4096);
        let end = c.nextByte;
        while (end < limit && !((times[end] as number) > clockUs)) end++;
        if (end > c.nextByte) this.#feed(c.port, chunk.bytes.subarray(c.nextByte, end), times.subarray(c.nextByte, end), times[end - 1] as number);
        c.nextByte = end;
        if (end === times.length) {
          c.next++;
          c.nextByte = 0;
        } else if (end < limit) {
          break;
        }
      }
    }
    return this.#chunks.every((c) => c.done);
  }

  #tick(): void {
    const nowMs = performance.now();
    let done: boolean;
    if (this.#speed === 0) {
      // As fast as possible, in slices so the worker stays responsive; the clock follows the data.
      done = this.#feedUntil(Infinity, SLICE_MS);
      if (this.timed && Number.isFinite(this.#lastFedUs)) this.#clockUs = Math.max(this.#clockUs, this.#lastFedUs);
    } else {
      // A stall (a long task, a background tab) must not jump the clock past silent data: that
      // would show a hold or failsafe that is not in the capture.
      this.#clockUs += Math.min(nowMs - this.#wallMs, MAX_STEP_MS) * 1000 * this.#speed;
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
