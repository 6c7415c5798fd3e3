/**
 * The link's rates over recent frames: the frame period (and, without a system byte, the 11 or
 * 22 ms it snaps to) over the last 32 gap-free intervals, and the fade rate over the last ~512
 * frames. The link monitor (link.ts) owns one and feeds it every timed frame.
 *
 * Without a system byte the period is snapped only once the window's timing can tell 11 from
 * 22 ms: an adapter that delivers in batches dates a frame late by up to the longest interval
 * it leaves, so the mean interval is known only to that over the periods in the window, and a
 * mean closer than that to the boundary between the two decides nothing yet.
 */
import type { LinkCheckpoint } from './checkpoint.js';
import { nominalPeriodOf, PERIOD_SNAP_US } from './link-rules.js';
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
    const slot = count < PERIOD_WINDOW ? count : this.#periodOldest;
    times[slot] = t;
    if (count < PERIOD_WINDOW) {
      if (count === 0) this.#periodOldest = 0;
      this.#periodCount = count + 1;
    } else {
      this.#periodOldest = slot === PERIOD_WINDOW - 1 ? 0 : slot + 1;
    }
    if (this.#periodCount >= 9) {
      if (snap && (!Number.isFinite(s.nominalPeriodUs) || this.#periodCount === PERIOD_WINDOW)) this.#snap(slot, s);
      // Whole periods in the span, so that a missed frame (one interval two periods long) does
      // not bias it, and chunk-time jitter averages out.
      const span = t - (times[this.#periodOldest] ?? NaN);
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

  /**
   * Without a system byte: the nominal period from the mean interval of the window ending at
   * `newest`. It is decided only where the mean interval is further from the 11/22 ms boundary than the lateness
   * the window's longest interval allows, and again over every full window, so that a few frames
   * missing early do not stick. A window that a delivery burst crowds (frames a stall held back,
   * dated together) is faster than any system sends: it says nothing of the period.
   */
  #snap(newest: number, s: LinkStats): void {
    const times = this.#periodTimes;
    const oldest = this.#periodOldest;
    const periods = this.#periodCount - 1;
    const mean = ((times[newest] ?? NaN) - (times[oldest] ?? NaN)) / periods;
    if (mean < BURST_MEAN_US) return;
    let longest = 0;
    for (let k = 1, i = oldest; k < this.#periodCount; k++) {
      const next = i === PERIOD_WINDOW - 1 ? 0 : i + 1;
      const interval = (times[next] ?? NaN) - (times[i] ?? NaN);
      if (interval > longest) longest = interval;
      i = next;
    }
    if (Math.abs(mean - PERIOD_SNAP_US) > longest / periods) s.nominalPeriodUs = nominalPeriodOf(mean);
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
