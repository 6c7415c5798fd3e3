/**
 * The link's rates over recent frames: the frame period (and, without a system byte, the 11 or
 * 22 ms it snaps to) over the last 32 gap-free intervals, and the fade rate over the last ~512
 * frames. The link monitor (link.ts) owns one and feeds it every timed frame.
 */
import type { LinkCheckpoint } from './checkpoint.js';
import { nominalPeriodOf } from './link-rules.js';
import type { LinkStats } from './link-types.js';
import { FRAME_PERIOD_11MS_US } from './spec.js';

const PERIOD_WINDOW = 33;
/** A mean frame interval below this (0.8 × 11 ms) is no system's period: frames a delivery burst brought together. */
const BURST_MEAN_US = 0.8 * FRAME_PERIOD_11MS_US;
const RATE_WINDOW = 512;

/** What of a `LinkCheckpoint` is the rates'. */
type RatesCheckpoint = Pick<
  LinkCheckpoint,
  'periodTimes' | 'periodCount' | 'periodOldest' | 'rateTimes' | 'rateFades' | 'rateCount' | 'rateNext'
>;

/**
 * The period and fade-rate windows: each frame taken (`measure`) sets `periodUs`, `fadeRate`
 * and, while no system byte gives it, `nominalPeriodUs` in the monitor's stats.
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

  /** Forgets the period window's frames (after a gap or an interruption: no interval spans it). */
  clearPeriod(): void {
    this.#periodCount = 0;
  }

  /**
   * The period and fade-rate windows take the frame at `t` (and, when `snap`: no system byte
   * gives the period, the nominal period is snapped, which the frame's own rules read), and the
   * figures in `s` follow.
   */
  measure(t: number, fadesDelta: number, s: LinkStats, snap: boolean): void {
    // Period: the span of the last 32 gap-free intervals, which averages out chunk jitter.
    const times = this.#periodTimes;
    const count = this.#periodCount;
    if (count < PERIOD_WINDOW) {
      if (count === 0) this.#periodOldest = 0;
      times[count] = t;
      this.#periodCount = count + 1;
    } else {
      const oldest = this.#periodOldest;
      times[oldest] = t;
      this.#periodOldest = oldest === PERIOD_WINDOW - 1 ? 0 : oldest + 1;
    }
    if (this.#periodCount >= 9) {
      if (snap && (!Number.isFinite(s.nominalPeriodUs) || this.#periodCount === PERIOD_WINDOW)) {
        // Without a system byte: snap the mean interval to 11 or 22 ms, first over 8 intervals,
        // then again over every full window, so a few frames missing early do not stick. A
        // window that a delivery burst crowds (frames a stall held back, dated together) is
        // faster than any system sends: it says nothing of the period.
        const mean = (t - (times[this.#periodOldest] ?? NaN)) / (this.#periodCount - 1);
        if (!(mean < BURST_MEAN_US)) s.nominalPeriodUs = nominalPeriodOf(mean);
      }
      // Whole periods in the span, so that a missed frame (one interval two periods long) does
      // not bias it, and chunk-time jitter averages out.
      const newest =
        this.#periodCount < PERIOD_WINDOW ? this.#periodCount - 1 : this.#periodOldest === 0 ? PERIOD_WINDOW - 1 : this.#periodOldest - 1;
      const span = (times[newest] ?? NaN) - (times[this.#periodOldest] ?? NaN);
      s.periodUs = span / Math.max(1, Math.round(span / s.nominalPeriodUs));
    }
    // Fade rate over a window of recent frames.
    const i = this.#rateNext;
    const fades = this.#rateFades;
    const prev = this.#rateCount === 0 ? 0 : (fades[i === 0 ? RATE_WINDOW - 1 : i - 1] ?? 0);
    this.#rateTimes[i] = t;
    fades[i] = prev + fadesDelta;
    this.#rateNext = i === RATE_WINDOW - 1 ? 0 : i + 1;
    if (this.#rateCount < RATE_WINDOW) this.#rateCount++;
    const oldest = this.#rateCount < RATE_WINDOW ? 0 : this.#rateNext;
    const span = t - (this.#rateTimes[oldest] ?? NaN);
    s.fadeRate = span > 0 ? (((fades[i] ?? 0) - (fades[oldest] ?? 0)) / span) * 1e6 : 0;
  }

  /** The windows as they stand (copies), for `LinkMonitor.checkpoint()`. */
  checkpoint(): RatesCheckpoint {
    return {
      periodTimes: this.#periodTimes.slice(),
      periodCount: this.#periodCount,
      periodOldest: this.#periodOldest,
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
    this.#rateTimes.set(cp.rateTimes);
    this.#rateFades.set(cp.rateFades);
    this.#rateCount = cp.rateCount;
    this.#rateNext = cp.rateNext;
  }
}
