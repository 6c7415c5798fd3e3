/**
 * High-rate data on the page: the latest batch's values in typed arrays and the graph series
 * in growing columns, outside the virtual DOM. Renderers read it once per animation frame
 * (frame-loop.ts) and redraw only what changed.
 */
import { CHANNEL_COUNT } from '../decoder/spec.js';
import type { Batch } from '../worker/protocol.js';
import { TraceBuffer } from './traces.js';

/** Episodes are kept as long as the longest graph window (10 min). */
const EPISODE_KEEP_US = 600e6;
/** Ten minutes of 100 ms buckets: the longest graph window. */
const WINDOW_BUCKETS = 6000;
/** Buckets kept past the window before the oldest are dropped (in one step every 2.5 minutes). */
const SLACK_BUCKETS = 1500;

/** A bucket's value as the graphs take it: NaN (no value in that bucket) breaks the line, as null. */
const gap = (v: number): number | null => (Number.isNaN(v) ? null : v);

/**
 * One remote's graph buckets as columns that grow: each batch's new buckets are appended once,
 * in the form uPlot draws (seconds, gaps as null), and the graphs hand the same arrays to uPlot
 * on every redraw, which draws only what its x scale shows. Nothing is rebuilt per redraw; what
 * is older than the longest window is dropped in one step once 2.5 minutes of it piled up.
 *
 * The newest buckets are provisional (still open in the worker: a missed frame may yet be
 * placed in them) and each batch replaces them, so the graphs always hold what the counters
 * count.
 */
export class SeriesBuffer {
  /** Bucket start in seconds of the source clock (uPlot's x), ascending. */
  readonly t: number[] = [];
  // Fades and lost frames have a value in every bucket: kept as plain doubles (no null in the
  // array, so V8 stores them unboxed). RSSI and the period have gaps.
  readonly fadeRate: number[] = [];
  readonly rssi: (number | null)[] = [];
  readonly periodMs: (number | null)[] = [];
  readonly lost: number[] = [];
  /** Final buckets appended since the last clear (including those dropped since): what is new to a reader. */
  appended = 0;
  /** The last this many buckets are provisional: a reader reads them again after each append. */
  provisional = 0;
  /** Counts clears, so a reader that kept a position knows to start over. */
  epoch = 0;

  get length(): number {
    return this.t.length;
  }

  append(s: Batch['series']): void {
    if (this.provisional > 0) for (const col of this.#columns()) col.length -= this.provisional;
    s.t.forEach((t, i) => {
      this.t.push(t / 1e6);
      this.fadeRate.push(s.fadeRate[i] ?? 0);
      this.rssi.push(gap(s.rssi[i] ?? Number.NaN));
      this.periodMs.push(gap(s.periodMs[i] ?? Number.NaN));
      this.lost.push(s.lost[i] ?? 0);
    });
    this.appended += s.settled;
    this.provisional = s.t.length - s.settled;
    if (this.t.length > WINDOW_BUCKETS + SLACK_BUCKETS) {
      const drop = this.t.length - WINDOW_BUCKETS;
      for (const col of this.#columns()) col.splice(0, drop);
    }
  }

  /**
   * How many of the newest buckets a reader that last read at `appended` must (re)read: the
   * final ones appended since, and the provisional ones.
   */
  unreadSince(appended: number): number {
    return Math.min(this.appended - appended + this.provisional, this.t.length);
  }

  clear(): void {
    for (const col of this.#columns()) col.length = 0;
    this.appended = 0;
    this.provisional = 0;
    this.epoch++;
  }

  /** Index of the first bucket at or after `tSec` (binary search). */
  indexAt(tSec: number): number {
    let lo = 0;
    let hi = this.t.length;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if ((this.t[mid] ?? Number.POSITIVE_INFINITY) < tSec) lo = mid + 1;
      else hi = mid;
    }
    return lo;
  }

  #columns(): (number | null)[][] {
    return [this.t, this.fadeRate, this.rssi, this.periodMs, this.lost];
  }
}

export interface Episode {
  kind: 'hold' | 'failsafe';
  startUs: number;
  endUs: number | null;
}

export class Live {
  readonly positions = new Uint16Array(CHANNEL_COUNT);
  readonly seenUs = new Float64Array(CHANNEL_COUNT).fill(NaN);
  readonly series = new SeriesBuffer();
  /** Every frame's channel values and the glitches, for the channel traces. */
  readonly traces = new TraceBuffer();
  readonly episodes = new Map<number, Episode>();
  link: Batch['link'] | null = null;
  counters: Batch['counters'] = { bytes: 0, frames: 0, resyncs: 0, discardedBytes: 0, badFrames: 0, emptySlots: 0, vtxFrames: 0 };
  resolution: 1024 | 2048 | null = null;
  /** The source has ended: its clock and state stand still. */
  ended = false;
  /** While a forced resolution matches no frame: the resolution the stream looks like. */
  mismatch: 1024 | 2048 | null = null;
  /** Each channel's frames, lowest, highest and last µs, as `satscope info` counts them (null: none yet). */
  channels: Batch['channels'] | null = null;
  /** Source clock at the last batch, and when (performance.now()) it arrived. */
  #clockUs = NaN;
  #clockAtMs = 0;
  clockRate = 0;
  /** Something new for the renderers since they last drew. */
  version = 0;
  /** Latency samples: batch arrival on the page minus byte arrival in the worker (ms). */
  lastArrivedMs = 0;

  apply(batch: Batch): void {
    this.positions.set(batch.positions);
    this.seenUs.set(batch.seenUs);
    this.link = batch.link;
    this.counters = batch.counters;
    this.resolution = batch.resolution;
    this.ended = batch.ended;
    this.mismatch = batch.mismatch;
    this.channels = batch.channels;
    this.series.append(batch.series);
    this.traces.append(batch.traces);
    for (const e of batch.episodes) this.episodes.set(e.id, { kind: e.kind, startUs: e.startUs, endUs: e.endUs });
    for (const id of batch.retracted) this.episodes.delete(id);
    // Nothing shows episodes older than the longest window: a long session must not pile them up.
    for (const [id, e] of this.episodes) if (e.endUs !== null && e.endUs < batch.nowUs - EPISODE_KEEP_US) this.episodes.delete(id);
    this.#clockUs = batch.nowUs;
    this.#clockAtMs = performance.now();
    this.lastArrivedMs = batch.arrivedMs;
    this.version++;
  }

  reset(): void {
    this.positions.fill(0);
    this.seenUs.fill(NaN);
    this.series.clear();
    this.traces.clear();
    this.episodes.clear();
    this.link = null;
    this.counters = { bytes: 0, frames: 0, resyncs: 0, discardedBytes: 0, badFrames: 0, emptySlots: 0, vtxFrames: 0 };
    this.resolution = null;
    this.ended = false;
    this.mismatch = null;
    this.channels = null;
    this.#clockUs = NaN;
    this.version++;
  }

  /** The source clock now, extrapolated from the last batch (frozen when paused or ended). */
  nowUs(): number {
    if (this.ended) return this.#clockUs;
    return this.#clockUs + (performance.now() - this.#clockAtMs) * 1000 * this.clockRate;
  }
}
