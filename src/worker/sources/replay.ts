/**
 * Replay: a capture file played back through exactly the live path, chunk by chunk at the
 * recorded times, at 1×, 4× or as fast as possible, with pause and seek. A capture may hold
 * several ports (remotes) with one common clock: each port feeds its own decode, and all of
 * them advance with the one replay clock.
 */
import { BYTE_TIME_US, FRAME_PERIOD_11MS_US, FRAME_SIZE } from '../../decoder/index.js';
import { captureChunksByPort, capturePorts, captureTimesInOrder, type Capture } from '../../capture/index.js';
import { captureSpan } from '../../analysis/index.js';
import { BROWSER_CLOCK, type Clock } from '../host.js';

/** Wall time and ticks, passed in so that tests drive replay with a simulated clock. */
export type ReplayClock = Pick<Clock, 'now' | 'every' | 'cancel'>;

export interface ReplayOptions {
  clock?: ReplayClock;
  /**
   * For a capture without timing (raw .bin): the receiver's frame period, µs, at whose pace
   * (16 bytes a period) its bytes are played. The bytes are decoded without times all the same:
   * nothing is measured from a made-up clock. Default 11 ms.
   */
  untimedPeriodUs?: number;
}

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
 * chunks, so they are read by index when fed, never turned into objects up front. The index is
 * the one array a port adds (4 bytes a chunk): its part of one array for all ports (`portIndexes`).
 */
class PortChunks {
  readonly length: number;
  /** The capture's chunk number of each of this port's chunks. */
  readonly #index: Uint32Array;
  /** Next chunk to feed, and bytes of it already fed (per-byte-timed chunks go piece by piece). */
  next = 0;
  nextByte = 0;

  /** Without timing: this port's bytes up to the end of each chunk, for the paced clock. */
  readonly #bytesBefore: Float64Array | undefined;
  /** Whether the chunks' times never go back (as recorded): a seek then bisects for its chunk. */
  readonly #ordered: boolean;
  /** Whether the per-byte times inside each chunk never go back: a seek then bisects for its byte. */
  readonly #bytesOrdered: boolean;

  /**
   * @param index the capture's chunk number of each of this port's chunks, in order (`portIndexes`)
   * @param usPerByte without timing, the pace bytes are played at (µs a byte); NaN with timing
   */
  constructor(
    readonly capture: Capture,
    readonly port: number,
    index: Uint32Array,
    readonly usPerByte: number,
  ) {
    const n = index.length;
    this.#index = index;
    this.length = n;
    const { chunkEnds, chunkTimesUs, byteTimesUs: times } = capture;
    if (Number.isFinite(usPerByte)) {
      const before = new Float64Array(n);
      let total = 0;
      for (let k = 0; k < n; k++) {
        const i = index[k] ?? 0;
        total += (chunkEnds[i] ?? 0) - (i === 0 ? 0 : (chunkEnds[i - 1] ?? 0));
        before[k] = total;
      }
      this.#bytesBefore = before;
    }
    let ordered = true;
    if (this.#bytesBefore === undefined && times === undefined) {
      // Chunk times: in order for the capture (one pass for all ports), in order for each port; else
      // this port's are checked, read straight from the column (a day's capture has eleven million).
      if (!captureTimesInOrder(capture))
        for (let k = 1; k < n && ordered; k++)
          ordered = (chunkTimesUs[index[k] ?? 0] ?? Number.NaN) >= (chunkTimesUs[index[k - 1] ?? 0] ?? Number.NaN);
    } else {
      for (let k = 1; k < n && ordered; k++) ordered = this.atUs(k) >= this.atUs(k - 1);
    }
    this.#ordered = ordered;
    let bytesOrdered = true;
    for (let k = 0; k < n && times !== undefined && bytesOrdered; k++) {
      const i = this.#chunk(k);
      for (let j = this.#start(i) + 1; j < this.#end(i) && bytesOrdered; j++)
        bytesOrdered = (times[j] ?? Number.NaN) >= (times[j - 1] ?? Number.NaN);
    }
    this.#bytesOrdered = bytesOrdered;
  }

  /** The capture's chunk number of this port's chunk k. */
  #chunk(k: number): number {
    return this.#index[k] ?? 0;
  }

  /** Where the capture's chunk i starts and ends in its bytes. */
  #start(i: number): number {
    return i === 0 ? 0 : (this.capture.chunkEnds[i - 1] ?? 0);
  }

  #end(i: number): number {
    return this.capture.chunkEnds[i] ?? 0;
  }

  /** Arrival time of chunk k (µs): recorded, or on the paced clock without timing. */
  atUs(k: number): number {
    if (this.#bytesBefore !== undefined) return (this.#bytesBefore[k] ?? Number.NaN) * this.usPerByte;
    const i = this.#chunk(k);
    const times = this.capture.byteTimesUs;
    if (times !== undefined) return times[this.#end(i) - 1] ?? Number.NaN;
    return this.capture.chunkTimesUs[i] ?? Number.NaN;
  }

  /**
   * The first chunk that arrives at or after `timeUs` (`length` when none does), as a walk from
   * the first chunk finds it; found by bisection when the times never go back.
   */
  firstAtOrAfter(timeUs: number): number {
    if (!this.#ordered) {
      let k = 0;
      while (k < this.length && this.atUs(k) < timeUs) k++;
      return k;
    }
    let lo = 0;
    let hi = this.length;
    while (lo < hi) {
      const mid = (lo + hi) >>> 1;
      if (this.atUs(mid) < timeUs) lo = mid + 1;
      else hi = mid;
    }
    return lo;
  }

  /**
   * Puts the cursor on the first byte a walk from the start finds at or after `fromUs`: the
   * first chunk that arrives then and, in a chunk with per-byte times (a logic analyser's one
   * chunk per port), its first byte timed then, so that a seek in a long one feeds only its
   * history, not everything before it.
   */
  seekTo(fromUs: number): void {
    this.next = this.firstAtOrAfter(fromUs);
    this.nextByte = 0;
    const times = this.capture.byteTimesUs;
    if (times === undefined || this.done) return;
    const i = this.#chunk(this.next);
    const start = this.#start(i);
    const end = this.#end(i);
    let lo = start;
    if (this.#bytesOrdered) {
      let hi = end;
      while (lo < hi) {
        const mid = (lo + hi) >>> 1;
        if ((times[mid] ?? Number.NaN) < fromUs) lo = mid + 1;
        else hi = mid;
      }
    } else {
      while (lo < end && (times[lo] ?? Number.NaN) < fromUs) lo++;
    }
    this.nextByte = lo - start;
  }

  /** Puts the cursor on this port's first chunk at or after the capture's chunk `i` (a checkpoint's). */
  seekToChunk(i: number): void {
    const index = this.#index;
    let lo = 0;
    let hi = this.length;
    while (lo < hi) {
      const mid = (lo + hi) >>> 1;
      if ((index[mid] ?? 0) < i) lo = mid + 1;
      else hi = mid;
    }
    this.next = lo;
    this.nextByte = 0;
  }

  get(k: number): Chunk {
    const i = this.#chunk(k);
    const c = this.capture;
    const start = this.#start(i);
    const end = this.#end(i);
    return { bytes: c.bytes.subarray(start, end), byteTimes: c.byteTimesUs?.subarray(start, end), atUs: this.atUs(k) };
  }

  /** Without timing: the port's bytes before chunk k. */
  bytesBeforeChunk(k: number): number {
    return k === 0 || this.#bytesBefore === undefined ? 0 : (this.#bytesBefore[k - 1] ?? 0);
  }

  /** Whether chunk k's bytes are decoded with times (recorded ones); not on the paced clock. */
  get timed(): boolean {
    return this.#bytesBefore === undefined;
  }

  get done(): boolean {
    return this.next >= this.length;
  }

  /**
   * The earliest time a byte not fed yet can carry, µs (Infinity when all are fed): its own
   * time, or for a chunk-timed chunk, the chunk's arrival less its bytes at line rate, which
   * is as early as the decoder dates a frame in it.
   */
  nextByteUs(): number {
    if (this.done) return Number.POSITIVE_INFINITY;
    const i = this.#chunk(this.next);
    const c = this.capture;
    const start = this.#start(i);
    if (c.byteTimesUs !== undefined) return c.byteTimesUs[start + this.nextByte] ?? Number.POSITIVE_INFINITY;
    if (!this.timed) return (this.bytesBeforeChunk(this.next) + this.nextByte + 1) * this.usPerByte;
    return this.atUs(this.next) - (this.#end(i) - start - 1) * BYTE_TIME_US;
  }
}

/**
 * Each of `ports`' chunk numbers in the capture, in order: views of one array of the chunks sorted
 * by port (a counting sort on the capture's count of chunks by port), one pass over the chunks.
 */
function portIndexes(capture: Capture, ports: readonly number[]): Uint32Array[] {
  const counts = captureChunksByPort(capture);
  const chunkPorts = capture.chunkPorts;
  const at = new Uint32Array(256);
  for (let p = 1; p < 256; p++) at[p] = (at[p - 1] ?? 0) + (counts[p - 1] ?? 0);
  const starts = at.slice();
  const all = new Uint32Array(chunkPorts.length);
  for (let i = 0; i < chunkPorts.length; i++) {
    const p = chunkPorts[i] ?? 0;
    const k = at[p] ?? 0;
    all[k] = i;
    at[p] = k + 1;
  }
  return ports.map((p) => all.subarray(starts[p] ?? 0, (starts[p] ?? 0) + (counts[p] ?? 0)));
}

export type ReplaySink = (port: number, bytes: Uint8Array, time: number | Float64Array | undefined, atUs: number) => void;

const TICK_MS = 10;
/** Decode for at most this long per tick, then let messages through. */
const SLICE_MS = 12;
/** The most wall time one tick may move the replay clock by. */
const MAX_STEP_MS = 100;
/**
 * A seek without a checkpoint (fresh decodes) replays this much before the target so the graphs
 * and failsafe state have history.
 */
const SEEK_HISTORY_US = 10 * 60e6;

export class ReplaySource {
  readonly ports: readonly number[];
  readonly #chunks: PortChunks[];
  /** The capture's first and last recorded time (`captureSpan`), or the paced clock's span without timing. */
  readonly startUs: number;
  readonly endUs: number;
  /** False for a capture without timing: its clock is the receiver's pace, not a recording. */
  readonly recordedTiming: boolean;
  readonly #clock: ReplayClock;
  #clockUs: number;
  #wallMs = 0;
  #speed = 1;
  #playing = false;
  #ended = false;
  #lastFedUs = NaN;
  #timer: unknown;

  /**
   * @param sink gets each piece of a port's bytes with its time argument and arrival time
   * @param onTick after each tick that moved the clock (the worker sends batches)
   * @param onEnd when the clock has reached the end and every port's last chunk has been fed
   */
  constructor(
    readonly capture: Capture,
    readonly sink: ReplaySink,
    readonly onTick: (clockUs: number) => void,
    readonly onEnd: () => void,
    options: ReplayOptions = {},
  ) {
    this.#clock = options.clock ?? BROWSER_CLOCK;
    this.ports = capturePorts(capture);
    const span = captureSpan(capture);
    this.recordedTiming = Number.isFinite(span.startUs);
    const usPerByte = this.recordedTiming ? NaN : (options.untimedPeriodUs ?? FRAME_PERIOD_11MS_US) / FRAME_SIZE;
    const indexes = portIndexes(capture, this.ports);
    this.#chunks = this.ports.map((p, k) => new PortChunks(capture, p, indexes[k] ?? new Uint32Array(0), usPerByte));
    if (this.recordedTiming) {
      this.startUs = span.startUs;
      this.endUs = span.endUs;
    } else {
      let end = 0;
      for (const c of this.#chunks) if (c.length > 0) end = Math.max(end, c.atUs(c.length - 1));
      this.startUs = 0;
      this.endUs = end;
    }
    this.#clockUs = this.startUs;
  }

  /** Whether there is a timeline to play and seek on. */
  get timed(): boolean {
    return this.endUs > this.startUs;
  }

  /**
   * The time a port's link is judged at (hold, failsafe): the replay clock, but never past the
   * next byte not fed yet, so that a frame still to come is never taken for silence. This keeps
   * every state the same at 1×, 4× and full speed. NaN without recorded timing.
   */
  linkNowUs(port: number): number {
    if (!this.recordedTiming) return NaN;
    const c = this.#chunks[this.ports.indexOf(port)];
    return c === undefined ? this.#clockUs : Math.min(this.#clockUs, c.nextByteUs());
  }

  /** Whether the replay has reached its end. */
  get ended(): boolean {
    return this.#ended;
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
    if (this.#playing || this.#ended) return;
    this.#playing = true;
    this.#wallMs = this.#clock.now();
    this.#timer = this.#clock.every(TICK_MS, () => this.#tick());
  }

  pause(): void {
    this.#playing = false;
    if (this.#timer !== undefined) this.#clock.cancel(this.#timer);
    this.#timer = undefined;
  }

  setSpeed(speed: number): void {
    this.#speed = speed;
    this.#wallMs = this.#clock.now();
  }

  /**
   * Moves to `timeUs`: the caller resets its decode state first, or restores it to a checkpoint
   * taken before the capture's chunk `fromChunk`; the chunks from there (or, without one, from
   * a while before the target) are fed at once so history is there, then playback goes on from
   * the target.
   */
  seek(timeUs: number, fromChunk?: number): void {
    const target = Math.min(Math.max(timeUs, this.startUs), this.endUs);
    this.#lastFedUs = NaN;
    this.#ended = false;
    const from = target - SEEK_HISTORY_US;
    for (const c of this.#chunks) {
      if (fromChunk === undefined) c.seekTo(from);
      else c.seekToChunk(fromChunk);
    }
    const done = this.#feedUntil(target, Infinity);
    this.#clockUs = target;
    this.#wallMs = this.#clock.now();
    if (done && target >= this.endUs) {
      this.#finish();
      return;
    }
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
    const started = this.#clock.now();
    for (const c of this.#chunks) {
      while (c.next < c.length) {
        if (budgetMs !== Infinity && this.#clock.now() - started > budgetMs) return false;
        const chunk = c.get(c.next);
        if (!c.timed) {
          // The paced clock: byte j of the port is due at (j + 1) × usPerByte; fed untimed.
          const first = c.bytesBeforeChunk(c.next);
          const due = Math.min(chunk.bytes.length, Math.floor(clockUs / c.usPerByte + 1e-9) - first);
          if (due > c.nextByte) {
            this.#feed(c.port, chunk.bytes.subarray(c.nextByte, due), undefined, (first + due) * c.usPerByte);
            c.nextByte = due;
          }
          if (c.nextByte === chunk.bytes.length) {
            c.next++;
            c.nextByte = 0;
            continue;
          }
          break;
        }
        if (chunk.byteTimes === undefined) {
          if (chunk.atUs > clockUs) break;
          // Without recorded timing the bytes go in untimed: the pace is not a measurement.
          this.#feed(c.port, chunk.bytes, c.timed && !Number.isNaN(chunk.atUs) ? chunk.atUs : undefined, chunk.atUs);
          c.next++;
          continue;
        }
        const times = chunk.byteTimes;
        const limit = Math.min(times.length, c.nextByte + 4096);
        let end = c.nextByte;
        while (end < limit && !((times[end] ?? Number.POSITIVE_INFINITY) > clockUs)) end++;
        if (end > c.nextByte)
          this.#feed(c.port, chunk.bytes.subarray(c.nextByte, end), times.subarray(c.nextByte, end), times[end - 1] ?? Number.NaN);
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
    const nowMs = this.#clock.now();
    let done: boolean;
    if (this.#speed === 0) {
      // As fast as possible, in slices so the worker stays responsive; the clock follows the data.
      done = this.#feedUntil(Infinity, SLICE_MS);
      if (Number.isFinite(this.#lastFedUs)) this.#clockUs = Math.min(this.endUs, Math.max(this.#clockUs, this.#lastFedUs));
    } else {
      // A stall (a long task, a background tab) must not jump the clock past silent data: that
      // would show a hold or failsafe that is not in the capture. Nor does it run past the end.
      this.#clockUs = Math.min(this.endUs, this.#clockUs + Math.min(nowMs - this.#wallMs, MAX_STEP_MS) * 1000 * this.#speed);
      done = this.#feedUntil(this.#clockUs, SLICE_MS) && this.#clockUs >= this.endUs;
    }
    this.#wallMs = nowMs;
    if (done) {
      this.#finish();
      return;
    }
    this.onTick(this.#clockUs);
  }

  /** The end: the clock stops at the capture's last recorded time, never past it. */
  #finish(): void {
    this.#clockUs = this.endUs;
    this.#ended = true;
    this.pause();
    this.onTick(this.#clockUs);
    this.onEnd();
  }
}
