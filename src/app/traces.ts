/**
 * The channel traces on the page: one remote's frames as columns that grow (each frame's time
 * and every channel's value as of that frame, in µs), its glitches, and the view of a time
 * window as uPlot draws it, each chosen channel in a lane of its own.
 *
 * A channel's value holds from one appearance to the next (a 22 ms system carries some
 * channels every other frame, and a receiver's output holds a value until the next one), but
 * never across a break: after a silence the link monitor calls a hold, a channel has no value
 * until it appears again, and the line stops there rather than join what came before.
 */
import { CHANNEL_COUNT, PULSE_MAX_US, PULSE_MIN_US } from '../decoder/spec.js';
import type { TraceBatch } from '../worker/protocol.js';

/** Frames kept: ten minutes (the longest window) at 11 ms, with room (the worker sends no more between two batches). */
export const TRACE_ROWS = 65_536;
/** Glitches kept. */
const SPIKE_ROWS = 4096;
/** Anything older than the longest window before the newest frame is dropped when room is needed, µs. */
const KEEP_US = 600e6;

/** Columns that grow by doubling up to `cap` rows; when full, the oldest rows make room. */
class Rows {
  length = 0;
  constructor(readonly cap: number) {}

  /** Room for `n` more rows: grows each array through `grow`, or drops the oldest `drop(n)` rows. */
  room(n: number, size: number, grow: (size: number) => void, drop: (rows: number) => void): void {
    if (this.length + n <= size) return;
    if (size < this.cap) grow(Math.min(this.cap, Math.max(size * 2, this.length + n)));
    if (this.length + n > this.cap) drop(this.length + n - this.cap);
  }
}

export class TraceBuffer {
  /** Frame times, µs, ascending. */
  t = new Float64Array(1024);
  /** CHANNEL_COUNT values a frame, µs: each channel's value as of that frame (NaN: none yet, or none since a break). */
  us = new Float32Array(1024 * CHANNEL_COUNT);
  /** 1 where the line breaks before the frame. */
  gap = new Uint8Array(1024);
  readonly #rows = new Rows(TRACE_ROWS);
  /** The glitches: time (µs), channel and wrong value (µs), ascending in time. */
  spikeT = new Float64Array(64);
  spikeChannel = new Uint8Array(64);
  spikeUs = new Float32Array(64);
  readonly #spikes = new Rows(SPIKE_ROWS);
  /** Each channel's value now (carried into the next frame). */
  readonly #last = new Float32Array(CHANNEL_COUNT).fill(Number.NaN);
  /** Channels that have appeared, one bit each. */
  seen = 0;
  /** Counts changes, so a renderer knows to draw again. */
  version = 0;

  get length(): number {
    return this.#rows.length;
  }

  get spikes(): number {
    return this.#spikes.length;
  }

  append(b: TraceBatch): void {
    const n = b.t.length;
    if (n > 0) {
      this.#rows.room(
        n,
        this.t.length,
        (size) => this.#growRows(size),
        (drop) => this.#dropRows(drop),
      );
      // A batch larger than the buffer (never sent by the worker) keeps its newest rows.
      const skip = Math.max(0, n - TRACE_ROWS);
      const last = this.#last;
      let at = this.#rows.length;
      for (let i = skip; i < n; i++, at++) {
        const gap = b.gap[i] === 1 || (i === skip && skip > 0);
        if (gap) last.fill(Number.NaN);
        for (let c = 0; c < CHANNEL_COUNT; c++) {
          const v = b.us[i * CHANNEL_COUNT + c] ?? Number.NaN;
          if (!Number.isNaN(v)) {
            last[c] = v;
            this.seen |= 1 << c;
          }
        }
        this.t[at] = b.t[i] ?? Number.NaN;
        this.gap[at] = gap ? 1 : 0;
        this.us.set(last, at * CHANNEL_COUNT);
      }
      this.#rows.length = at;
    }
    const m = b.spikes.t.length;
    if (m > 0) {
      this.#spikes.room(
        m,
        this.spikeT.length,
        (size) => this.#growSpikes(size),
        (drop) => this.#dropSpikes(drop),
      );
      const skip = Math.max(0, m - SPIKE_ROWS);
      const at = this.#spikes.length;
      this.spikeT.set(b.spikes.t.subarray(skip), at);
      this.spikeChannel.set(b.spikes.channel.subarray(skip), at);
      this.spikeUs.set(b.spikes.us.subarray(skip), at);
      this.#spikes.length = at + m - skip;
    }
    if (n > 0 || m > 0) this.version++;
  }

  clear(): void {
    this.#rows.length = 0;
    this.#spikes.length = 0;
    this.#last.fill(Number.NaN);
    this.seen = 0;
    this.version++;
  }

  /** Index of the first frame at or after `tUs` (binary search); the same over the glitches with `spikes`. */
  indexAt(tUs: number, spikes = false): number {
    const t = spikes ? this.spikeT : this.t;
    let lo = 0;
    let hi = spikes ? this.#spikes.length : this.#rows.length;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if ((t[mid] ?? Number.POSITIVE_INFINITY) < tUs) lo = mid + 1;
      else hi = mid;
    }
    return lo;
  }

  #growRows(size: number): void {
    const t = new Float64Array(size);
    const us = new Float32Array(size * CHANNEL_COUNT);
    const gap = new Uint8Array(size);
    t.set(this.t.subarray(0, this.#rows.length));
    us.set(this.us.subarray(0, this.#rows.length * CHANNEL_COUNT));
    gap.set(this.gap.subarray(0, this.#rows.length));
    this.t = t;
    this.us = us;
    this.gap = gap;
  }

  /** Drops at least `n` of the oldest frames, and everything older than the longest window, in one step. */
  #dropRows(n: number): void {
    const len = this.#rows.length;
    const old = this.indexAt((this.t[len - 1] ?? 0) - KEEP_US);
    const drop = Math.min(len, Math.max(n, old, len >> 2));
    this.t.copyWithin(0, drop, len);
    this.us.copyWithin(0, drop * CHANNEL_COUNT, len * CHANNEL_COUNT);
    this.gap.copyWithin(0, drop, len);
    this.#rows.length = len - drop;
    // The oldest frame left starts a line: what joined it to the frames before is gone.
    if (this.#rows.length > 0) this.gap[0] = 1;
  }

  #growSpikes(size: number): void {
    const t = new Float64Array(size);
    const ch = new Uint8Array(size);
    const us = new Float32Array(size);
    t.set(this.spikeT.subarray(0, this.#spikes.length));
    ch.set(this.spikeChannel.subarray(0, this.#spikes.length));
    us.set(this.spikeUs.subarray(0, this.#spikes.length));
    this.spikeT = t;
    this.spikeChannel = ch;
    this.spikeUs = us;
  }

  #dropSpikes(n: number): void {
    const len = this.#spikes.length;
    const drop = Math.min(len, Math.max(n, len >> 2));
    this.spikeT.copyWithin(0, drop, len);
    this.spikeChannel.copyWithin(0, drop, len);
    this.spikeUs.copyWithin(0, drop, len);
    this.#spikes.length = len - drop;
  }
}

/** Room above and below the full range in each lane, as a share of the lane. */
const LANE_PAD = 0.08;

/** A value in µs as a height in lane `lane` of `lanes` (the top lane is 0): lanes stack from `lanes` down to 0. */
export function laneY(us: number, lane: number, lanes: number): number {
  return lanes - 1 - lane + LANE_PAD + ((us - PULSE_MIN_US) / (PULSE_MAX_US - PULSE_MIN_US)) * (1 - 2 * LANE_PAD);
}

/** The µs a height in lane `lane` stands for (the inverse of `laneY`). */
export function laneUs(y: number, lane: number, lanes: number): number {
  return PULSE_MIN_US + ((y - (lanes - 1 - lane) - LANE_PAD) / (1 - 2 * LANE_PAD)) * (PULSE_MAX_US - PULSE_MIN_US);
}

/**
 * What uPlot draws of the window [`startUs`, `endUs`] for `channels` (lane 0 at the top): x in
 * seconds, then each channel's heights (laneY), null where the line breaks. Where the window
 * holds more frames than twice `columns` (the plot's width in device pixels), each column shows
 * the lowest and the highest value of its frames, so that a one-frame glitch still shows as the
 * spike it is, and the cost of a redraw follows the width, not the frames.
 */
export function traceView(
  b: TraceBuffer,
  channels: readonly number[],
  startUs: number,
  endUs: number,
  columns: number,
): (number | null)[][] {
  const lanes = channels.length;
  const x: number[] = [];
  const ys: (number | null)[][] = channels.map(() => []);
  const t = b.t;
  const us = b.us;
  const gap = b.gap;
  // Each lane's channel, and the height of 903 µs and of a µs in it (laneY, worked out once).
  const ch = Int32Array.from(channels);
  const zero = new Float64Array(lanes);
  const slope = laneY(PULSE_MIN_US + 1, 0, 1) - laneY(PULSE_MIN_US, 0, 1);
  for (let k = 0; k < lanes; k++) zero[k] = laneY(PULSE_MIN_US, k, lanes);
  const height = (k: number, v: number): number | null => (Number.isNaN(v) ? null : (zero[k] as number) + (v - PULSE_MIN_US) * slope);
  const empty = (at: number) => {
    x.push(at / 1e6);
    for (let k = 0; k < lanes; k++) (ys[k] as (number | null)[]).push(null);
  };
  // From the frame before the window (the line enters it from the left) to the last in it.
  const from = Math.max(0, b.indexAt(startUs) - 1);
  const to = b.indexAt(endUs + 1e-6);
  if (to - from <= 2 * columns) {
    for (let i = from; i < to; i++) {
      // A point with no value between the frames on either side of a break.
      if (gap[i] === 1 && x.length > 0) empty(((t[i - 1] as number) + (t[i] as number)) / 2);
      x.push((t[i] as number) / 1e6);
      const row = i * CHANNEL_COUNT;
      for (let k = 0; k < lanes; k++) (ys[k] as (number | null)[]).push(height(k, us[row + (ch[k] as number)] as number));
    }
    return [x, ...ys];
  }
  const per = (endUs - startUs) / columns;
  const lo = new Float64Array(lanes);
  const hi = new Float64Array(lanes);
  let i = from;
  while (i < to) {
    const column = Math.floor(((t[i] as number) - startUs) / per);
    const colStart = startUs + column * per;
    const colEnd = colStart + per;
    if (gap[i] === 1 && x.length > 0) empty(colStart);
    lo.fill(Number.POSITIVE_INFINITY);
    hi.fill(Number.NEGATIVE_INFINITY);
    // The frames of this column, up to a break (the line stops there, and starts again after it);
    // the first always, so that every pass moves on.
    const first = i;
    for (; i < to && (i === first || ((t[i] as number) < colEnd && gap[i] !== 1)); i++) {
      const row = i * CHANNEL_COUNT;
      for (let k = 0; k < lanes; k++) {
        const v = us[row + (ch[k] as number)] as number;
        if (v < (lo[k] as number)) lo[k] = v;
        if (v > (hi[k] as number)) hi[k] = v;
      }
    }
    x.push(colStart / 1e6, (colStart + per / 2) / 1e6);
    for (let k = 0; k < lanes; k++) {
      const y = ys[k] as (number | null)[];
      const l = lo[k] as number;
      const h = hi[k] as number;
      // A lane with no value in the column (none since a break): no point.
      y.push(l === Number.POSITIVE_INFINITY ? null : height(k, l), h === Number.NEGATIVE_INFINITY ? null : height(k, h));
    }
  }
  return [x, ...ys];
}
