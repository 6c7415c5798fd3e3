/**
 * The one binned time series of a link: frames, fades, lost frames, RSSI and frame intervals
 * per time bin, made from what a `LinkMonitor` decided (plausible fades, ordinary intervals,
 * missed frames placed where they were due). The live page (100 ms bins), the replay overview
 * and the health report (1 s bins) all fill it the same way.
 */
import { LinkMonitor } from '../decoder/link.js';
import type { LinkOptions } from '../decoder/link-types.js';
import type { DecodedFrame } from '../decoder/types.js';

/**
 * The most bins a series holds: 12 days of 1 s bins, 29 h of 100 ms ones. Times are whatever a
 * caller passes; one far from the rest must not make the series allocate for the span between
 * them, so what falls past the last bin is counted (`unbinned`), never given bins.
 */
export const MAX_SERIES_BINS = 1 << 20;

/** A growable Float64Array column (up to MAX_SERIES_BINS). */
class Column {
  data: Float64Array;
  constructor(fill: number) {
    this.data = new Float64Array(64).fill(fill);
    this.fill = fill;
  }
  readonly fill: number;
  ensure(n: number): void {
    if (n <= this.data.length) return;
    let size = this.data.length;
    while (size < n) size *= 2;
    size = Math.min(size, Math.max(n, MAX_SERIES_BINS));
    const next = new Float64Array(size).fill(this.fill);
    next.set(this.data);
    this.data = next;
  }
}

/** Per-bin sums; bin `i` covers [originUs + i × binUs, originUs + (i + 1) × binUs). */
export class LinkSeries {
  readonly binUs: number;
  #origin: number;
  #bins = 0;
  /** Bins below this are sealed (handed out): later additions go to the first open bin. */
  #sealed = 0;
  /** Frames and missed frames whose time fell past MAX_SERIES_BINS. */
  #unbinned = 0;
  readonly #frames = new Column(0);
  readonly #fades = new Column(0);
  readonly #lost = new Column(0);
  readonly #rssiSum = new Column(0);
  readonly #rssiN = new Column(0);
  readonly #rssiMin = new Column(Infinity);
  readonly #intervalSum = new Column(0);
  readonly #intervalN = new Column(0);
  readonly #columns: Column[];
  /**
   * The bin the frames go into now, its cells in fields: read from its columns when it became the
   * held bin, written back before anything reads them or the frames move on (`#writeHeld`).
   * Adding to seven fields a frame, not to seven columns' arrays, took most of the series' time off
   * a day capture's replay pass (30 ns a frame in Chromium's worker, by its profile). Each cell is
   * summed in the same order as before, so every value is the same to the last bit, read when it may.
   */
  #held = -1;
  #heldFrames = 0;
  #heldFades = 0;
  #heldRssiSum = 0;
  #heldRssiN = 0;
  #heldRssiMin = Infinity;
  #heldIntervalSum = 0;
  #heldIntervalN = 0;

  /**
   * @param binUs bin width, µs
   * @param originUs start of bin 0; default: the first frame's time, down to a multiple of `binUs`
   * @throws {TypeError} when `binUs` is not a positive finite number
   */
  constructor(binUs: number, originUs = NaN) {
    if (!(Number.isFinite(binUs) && binUs > 0)) throw new TypeError(`binUs must be a positive finite number, not ${String(binUs)}`);
    this.binUs = binUs;
    this.#origin = originUs;
    this.#columns = [this.#frames, this.#fades, this.#lost, this.#rssiSum, this.#rssiN, this.#rssiMin, this.#intervalSum, this.#intervalN];
  }

  /** Start of bin 0, µs (NaN until the first timed frame when not given). */
  get originUs(): number {
    return this.#origin;
  }

  /** Bins so far (up to the last one anything went into, or `extendTo`). */
  get bins(): number {
    return this.#bins;
  }

  /** Frames and missed frames not binned: their time fell more than MAX_SERIES_BINS bins after the origin. */
  get unbinned(): number {
    return this.#unbinned;
  }

  /** The bin time `t` (finite) goes in, made if need be; -1 when it is past MAX_SERIES_BINS. */
  #bin(t: number): number {
    if (Number.isNaN(this.#origin)) this.#origin = Math.floor(t / this.binUs) * this.binUs;
    const b = Math.max(this.#sealed, Math.floor((t - this.#origin) / this.binUs));
    if (!(b < MAX_SERIES_BINS)) return -1;
    if (b >= this.#bins) {
      for (const c of this.#columns) c.ensure(b + 1);
      this.#bins = b + 1;
    }
    return b;
  }

  /** Makes the series at least as long as the bin holding `t`. */
  extendTo(t: number): void {
    if (Number.isFinite(t) && !Number.isNaN(this.#origin)) this.#bin(t);
  }

  /** Counts a frame `link` has just counted (its plausible fades, RSSI and ordinary interval). */
  frame(f: DecodedFrame, link: LinkMonitor): void {
    const t = f.timeUs;
    if (!Number.isFinite(t)) return;
    // A bin the series has, open to frames: #bin's answer without the call (the usual frame; an
    // origin not known yet is NaN and fails the test).
    const at = Math.floor((t - this.#origin) / this.binUs);
    const b = at >= this.#sealed && at < this.#bins ? at : this.#bin(t);
    if (b < 0) {
      this.#unbinned++;
      return;
    }
    if (b !== this.#held) this.#hold(b);
    this.#heldFrames++;
    this.#heldFades += link.lastFades;
    const rssi = f.rssi;
    if (rssi !== null && rssi !== -128) {
      this.#heldRssiSum += rssi;
      this.#heldRssiN++;
      if (rssi < this.#heldRssiMin) this.#heldRssiMin = rssi;
    }
    const iv = link.lastIntervalUs;
    if (Number.isFinite(iv)) {
      this.#heldIntervalSum += iv;
      this.#heldIntervalN++;
    }
  }

  /** Makes bin `b` the held bin: the one held before written back, `b`'s cells read. */
  #hold(b: number): void {
    this.#writeHeld();
    this.#held = b;
    this.#heldFrames = this.#frames.data[b]!;
    this.#heldFades = this.#fades.data[b]!;
    this.#heldRssiSum = this.#rssiSum.data[b]!;
    this.#heldRssiN = this.#rssiN.data[b]!;
    this.#heldRssiMin = this.#rssiMin.data[b]!;
    this.#heldIntervalSum = this.#intervalSum.data[b]!;
    this.#heldIntervalN = this.#intervalN.data[b]!;
  }

  /** Writes the held bin's cells into its columns (it stays held: nothing else writes them). */
  #writeHeld(): void {
    const b = this.#held;
    if (b < 0) return;
    this.#frames.data[b] = this.#heldFrames;
    this.#fades.data[b] = this.#heldFades;
    this.#rssiSum.data[b] = this.#heldRssiSum;
    this.#rssiN.data[b] = this.#heldRssiN;
    this.#rssiMin.data[b] = this.#heldRssiMin;
    this.#intervalSum.data[b] = this.#heldIntervalSum;
    this.#intervalN.data[b] = this.#heldIntervalN;
  }

  /**
   * `count` frames missing, due one `periodUs` apart from `fromUs`, none after `toUs` (those due
   * later count at `toUs`). Each bin gets the frames whose time falls in it, worked out a bin at
   * a time: the work follows the bins touched, not the count (a clock gone wild can ask for
   * billions).
   */
  missed(fromUs: number, toUs: number, count: number, periodUs: number): void {
    if (!Number.isFinite(fromUs) || !(count > 0)) return;
    const n = Math.floor(count);
    const p = Number.isFinite(periodUs) && periodUs > 0 ? periodUs : 0;
    const end = Number.isFinite(toUs) ? toUs : Infinity;
    const at = (k: number): number => Math.min(fromUs + k * p, end);
    // Frames 0 … due - 1 fall before `end`, the rest at it. Estimated, then set right where
    // rounding put the estimate a frame off (a few steps at most).
    let due = p === 0 ? (fromUs < end ? n : 0) : Math.min(n, Math.max(0, Math.ceil((end - fromUs) / p)));
    for (let s = 0; s < 4 && due > 0 && !(fromUs + (due - 1) * p < end); s++) due--;
    for (let s = 0; s < 4 && due < n && fromUs + due * p < end; s++) due++;
    for (let k = 0; k < due; ) {
      const b = this.#bin(at(k));
      if (b < 0) {
        this.#unbinned += n - k;
        return;
      }
      // The last frame in bin b: estimated from the bin's end, then set right frame by frame.
      let last = p === 0 ? due - 1 : Math.min(due - 1, Math.max(k, Math.ceil((this.startOf(b + 1) - fromUs) / p) - 1));
      for (let s = 0; s < 4 && last > k && this.#target(at(last)) !== b; s++) last--;
      for (let s = 0; s < 4 && last + 1 < due && this.#target(at(last + 1)) === b; s++) last++;
      this.#lost.data[b]! += last - k + 1;
      k = last + 1;
    }
    if (due < n) {
      const b = this.#bin(end);
      if (b < 0) this.#unbinned += n - due;
      else this.#lost.data[b]! += n - due;
    }
  }

  /** The bin time `t` goes in (the origin known), without making it. */
  #target(t: number): number {
    return Math.max(this.#sealed, Math.floor((t - this.#origin) / this.binUs));
  }

  /** Seals the bins before `bin`: nothing is added to them any more (the live view has shown them). */
  seal(bin: number): void {
    if (bin > this.#sealed) this.#sealed = bin;
  }

  /** The bin that holds time `t` (can be negative or past the end). */
  binOf(t: number): number {
    return Math.floor((t - this.#origin) / this.binUs);
  }

  /** Start time of bin `i`, µs. */
  startOf(i: number): number {
    return this.#origin + i * this.binUs;
  }

  frames(i: number): number {
    if (i === this.#held) this.#writeHeld();
    return this.#frames.data[i] ?? 0;
  }
  fades(i: number): number {
    if (i === this.#held) this.#writeHeld();
    return this.#fades.data[i] ?? 0;
  }
  lost(i: number): number {
    return this.#lost.data[i] ?? 0;
  }
  /** Mean RSSI of bin `i` (loss reports of −128 left out), NaN without. */
  rssiMean(i: number): number {
    if (i === this.#held) this.#writeHeld();
    const n = this.#rssiN.data[i] ?? 0;
    return n > 0 ? (this.#rssiSum.data[i] ?? 0) / n : NaN;
  }
  /** Lowest RSSI of bin `i`, NaN without. */
  rssiMin(i: number): number {
    if (i === this.#held) this.#writeHeld();
    const v = this.#rssiMin.data[i] ?? Infinity;
    return Number.isFinite(v) ? v : NaN;
  }
  /** Mean ordinary frame interval of bin `i`, µs, NaN without one. */
  intervalMean(i: number): number {
    if (i === this.#held) this.#writeHeld();
    const n = this.#intervalN.data[i] ?? 0;
    return n > 0 ? (this.#intervalSum.data[i] ?? 0) / n : NaN;
  }

  /** The whole series as plain data (copies of its bins so far), for `restore` in another series of the same `binUs`. */
  checkpoint(): LinkSeriesCheckpoint {
    this.#writeHeld();
    return {
      binUs: this.binUs,
      originUs: this.#origin,
      bins: this.#bins,
      sealed: this.#sealed,
      unbinned: this.#unbinned,
      columns: this.#columns.map((c) => c.data.slice(0, this.#bins)),
    };
  }

  /**
   * Back to where `checkpoint()` was taken.
   * @throws {TypeError} when `cp` has another bin width
   */
  restore(cp: LinkSeriesCheckpoint): void {
    if (cp.binUs !== this.binUs) throw new TypeError(`a series of ${cp.binUs} µs bins cannot restore into one of ${this.binUs} µs`);
    this.#origin = cp.originUs;
    this.#held = -1;
    this.#bins = cp.bins;
    this.#sealed = cp.sealed;
    this.#unbinned = cp.unbinned ?? 0;
    this.#columns.forEach((c, i) => {
      c.data = new Float64Array(Math.max(64, cp.bins)).fill(c.fill);
      c.data.set(cp.columns[i] ?? []);
    });
  }
}

/** `LinkSeries.checkpoint()`. */
export interface LinkSeriesCheckpoint {
  readonly binUs: number;
  readonly originUs: number;
  readonly bins: number;
  readonly sealed: number;
  /** `unbinned` when it was taken (absent in checkpoints from before it was counted: 0). */
  readonly unbinned?: number;
  /** Frames, fades, lost, RSSI sum, RSSI count, RSSI minimum, interval sum, interval count: one value a bin. */
  readonly columns: readonly Float64Array[];
}

/** A link monitor whose missed frames go into `series` too. */
export function monitorWithSeries(options: Omit<LinkOptions, 'onMissed'>, series: LinkSeries): LinkMonitor {
  return new LinkMonitor({ ...options, onMissed: (from, to, n, p) => series.missed(from, to, n, p) });
}
