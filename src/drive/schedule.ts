/**
 * The frame writer's schedule: which write to make now, so that a flight controller reads every
 * frame as one. Flight stacks find a frame's edges by the silence before it (Betaflight and
 * iNav drop a frame after a gap over 5 ms, ArduPilot re-syncs on a gap of 5 ms or more, PX4
 * needs a gap to sync): two frames that leave a few ms apart merge into one broken frame. So a
 * frame leaves only after `minSilenceUs` of silence, and a writer that woke late sends the
 * newest frame due, never a backlog: the frames it skipped are counted, not sent late. Noise
 * bytes a scenario puts between frames are sent on time or not at all, and do not count in the
 * silence (noise right before a frame is what such a scenario tests).
 */
import { BYTE_TIME_US } from '../decoder/spec.js';
import type { DrivePlayer, DriveWrite } from './player.js';

/**
 * The silence a frame always has before it, µs: the 5 ms every flight stack ends a frame on, and
 * 3 ms for the way from a write to the wire (a browser's serial service and the OS add that
 * much jitter, measured through Chromium and a pty). An 11 ms frame slot leaves 9.6 ms.
 */
export const MIN_SILENCE_US = 8_000;
/** A noise write later than this is left out: it belongs between two frames, not on one. */
const NOISE_LATE_US = 1_000;
/** How far ahead of now the player is asked for writes: a period's worth, so the next write's time is known before it is due, µs. */
const LOOK_AHEAD_US = 25_000;
/** A writer this far behind skips the writes due in steps of this, µs. */
const SKIP_STEP_US = 1_000_000;
/** Frame intervals are counted in bins of 0.1 ms up to 200 ms; longer ones in the last bin. */
const BIN_US = 100;
const BINS = 2001;

/** How the writes went: counts, and the intervals between the starts of frames written. */
export interface DriveTimingStats {
  /** Frames written. */
  frames: number;
  /** Frames due while a later one was too: never written (the flight controller saw a longer gap). */
  skipped: number;
  /** Frames written later than due to keep the silence before them. */
  delayed: number;
  /** Noise writes made and left out (too late to fall between frames). */
  noise: number;
  noiseDropped: number;
  /** The shortest silence before a frame written, µs (Infinity before the second). */
  minSilenceUs: number;
  /** Interval between frame starts, µs: median, 1st and 99th percentiles, min and max (null before two frames). */
  interval: { p1: number; p50: number; p99: number; min: number; max: number } | null;
}

/**
 * Hands out the write to make at each moment (`take`) and when to look again (`nextDueUs`),
 * on the player's clock. The times are the caller's (a worker's clock), never read here.
 */
export class WriteSchedule {
  readonly #player: DrivePlayer;
  readonly #minSilenceUs: number;
  readonly #byteTimeUs: number;
  readonly #pending: DriveWrite[] = [];
  #lastStartUs = Number.NaN;
  #lastEndUs = Number.NEGATIVE_INFINITY;
  readonly #bins = new Uint32Array(BINS);
  #frames = 0;
  #skipped = 0;
  #delayed = 0;
  #noise = 0;
  #noiseDropped = 0;
  #minSilence = Number.POSITIVE_INFINITY;
  #minInterval = Number.POSITIVE_INFINITY;
  #maxInterval = 0;
  /** The player has handed out its writes up to here, µs. */
  #filledUs = 0;

  constructor(player: DrivePlayer, options: { minSilenceUs?: number; byteTimeUs?: number } = {}) {
    this.#player = player;
    this.#minSilenceUs = options.minSilenceUs ?? MIN_SILENCE_US;
    this.#byteTimeUs = options.byteTimeUs ?? BYTE_TIME_US;
  }

  /**
   * When the next write can be made, or when to look again (a silence of the scenario: nothing
   * to write yet), µs; NaN once the scenario has ended and all is written.
   */
  nextDueUs(): number {
    if (this.#pending.length === 0) this.#fill(Math.max(this.#filledUs, Number.isFinite(this.#lastEndUs) ? this.#lastEndUs : 0));
    const next = this.#pending[0];
    if (next === undefined) return this.#player.done ? Number.NaN : this.#filledUs;
    return next.frame !== null ? Math.max(next.atUs, this.#lastEndUs + this.#minSilenceUs) : next.atUs;
  }

  /** The write to make at `nowUs`, or null (nothing due, or the silence before a frame not over yet). */
  take(nowUs: number): DriveWrite | null {
    this.#fill(nowUs);
    const pending = this.#pending;
    // Of the writes due, the newest frame; older frames are skipped, noise is sent on time or not at all.
    let pick = -1;
    for (let i = 0; i < pending.length && (pending[i] as DriveWrite).atUs <= nowUs; i++) pick = i;
    if (pick < 0) return null;
    let lastFrame = -1;
    for (let i = 0; i <= pick; i++) if ((pending[i] as DriveWrite).frame !== null) lastFrame = i;
    if (lastFrame < 0) {
      // Only noise due: the oldest, if still between frames.
      const w = pending.shift() as DriveWrite;
      if (nowUs - w.atUs > NOISE_LATE_US || nowUs < this.#lastEndUs) {
        this.#noiseDropped++;
        return null;
      }
      // Noise does not move the frames' silence: noise close before a frame is what the scenario tests.
      this.#noise++;
      return w;
    }
    if (nowUs < this.#lastEndUs + this.#minSilenceUs) return null;
    for (let i = 0; i < lastFrame; i++) {
      if ((pending[i] as DriveWrite).frame !== null) this.#skipped++;
      else this.#noiseDropped++;
    }
    const w = pending.splice(0, lastFrame + 1)[lastFrame] as DriveWrite;
    if (nowUs - w.atUs > this.#minSilenceUs / 2) this.#delayed++;
    this.#wrote(nowUs, w.bytes.length);
    return w;
  }

  /** The figures so far. */
  get stats(): DriveTimingStats {
    const n = this.#frames - 1;
    let interval: DriveTimingStats['interval'] = null;
    if (n > 0) {
      const at = (q: number): number => {
        const want = Math.max(1, Math.ceil(q * n));
        let seen = 0;
        for (let b = 0; b < BINS; b++) {
          seen += this.#bins[b] as number;
          if (seen >= want) return (b + 0.5) * BIN_US;
        }
        return this.#maxInterval;
      };
      interval = { p1: at(0.01), p50: at(0.5), p99: at(0.99), min: this.#minInterval, max: this.#maxInterval };
    }
    return {
      frames: this.#frames,
      skipped: this.#skipped,
      delayed: this.#delayed,
      noise: this.#noise,
      noiseDropped: this.#noiseDropped,
      minSilenceUs: this.#minSilence,
      interval,
    };
  }

  #fill(nowUs: number): void {
    if (this.#pending.length > 0 && (this.#pending[this.#pending.length - 1] as DriveWrite).atUs > nowUs) return;
    // A writer that slept long (a machine suspended) skips what fell due meanwhile a second at a
    // time, so that the frames it will never send are not all held at once.
    while (this.#filledUs < nowUs - SKIP_STEP_US) {
      this.#filledUs += SKIP_STEP_US;
      for (const w of this.#player.writesUntil(this.#filledUs)) if (w.frame !== null) this.#skipped++;
    }
    this.#filledUs = Math.max(this.#filledUs, nowUs + LOOK_AHEAD_US);
    for (const w of this.#player.writesUntil(this.#filledUs)) this.#pending.push(w);
  }

  #wrote(nowUs: number, length: number): void {
    if (!Number.isNaN(this.#lastStartUs)) {
      const gap = nowUs - this.#lastStartUs;
      const bin = Math.min(BINS - 1, Math.floor(gap / BIN_US));
      this.#bins[bin] = (this.#bins[bin] ?? 0) + 1;
      if (gap < this.#minInterval) this.#minInterval = gap;
      if (gap > this.#maxInterval) this.#maxInterval = gap;
      const silence = nowUs - this.#lastEndUs;
      if (silence < this.#minSilence) this.#minSilence = silence;
    }
    this.#frames++;
    this.#lastStartUs = nowUs;
    this.#lastEndUs = nowUs + length * this.#byteTimeUs;
  }
}
