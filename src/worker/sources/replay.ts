/**
 * Replay: a capture file played back through exactly the live path, chunk by chunk at the
 * recorded times, at 1×, 4× or as fast as possible, with pause and seek. A capture may hold
 * several ports (remotes) with one common clock: each port feeds its own decode, and all of
 * them advance with the one replay clock. A capture read whole plays from memory; a .sscap
 * replayed from its File plays a window of its records at a time (capture-file.ts), the next
 * one read while this one plays, and the clock never runs past the records read.
 */
import { FRAME_PERIOD_11MS_US, FRAME_SIZE } from '../../decoder/spec.js';
import { capturePortIndex, capturePorts } from '../../capture/facts.js';
import type { Capture } from '../../capture/model.js';
import { captureSpan } from '../../report/capture-span.js';
import type { CaptureFile, CaptureWindow } from '../replay/capture-file.js';
import { BROWSER_CLOCK, type Clock } from '../host.js';
import { PortChunks } from './port-chunks.js';

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
  /** A port's recorded stop ("device lost" at `atUs`), told before the first byte recorded after it. */
  onStop?: (port: number, atUs: number) => void;
  /** A window of a file's records starts to play (its recorded events go to the doctor). */
  onWindow?: (window: CaptureWindow) => void;
  /** The file could not be read on (`error`): the replay ends at `lastUs`, the last record read (`playsToUs`). */
  onReadFailed?: (error: unknown, lastUs: number) => void;
}

/**
 * Gets a piece of a port's bytes: its time argument for the decoder, its recorded time, and the
 * wall time it was fed at (the replay's clock, ms).
 */
export type ReplaySink = (port: number, bytes: Uint8Array, time: number | Float64Array | undefined, atUs: number, fedAtMs: number) => void;

const TICK_MS = 10;
/** Decode for at most this long per tick, then let messages through. */
const SLICE_MS = 12;
/**
 * The clock is read once every this many chunks fed, not for each: a seek feeds a minute or two
 * of every port at once (7 500 to 15 000 chunks of the day capture's two), and a read costs
 * 0.3-0.5 µs in a Chromium worker (20 000 reads: 6-10 ms).
 */
const CLOCK_EVERY_CHUNKS = 64;
/** The most wall time one tick may move the replay clock by. */
const MAX_STEP_MS = 100;
/**
 * A seek without a checkpoint (fresh decodes) replays this much before the target so the graphs
 * and failsafe state have history.
 */
const SEEK_HISTORY_US = 10 * 60e6;

/** What a replay plays: a capture read whole, or a .sscap read from its File a window at a time. */
export type ReplayData = { capture: Capture } | { file: CaptureFile; ports: readonly number[] };

/** Where a seek starts: a checkpoint's chunk of a capture read whole, or its record's file offset. */
export interface ReplayPosition {
  chunk: number;
  offset: number;
  /** The file offset the seek will feed to (a checkpoint after its target): read at once. */
  readTo?: number | undefined;
}

export class ReplaySource {
  readonly ports: readonly number[];
  /** The records being played (a capture read whole is one window), and each port's chunks in it. */
  #window: CaptureWindow;
  #chunks: PortChunks[];
  /** The last time recorded in the window: with the next not read yet, nothing after it is known. */
  #windowEndUs: number;
  /** The window after this one: read, being read, or not asked for. */
  #next: CaptureWindow | Promise<CaptureWindow> | null = null;
  /** A seek is reading its windows: nothing is fed and no link judged until it has. */
  #seeking = false;
  /** Counts seeks (and the stop): a seek whose reads settle after a later one began lets it be. */
  #seeks = 0;
  readonly #file: CaptureFile | null;
  /** The capture's first and last recorded time (`captureSpan`), or the paced clock's span without timing. */
  readonly startUs: number;
  readonly endUs: number;
  /** False for a capture without timing: its clock is the receiver's pace, not a recording. */
  readonly recordedTiming: boolean;
  readonly #usPerByte: number;
  readonly #clock: ReplayClock;
  readonly #onStop: (port: number, atUs: number) => void;
  readonly #onWindow: (window: CaptureWindow) => void;
  readonly #onReadFailed: (error: unknown, lastUs: number) => void;
  /** Why the file could not be read on, and the last record read (null: it reads). */
  #readFailure: { error: unknown; lastUs: number } | null = null;
  #clockUs: number;
  #wallMs = 0;
  #speed = 1;
  #playing = false;
  #ended = false;
  #lastFedUs = NaN;
  /** When the chunks being fed were fed: the clock, read once every CLOCK_EVERY_CHUNKS. */
  #fedAtMs = 0;
  #timer: unknown;

  /**
   * @param sink gets each piece of a port's bytes with its time argument and arrival time
   * @param onTick after each tick that moved the clock (the worker sends batches)
   * @param onEnd when the clock has reached the end and every port's last chunk has been fed
   */
  constructor(
    data: ReplayData,
    readonly sink: ReplaySink,
    readonly onTick: (clockUs: number) => void,
    readonly onEnd: () => void,
    options: ReplayOptions = {},
  ) {
    this.#clock = options.clock ?? BROWSER_CLOCK;
    this.#onStop = options.onStop ?? (() => {});
    this.#onWindow = options.onWindow ?? (() => {});
    this.#onReadFailed = options.onReadFailed ?? (() => {});
    if ('capture' in data) {
      const { capture } = data;
      this.#file = null;
      this.ports = capturePorts(capture);
      const span = captureSpan(capture);
      this.recordedTiming = Number.isFinite(span.startUs);
      this.#usPerByte = this.recordedTiming ? NaN : (options.untimedPeriodUs ?? FRAME_PERIOD_11MS_US) / FRAME_SIZE;
      this.#window = { capture, offset: 0, end: 0, last: true };
      this.#chunks = this.#chunksOf(capture);
      if (this.recordedTiming) {
        this.startUs = span.startUs;
        this.endUs = span.endUs;
      } else {
        let end = 0;
        for (const c of this.#chunks) if (c.length > 0) end = Math.max(end, c.atUs(c.length - 1));
        this.startUs = 0;
        this.endUs = end;
      }
    } else {
      const { file } = data;
      this.#file = file;
      this.ports = data.ports;
      this.recordedTiming = true;
      this.#usPerByte = NaN;
      this.startUs = file.startUs;
      this.endUs = file.endUs;
      // The file's first records, read at open, until the first window asked for replaces them.
      this.#window = { capture: file.head, offset: file.recordsFrom, end: file.recordsFrom, last: false };
      this.#chunks = this.#chunksOf(file.head);
      this.#chunks.forEach((c) => {
        c.next = c.length;
      });
    }
    this.#windowEndUs = captureSpan(this.#window.capture).endUs;
    this.#clockUs = this.startUs;
  }

  /**
   * Where the replay ends, and every link is judged: the capture's last recorded time, or the
   * last record read where the file could not be read on (what follows is unknown, not silence).
   */
  get playsToUs(): number {
    return this.#readFailure?.lastUs ?? this.endUs;
  }

  /** The file could not be read on (`ReplayOptions.onReadFailed`): why, and the last record read; null while it reads. */
  get readFailure(): { error: unknown; lastUs: number } | null {
    return this.#readFailure;
  }

  #chunksOf(capture: Capture): PortChunks[] {
    const index = capturePortIndex(capture);
    return this.ports.map((p) => new PortChunks(capture, p, index[p] ?? new Uint32Array(0), this.#usPerByte));
  }

  /** Plays `window` from its first chunk on (a seek's, or the one after the last). */
  #enter(window: CaptureWindow): void {
    this.#window = window;
    this.#chunks = this.#chunksOf(window.capture);
    const span = captureSpan(window.capture);
    this.#windowEndUs = Number.isFinite(span.endUs) ? span.endUs : this.#windowEndUs;
    this.#next = null;
    // A window read: the file reads again (after a failure, a seek read it).
    this.#readFailure = null;
    this.#onWindow(window);
    this.#readAhead();
  }

  /** The next window is read while this one plays. */
  #readAhead(): void {
    const file = this.#file;
    if (file === null || this.#window.last || this.#next !== null) return;
    const reading = file.window(this.#window.end);
    this.#next = reading;
    reading.then(
      (w) => {
        if (this.#next === reading) this.#next = w;
      },
      (error: unknown) => {
        // The file could not be read on: the replay ends with the window playing, the last read.
        if (this.#next !== reading) return;
        this.#next = null;
        this.#window = { ...this.#window, last: true };
        const lastUs = Math.max(this.startUs, Math.min(this.endUs, this.#windowEndUs));
        this.#readFailure = { error, lastUs };
        // A tick (or a seek) may have moved the clock past the records read: nothing is judged there.
        this.#clockUs = Math.min(this.#clockUs, lastUs);
        this.#onReadFailed(error, lastUs);
      },
    );
  }

  /** Whether there is a timeline to play and seek on. */
  get timed(): boolean {
    return this.endUs > this.startUs;
  }

  /**
   * The time a port's link is judged at (hold, failsafe): the replay clock, but never past the
   * next byte not fed yet, so that a frame still to come is never taken for silence. This keeps
   * every state the same at 1×, 4× and full speed. NaN (not judged now) without recorded timing,
   * while a seek reads its first window, and for a port whose next byte lies in a window not
   * entered yet: when it is, is not known.
   */
  linkNowUs(port: number): number {
    if (!this.recordedTiming || this.#seeking) return NaN;
    const c = this.#chunks[this.ports.indexOf(port)];
    if (c === undefined) return this.#clockUs;
    if (c.done && !this.#window.last) return Number.NaN;
    return Math.min(this.#clockUs, c.nextByteUs());
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
   * taken at `from`; the chunks from there (or, without one, from a while before the target)
   * are fed at once so history is there, then playback goes on from the target. Settles once
   * they are (a file's windows are read first).
   */
  async seek(timeUs: number, from?: ReplayPosition): Promise<void> {
    const target = Math.min(Math.max(timeUs, this.startUs), this.endUs);
    const history = target - SEEK_HISTORY_US;
    this.#lastFedUs = NaN;
    this.#ended = false;
    this.#clockUs = target;
    const file = this.#file;
    if (file === null) {
      for (const c of this.#chunks) {
        if (from === undefined) c.seekTo(history);
        else c.seekToChunk(from.chunk);
      }
    } else {
      const seeking = ++this.#seeks;
      this.#seeking = true;
      try {
        const offset = from?.offset ?? (await file.offsetBefore(history));
        const window = await file.window(offset, (from?.readTo ?? Number.NaN) - offset);
        // A later seek has begun: it plays, not this one.
        if (seeking !== this.#seeks) return;
        this.#next = null;
        this.#enter(window);
        if (from === undefined) for (const c of this.#chunks) c.seekTo(history);
        while (!this.#feedUntil(target, Infinity) && this.#waitingForWindow()) {
          await this.#windowRead();
          if (seeking !== this.#seeks) return;
        }
      } finally {
        if (seeking === this.#seeks) this.#seeking = false;
      }
    }
    const done = this.#feedUntil(target, Infinity);
    this.#wallMs = this.#clock.now();
    if (done && target >= this.playsToUs) {
      this.#finish();
      return;
    }
    this.onTick(this.#clockUs);
  }

  /** Waits for the next window's read; one that cannot be read ends the replay at the last record read (#readAhead). */
  async #windowRead(): Promise<void> {
    if (this.#next instanceof Promise) await this.#next.catch(() => undefined);
  }

  /** Every chunk of the window is fed and the next is still being read. */
  #waitingForWindow(): boolean {
    return this.#next instanceof Promise && this.#chunks.every((c) => c.done);
  }

  stop(): void {
    this.pause();
    this.#seeks++;
  }

  #feed(c: PortChunks, bytes: Uint8Array, time: number | Float64Array | undefined, atUs: number): void {
    const port = c.port;
    if (c.nextByte === 0) for (let t = c.takeStop(c.next); t !== undefined; t = c.takeStop(c.next)) this.#onStop(port, t);
    if (Number.isFinite(atUs) && !(atUs <= this.#lastFedUs)) this.#lastFedUs = atUs;
    this.sink(port, bytes, time, atUs, this.#fedAtMs);
  }

  /**
   * Feeds every byte whose time is at or before `clockUs`, port by port (a chunk-timed chunk
   * whole once its arrival has passed; a per-byte-timed one range by range), window after window
   * as they have been read, for at most `budgetMs` of wall time. Returns whether everything has
   * been fed.
   */
  #feedUntil(clockUs: number, budgetMs: number): boolean {
    const started = this.#clock.now();
    this.#fedAtMs = started;
    for (;;) {
      if (!this.#feedWindow(clockUs, budgetMs, started)) return false;
      if (this.#window.last) return true;
      const next = this.#next;
      if (next === null || next instanceof Promise) {
        this.#readAhead();
        return false;
      }
      // The window's stops after each port's last chunk in it, then the next window.
      for (const c of this.#chunks) for (let t = c.takeStop(c.length); t !== undefined; t = c.takeStop(c.length)) this.#onStop(c.port, t);
      this.#enter(next);
    }
  }

  /** `#feedUntil` in the window: whether every chunk of it has been fed. */
  #feedWindow(clockUs: number, budgetMs: number, started: number): boolean {
    let unclocked = 0;
    for (const c of this.#chunks) {
      // A stop recorded before the port's next chunk is told once the clock has reached it, not
      // only when that chunk comes (the adapter was away meanwhile: no silence of the link's).
      if (c.nextByte === 0)
        for (let t = c.takeStop(c.next, clockUs); t !== undefined; t = c.takeStop(c.next, clockUs)) this.#onStop(c.port, t);
      while (c.next < c.length) {
        if (++unclocked === CLOCK_EVERY_CHUNKS) {
          unclocked = 0;
          this.#fedAtMs = this.#clock.now();
          if (budgetMs !== Infinity && this.#fedAtMs - started > budgetMs) return false;
        }
        const chunk = c.get(c.next);
        if (!c.timed) {
          // The paced clock: byte j of the port is due at (j + 1) × usPerByte; fed untimed.
          const first = c.bytesBeforeChunk(c.next);
          const due = Math.min(chunk.bytes.length, Math.floor(clockUs / c.usPerByte + 1e-9) - first);
          if (due > c.nextByte) {
            this.#feed(c, chunk.bytes.subarray(c.nextByte, due), undefined, (first + due) * c.usPerByte);
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
          this.#feed(c, chunk.bytes, c.timed && !Number.isNaN(chunk.atUs) ? chunk.atUs : undefined, chunk.atUs);
          c.next++;
          continue;
        }
        const times = chunk.byteTimes;
        const limit = Math.min(times.length, c.nextByte + 4096);
        let end = c.nextByte;
        while (end < limit && !((times[end] ?? Number.POSITIVE_INFINITY) > clockUs)) end++;
        if (end > c.nextByte)
          this.#feed(c, chunk.bytes.subarray(c.nextByte, end), times.subarray(c.nextByte, end), times[end - 1] ?? Number.NaN);
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
    if (this.#seeking) return;
    const nowMs = this.#clock.now();
    let done: boolean;
    if (this.#speed === 0) {
      // As fast as possible, in slices so the worker stays responsive; the clock follows the data.
      done = this.#feedUntil(Infinity, SLICE_MS);
      if (Number.isFinite(this.#lastFedUs)) this.#clockUs = Math.min(this.playsToUs, Math.max(this.#clockUs, this.#lastFedUs));
    } else {
      // A stall (a long task, a background tab) must not jump the clock past silent data: that
      // would show a hold or failsafe that is not in the capture. Nor does it run past the end,
      // nor past the records read (the next window not read yet).
      const readUntil = this.#waitingForWindow() ? Math.max(this.#clockUs, this.#windowEndUs) : this.playsToUs;
      const step = Math.min(nowMs - this.#wallMs, MAX_STEP_MS) * 1000 * this.#speed;
      this.#clockUs = Math.min(this.playsToUs, readUntil, this.#clockUs + step);
      done = this.#feedUntil(this.#clockUs, SLICE_MS) && this.#clockUs >= this.playsToUs;
    }
    this.#wallMs = nowMs;
    if (done) {
      this.#finish();
      return;
    }
    this.onTick(this.#clockUs);
  }

  /** The end: the clock stops at the capture's last recorded time (`playsToUs`), never past it. */
  #finish(): void {
    for (const c of this.#chunks) for (let t = c.takeStop(c.length); t !== undefined; t = c.takeStop(c.length)) this.#onStop(c.port, t);
    this.#clockUs = this.playsToUs;
    this.#ended = true;
    this.pause();
    this.onTick(this.#clockUs);
    this.onEnd();
  }
}
