/**
 * The link's rates over recent frames: the frame period (and, without a system byte, the 11 or
 * 22 ms it snaps to) over the last 32 gap-free intervals, and the fade rate over the last ~512
 * frames. The link monitor (link.ts) owns one and feeds it every timed frame.
 *
 * Without a system byte the period is snapped only once the window's timing can tell 11 from
 * 22 ms: an adapter that delivers in batches dates a frame late by up to the longest interval
 * it leaves, so the mean interval is known only to that over the periods in the window, and a
 * mean closer than that to the boundary between the two decides nothing yet.
 *
 * A system byte states the period, until the frames refute it: a window whose mean interval is
 * the other period's (an external remote whose fade count reads as a system byte, or a receiver
 * whose byte lies). Frames lost at random do not refute it (the mean falls between the two), nor
 * do frames lost where the receiver's counter counts them.
 */
import type { LinkCheckpoint } from './checkpoint.js';
import { nominalPeriodOf, PERIOD_SNAP_US } from './link-rules.js';
import type { LinkStats } from './link-types.js';
import { FRAME_PERIOD_11MS_US, FRAME_PERIOD_22MS_US } from './spec.js';

const PERIOD_WINDOW = 33;
/** A mean frame interval below this (0.8 × 11 ms) is no system's period: frames a delivery burst brought together. */
const BURST_MEAN_US = 0.8 * FRAME_PERIOD_11MS_US;
const RATE_WINDOW = 512;
/** Checks in a row that must refute a stated period: every eighth frame, so two windows' worth. */
const REFUTING_CHECKS = 5;
/** A window's mean interval this close to a period (or closer than its lateness allows) is that period's, µs. */
const MEAN_FIT_US = 500;

/** What of a `LinkCheckpoint` is the rates'. */
type RatesCheckpoint = Pick<
  LinkCheckpoint,
  | 'periodTimes'
  | 'periodCount'
  | 'periodOldest'
  | 'periodStated'
  | 'periodRefuted'
  | 'periodAgainst'
  | 'periodCounted'
  | 'rateTimes'
  | 'rateFades'
  | 'rateCount'
  | 'rateNext'
>;

/**
 * The period and fade-rate windows: each frame taken (`measure`) sets `periodUs`, `fadeRate`
 * and, while no system byte states it (or the frames refuted what one stated), `nominalPeriodUs`
 * in the monitor's stats.
 */
export class LinkRates {
  /** The last frame times without a gap, a ring: `#periodCount` of them, the oldest at `#periodOldest` once it is full. */
  readonly #periodTimes = new Float64Array(PERIOD_WINDOW);
  #periodCount = 0;
  #periodOldest = 0;
  readonly #rateTimes = new Float64Array(RATE_WINDOW);
  readonly #rateFades = new Float64Array(RATE_WINDOW);
  #rateCount = 0;
  #rateNext = 0;
  /** The period the system byte states (NaN: none), and whether the frames' timing refuted it. */
  #stated = NaN;
  #refuted = false;
  /** Checks in a row (every eighth frame) whose window refuted the stated period. */
  #against = 0;
  /** Frames in a row whose byte 0 was a fade count. */
  #counted = 0;

  /** The period the system byte states, µs (NaN: none). */
  get stated(): number {
    return this.#stated;
  }

  /** A system byte states the period `periodUs` (NaN: none does now): it is the nominal period until refuted. */
  state(periodUs: number, s: LinkStats): void {
    this.#stated = periodUs;
    this.#refuted = false;
    this.#against = 0;
    s.nominalPeriodUs = periodUs;
  }

  /** Forgets the period window's frames (after a gap or an interruption: no interval spans it). */
  clearPeriod(): void {
    this.#periodCount = 0;
  }

  /**
   * The period and fade-rate windows take the frame at `t` (`counted`: its byte 0 is a fade
   * count; and, where no system byte states the period or the frames refuted it, the nominal
   * period is snapped, which the frame's own rules read), and the figures in `s` follow.
   */
  measure(t: number, fadesDelta: number, s: LinkStats, counted: boolean): void {
    this.#counted = counted ? Math.min(this.#counted + 1, PERIOD_WINDOW) : 0;
    // Fade rate over a window of recent frames.
    const i = this.#rateNext;
    const fades = this.#rateFades;
    const prev = this.#rateCount === 0 ? 0 : (fades[i === 0 ? RATE_WINDOW - 1 : i - 1] ?? 0);
    this.#rateTimes[i] = t;
    fades[i] = prev + fadesDelta;
    this.#rateNext = i === RATE_WINDOW - 1 ? 0 : i + 1;
    if (this.#rateCount < RATE_WINDOW) this.#rateCount++;
    const oldest = this.#rateCount < RATE_WINDOW ? 0 : this.#rateNext;
    const rateSpan = t - (this.#rateTimes[oldest] ?? NaN);
    s.fadeRate = rateSpan > 0 ? (((fades[i] ?? 0) - (fades[oldest] ?? 0)) / rateSpan) * 1e6 : 0;
    // Period: the span of the last 32 gap-free intervals, which averages out chunk jitter.
    const times = this.#periodTimes;
    const count = this.#periodCount;
    const slot = count < PERIOD_WINDOW ? count : this.#periodOldest;
    times[slot] = t;
    if (count < PERIOD_WINDOW) {
      if (count === 0) this.#periodOldest = 0;
      this.#periodCount = count + 1;
    } else {
      this.#periodOldest = slot === PERIOD_WINDOW - 1 ? 0 : slot + 1;
    }
    if (this.#periodCount >= 9) {
      if (!Number.isFinite(this.#stated) || this.#refuted) {
        if (!Number.isFinite(s.nominalPeriodUs) || this.#periodCount === PERIOD_WINDOW)
          s.nominalPeriodUs = this.#snap(slot, s.nominalPeriodUs);
      } else if ((slot & 7) === 0) {
        // Every eighth frame: the stated period is weighed against the window's timing.
        this.#refute(slot, s);
      }
      // Whole periods in the span, so that a missed frame (one interval two periods long) does
      // not bias it, and chunk-time jitter averages out.
      const span = t - (times[this.#periodOldest] ?? NaN);
      s.periodUs = span / Math.max(1, Math.round(span / s.nominalPeriodUs));
    }
  }

  /**
   * The stated period is refuted where, over two windows' worth of checks, each window's mean
   * interval is the other period's, to within the lateness its longest interval allows (a
   * receiver losing frames at random averages between the two), and, if the frames came slower
   * than stated, the receiver's fade counter did not count the frames that would then be lost.
   */
  #refute(newest: number, s: LinkStats): void {
    const stated = this.#stated;
    const other = stated > FRAME_PERIOD_11MS_US ? FRAME_PERIOD_11MS_US : FRAME_PERIOD_22MS_US;
    const { mean, longest, periods } = this.#window(newest);
    let against = mean >= BURST_MEAN_US && Math.abs(mean - other) <= Math.max(MEAN_FIT_US, longest / periods);
    if (against && other > stated) {
      // Slower than stated: only a fade counter that counts every frame of the window, and did
      // not move, rules out the frames lost between them (RSSI mode has no counter).
      const fades = this.#rateFades;
      const last = this.#rateNext === 0 ? RATE_WINDOW - 1 : this.#rateNext - 1;
      const first = (last - (this.#periodCount - 1) + RATE_WINDOW) % RATE_WINDOW;
      against = this.#counted >= this.#periodCount && (fades[last] ?? 0) === (fades[first] ?? 0);
    }
    this.#against = against ? this.#against + 1 : 0;
    if (this.#against < REFUTING_CHECKS) return;
    this.#refuted = true;
    s.nominalPeriodUs = other;
  }

  /**
   * Without a system byte: the nominal period from the mean interval of the window ending at
   * `newest` (else `current`). It is decided only where the mean interval is further from the
   * 11/22 ms boundary than the lateness the window's longest interval allows, and again over
   * every full window, so that a few frames missing early do not stick. A window that a delivery
   * burst crowds (frames a stall held back, dated together) is faster than any system sends: it
   * says nothing of the period.
   */
  #snap(newest: number, current: number): number {
    const { mean, longest, periods } = this.#window(newest);
    if (mean < BURST_MEAN_US) return current;
    return Math.abs(mean - PERIOD_SNAP_US) > longest / periods ? nominalPeriodOf(mean) : current;
  }

  /** The period window ending at `newest`: its mean and longest interval, and how many intervals. */
  #window(newest: number): { mean: number; longest: number; periods: number } {
    const times = this.#periodTimes;
    const oldest = this.#periodOldest;
    const periods = this.#periodCount - 1;
    let longest = 0;
    for (let k = 1, i = oldest; k < this.#periodCount; k++) {
      const next = i === PERIOD_WINDOW - 1 ? 0 : i + 1;
      const interval = (times[next] ?? NaN) - (times[i] ?? NaN);
      if (interval > longest) longest = interval;
      i = next;
    }
    return { mean: ((times[newest] ?? NaN) - (times[oldest] ?? NaN)) / periods, longest, periods };
  }

  /** The windows as they stand (copies), for `LinkMonitor.checkpoint()`. */
  checkpoint(): RatesCheckpoint {
    return {
      periodTimes: this.#periodTimes.slice(),
      periodCount: this.#periodCount,
      periodOldest: this.#periodOldest,
      periodStated: this.#stated,
      periodRefuted: this.#refuted,
      periodAgainst: this.#against,
      periodCounted: this.#counted,
      rateTimes: this.#rateTimes.slice(),
      rateFades: this.#rateFades.slice(),
      rateCount: this.#rateCount,
      rateNext: this.#rateNext,
    };
  }

  /** Puts the windows back where `checkpoint()` was taken. */
  restore(cp: RatesCheckpoint): void {
    this.#periodTimes.set(cp.periodTimes);
    this.#periodCount = cp.periodCount;
    this.#periodOldest = cp.periodOldest;
    this.#stated = cp.periodStated;
    this.#refuted = cp.periodRefuted;
    this.#against = cp.periodAgainst;
    this.#counted = cp.periodCounted;
    this.#rateTimes.set(cp.rateTimes);
    this.#rateFades.set(cp.rateFades);
    this.#rateCount = cp.rateCount;
    this.#rateNext = cp.rateNext;
  }
}
