/**
 * Link health from decoded frames: fades, frame period, missed frames, and the failsafe state
 * machine of spec §7.1 (live → hold last values → failsafe after one second without a frame →
 * live again on the next frame). Time is always the caller's: `frame()` uses the frame's own
 * time and `update(now)` advances the clock between frames; nothing here reads a clock.
 */
import { FAILSAFE_TIMEOUT_US, FRAME_PERIOD_11MS_US, FRAME_PERIOD_22MS_US, systemInfo } from './spec.js';
import type { DecodedFrame } from './types.js';

export type LinkState = 'waiting' | 'live' | 'hold' | 'failsafe';

/** A stretch without frames. `endUs` is null while it lasts. */
export interface LinkEpisode {
  /** 0, 1, 2, … in the order the episodes began (stays with an episode when older ones are dropped). */
  id: number;
  kind: 'hold' | 'failsafe';
  /** When the hold (last frame + hold threshold) or the failsafe (last frame + 1 s) began, µs. */
  startUs: number;
  endUs: number | null;
  /** Time of the last frame before the gap, µs. */
  lastFrameUs: number;
}

export interface LinkOptions {
  /**
   * Gap after the last frame before the link counts as "hold", µs. Default: 2.5 frame periods,
   * at least 40 ms, so that USB adapters that deliver bytes in 16 ms batches do not flicker.
   */
  holdAfterUs?: number;
  /** Gap before failsafe, µs. Default 1 s (§7.1). */
  failsafeAfterUs?: number;
  /**
   * Episodes kept in `episodes` (the oldest go first); the counts in `stats` keep counting.
   * Default: all of them. A live view that runs for days sets a bound.
   */
  maxEpisodes?: number;
  /**
   * How late a frame may arrive from timing jitter alone, µs (16 ms for an FTDI adapter's
   * latency timer, 0 for a logic analyser). Gaps shorter than 1.5 periods plus this do not
   * count as missed frames. Default 0.
   */
  jitterUs?: number;
}

export interface LinkStats {
  frames: number;
  /** Sum of the receiver's fade deltas (frames it reported missing). */
  fades: number;
  /** Frames missing by the clock: gaps longer than a period, in periods. */
  missedFrames: number;
  /** Hold episodes (each failsafe began as a hold). */
  holds: number;
  failsafes: number;
  /** Measured frame period over the last 32 frames without a gap, µs; NaN until known. */
  periodUs: number;
  /** 11000 or 22000: the system byte's period, else the measured one rounded to the nearer. */
  nominalPeriodUs: number;
  /** Fades per second over the last ~512 frames. */
  fadeRate: number;
  /** Longest gap between two frames, µs. */
  longestGapUs: number;
  /** Last RSSI (dBm) and lowest seen, NaN without RSSI. */
  rssi: number;
  minRssi: number;
}

const PERIOD_WINDOW = 33;
const RATE_WINDOW = 512;
const MIN_HOLD_US = 40_000;

export class LinkMonitor {
  readonly #holdOption: number | undefined;
  readonly #failsafeAfterUs: number;
  readonly #jitterUs: number;
  #state: LinkState = 'waiting';
  #lastUs = NaN;
  #systemPeriod = NaN;
  readonly #periodTimes = new Float64Array(PERIOD_WINDOW);
  #periodCount = 0;
  readonly #rateTimes = new Float64Array(RATE_WINDOW);
  readonly #rateFades = new Float64Array(RATE_WINDOW);
  #rateCount = 0;
  #rateNext = 0;
  readonly #episodes: LinkEpisode[] = [];
  readonly #maxEpisodes: number;
  #nextEpisode = 0;
  #open: LinkEpisode | null = null;
  readonly #stats: LinkStats = {
    frames: 0, fades: 0, missedFrames: 0, holds: 0, failsafes: 0, periodUs: NaN,
    nominalPeriodUs: NaN, fadeRate: 0, longestGapUs: 0, rssi: NaN, minRssi: NaN,
  };

  /** @throws {TypeError} when a duration is not a positive finite number. */
  constructor(options: LinkOptions = {}) {
    for (const key of ['holdAfterUs', 'failsafeAfterUs', 'jitterUs', 'maxEpisodes'] as const) {
      const v = options[key];
      if (v !== undefined && !(Number.isFinite(v) && v >= 0)) throw new TypeError(`${key} must be a finite number ≥ 0, not ${String(v)}`);
    }
    this.#holdOption = options.holdAfterUs;
    this.#failsafeAfterUs = options.failsafeAfterUs ?? FAILSAFE_TIMEOUT_US;
    this.#jitterUs = options.jitterUs ?? 0;
    this.#maxEpisodes = options.maxEpisodes ?? Infinity;
  }

  get state(): LinkState {
    return this.#state;
  }

  /** Live counters (the same object each time). */
  get stats(): Readonly<LinkStats> {
    return this.#stats;
  }

  /** The hold and failsafe episodes kept (all, unless `maxEpisodes`), oldest first; the last may still be open. */
  get episodes(): readonly LinkEpisode[] {
    return this.#episodes;
  }

  /** Time of the last frame, µs (NaN before the first or without timing). */
  get lastFrameUs(): number {
    return this.#lastUs;
  }

  /** The hold threshold in force, µs. */
  get holdAfterUs(): number {
    if (this.#holdOption !== undefined) return this.#holdOption;
    const p = this.#stats.nominalPeriodUs;
    return Number.isFinite(p) ? Math.max(MIN_HOLD_US, 2.5 * p) : MIN_HOLD_US;
  }

  /** Feeds one decoded frame (in stream order). */
  frame(frame: DecodedFrame): void {
    const s = this.#stats;
    const t = frame.timeUs;
    s.frames++;
    s.fades += frame.fadesDelta;
    if (frame.rssi !== null) {
      s.rssi = frame.rssi;
      if (!(s.minRssi <= frame.rssi)) s.minRssi = frame.rssi;
    }
    if (frame.system !== null) {
      const info = systemInfo(frame.system);
      if (info) {
        this.#systemPeriod = info.periodMs === 11 ? FRAME_PERIOD_11MS_US : FRAME_PERIOD_22MS_US;
        s.nominalPeriodUs = this.#systemPeriod;
      }
    }
    if (Number.isFinite(t)) {
      const last = this.#lastUs;
      if (Number.isFinite(last) && t >= last) {
        const gap = t - last;
        // Open the episodes a caller that never called update() in the gap would have missed.
        this.update(t);
        if (gap > s.longestGapUs) s.longestGapUs = gap;
        const p = s.nominalPeriodUs;
        if (Number.isFinite(p) && gap > 1.5 * p + this.#jitterUs) s.missedFrames += Math.max(0, Math.round(gap / p) - 1);
        if (gap > 3 * (Number.isFinite(p) ? p : FRAME_PERIOD_22MS_US)) this.#periodCount = 0;
      }
      this.#lastUs = t;
      this.#measure(t, frame.fadesDelta);
    }
    if (this.#open !== null) {
      this.#open.endUs = Number.isFinite(t) ? t : this.#open.startUs;
      this.#open = null;
    }
    this.#state = 'live';
  }

  /**
   * Advances the clock to `nowUs` (the caller's time, same clock as the frames) and returns
   * the state: 'hold' once the hold threshold has passed without a frame, 'failsafe' after 1 s.
   */
  update(nowUs: number): LinkState {
    const last = this.#lastUs;
    if (this.#state === 'waiting' || !Number.isFinite(last) || !Number.isFinite(nowUs)) return this.#state;
    const gap = nowUs - last;
    const s = this.#stats;
    if (gap > this.holdAfterUs && this.#state === 'live') {
      this.#state = 'hold';
      s.holds++;
      this.#openEpisode('hold', last + this.holdAfterUs, last);
    }
    if (gap >= this.#failsafeAfterUs && this.#state === 'hold') {
      this.#state = 'failsafe';
      s.failsafes++;
      if (this.#open !== null) this.#open.endUs = last + this.#failsafeAfterUs;
      this.#openEpisode('failsafe', last + this.#failsafeAfterUs, last);
    }
    return this.#state;
  }

  #openEpisode(kind: 'hold' | 'failsafe', startUs: number, lastFrameUs: number): void {
    const episode: LinkEpisode = { id: this.#nextEpisode++, kind, startUs, endUs: null, lastFrameUs };
    this.#episodes.push(episode);
    // Drop the oldest in one go (an amortised splice), never the open one.
    if (this.#episodes.length > this.#maxEpisodes * 1.25) this.#episodes.splice(0, this.#episodes.length - this.#maxEpisodes);
    this.#open = episode;
  }

  #measure(t: number, fadesDelta: number): void {
    const s = this.#stats;
    // Period: the span of the last 32 gap-free intervals, which averages out chunk jitter.
    const times = this.#periodTimes;
    if (this.#periodCount < PERIOD_WINDOW) {
      times[this.#periodCount++] = t;
    } else {
      times.copyWithin(0, 1);
      times[PERIOD_WINDOW - 1] = t;
    }
    if (this.#periodCount >= 9) {
      const span = (times[this.#periodCount - 1] as number) - (times[0] as number);
      if (!Number.isFinite(this.#systemPeriod) && (!Number.isFinite(s.nominalPeriodUs) || this.#periodCount === PERIOD_WINDOW)) {
        // Without a system byte: snap the mean interval to 11 or 22 ms, first over 8 intervals,
        // then again over every full window, so a few frames missing early do not stick.
        s.nominalPeriodUs = span / (this.#periodCount - 1) < 16_500 ? FRAME_PERIOD_11MS_US : FRAME_PERIOD_22MS_US;
      }
      // Whole periods in the span (a missed frame makes one interval two periods long), so a
      // short gap does not bias the measurement and chunk-time jitter averages out.
      const periods = Math.max(1, Math.round(span / s.nominalPeriodUs));
      s.periodUs = span / periods;
    }
    // Fade rate over a window of recent frames.
    const i = this.#rateNext;
    const prev = this.#rateCount === 0 ? 0 : (this.#rateFades[(i + RATE_WINDOW - 1) % RATE_WINDOW] as number);
    this.#rateTimes[i] = t;
    this.#rateFades[i] = prev + fadesDelta;
    this.#rateNext = (i + 1) % RATE_WINDOW;
    if (this.#rateCount < RATE_WINDOW) this.#rateCount++;
    const oldest = this.#rateCount < RATE_WINDOW ? 0 : this.#rateNext;
    const span = t - (this.#rateTimes[oldest] as number);
    s.fadeRate = span > 0 ? (((this.#rateFades[i] as number) - (this.#rateFades[oldest] as number)) / span) * 1e6 : 0;
  }
}
