/**
 * High-rate data on the page: the latest batch's values and the graph series, kept in typed
 * arrays outside the virtual DOM. Renderers read it once per animation frame (frame-loop.ts)
 * and redraw only what changed.
 */
import { CHANNEL_COUNT } from '../decoder/index.js';
import type { Batch } from '../worker/protocol.js';

/** Episodes are kept as long as the longest graph window (10 min). */
const EPISODE_KEEP_US = 600e6;
/** Ten minutes of 100 ms buckets, twice over so that sliding is a rare copy. */
const SERIES_CAPACITY = 2 * 6000;

export class SeriesBuffer {
  /** Bucket start in seconds of the source clock (uPlot's x). */
  readonly t = new Float64Array(SERIES_CAPACITY);
  readonly fadeRate = new Float64Array(SERIES_CAPACITY);
  readonly rssi = new Float64Array(SERIES_CAPACITY);
  readonly periodMs = new Float64Array(SERIES_CAPACITY);
  readonly lost = new Float64Array(SERIES_CAPACITY);
  length = 0;

  append(s: Batch['series']): void {
    const n = s.t.length;
    if (n === 0) return;
    if (this.length + n > SERIES_CAPACITY) {
      // Keep the newest half: graphs show at most half the capacity.
      const keep = Math.min(this.length, SERIES_CAPACITY / 2 - n);
      const from = this.length - keep;
      for (const col of [this.t, this.fadeRate, this.rssi, this.periodMs, this.lost]) col.copyWithin(0, from, this.length);
      this.length = keep;
    }
    const at = this.length;
    for (let i = 0; i < n; i++) this.t[at + i] = (s.t[i] as number) / 1e6;
    this.fadeRate.set(s.fadeRate, at);
    this.rssi.set(s.rssi, at);
    this.periodMs.set(s.periodMs, at);
    this.lost.set(s.lost, at);
    this.length += n;
  }

  clear(): void {
    this.length = 0;
  }

  /** Index of the first bucket at or after `tSec` (binary search). */
  indexAt(tSec: number): number {
    let lo = 0;
    let hi = this.length;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if ((this.t[mid] as number) < tSec) lo = mid + 1;
      else hi = mid;
    }
    return lo;
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
  readonly episodes = new Map<number, Episode>();
  link: Batch['link'] | null = null;
  counters: Batch['counters'] = { bytes: 0, frames: 0, resyncs: 0, discardedBytes: 0, badFrames: 0, emptySlots: 0, vtxFrames: 0 };
  resolution: 1024 | 2048 | null = null;
  /** The source has ended: its clock and state stand still. */
  ended = false;
  /** While a forced resolution matches no frame: the resolution the stream looks like. */
  mismatch: 1024 | 2048 | null = null;
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
    this.series.append(batch.series);
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
    this.episodes.clear();
    this.link = null;
    this.counters = { bytes: 0, frames: 0, resyncs: 0, discardedBytes: 0, badFrames: 0, emptySlots: 0, vtxFrames: 0 };
    this.resolution = null;
    this.ended = false;
    this.mismatch = null;
    this.#clockUs = NaN;
    this.version++;
  }

  /** The source clock now, extrapolated from the last batch (frozen when paused or ended). */
  nowUs(): number {
    if (this.ended) return this.#clockUs;
    return this.#clockUs + (performance.now() - this.#clockAtMs) * 1000 * this.clockRate;
  }
}
