/**
 * What the health report reads from one port: the port decoded once (`decodeCapture`, with the
 * doctor listening when one is given), summed up as it goes: frames, RSSI, the ordinary frame
 * intervals' statistics, each channel's pulse widths and its glitches (single-frame spikes, see
 * `SPIKE_MIN_JUMP_PERCENT`). Sums, not a record per frame, so a day-long capture costs the same
 * memory as a minute.
 */
import type { Capture } from '../capture/index.js';
import {
  CHANNEL_COUNT,
  channelName,
  channelResolution,
  servoToMicros,
  servoToPercent,
  type DecodedFrame,
  type DecoderStats,
  type FormatInfo,
  type LinkMonitor,
  type Resolution,
} from '../decoder/index.js';
import { decodeCapture } from './capture-pass.js';
import type { Doctor } from './doctor.js';
import {
  MAX_LISTED_GLITCHES,
  REPORT_BIN_US,
  SPIKE_MIN_JUMP_PERCENT,
  SPIKE_RETURN_PERCENT,
  SPIKE_WINDOW_FRAMES,
  SPIKE_WINDOW_US,
} from './report-thresholds.js';
import { r1 } from './report-text.js';
import type { ReportGlitch, ReportPeriodStats } from './report-types.js';

/** A growable Float64Array. */
class Column {
  data = new Float64Array(1024);
  length = 0;
  push(v: number): void {
    if (this.length === this.data.length) {
      const next = new Float64Array(this.data.length * 2);
      next.set(this.data);
      this.data = next;
    }
    this.data[this.length++] = v;
  }
  view(): Float64Array {
    return this.data.subarray(0, this.length);
  }
}

/** Distinct intervals counted by value before the tally keeps every value instead. */
const MAX_DISTINCT_INTERVALS = 4096;

/**
 * The ordinary frame intervals. Chunk-timed frames take few distinct intervals (a day of
 * DSMX 11 ms through a USB adapter: about 120), so they are counted by value and a day costs a
 * small map; past `MAX_DISTINCT_INTERVALS` values (a logic analyser's times) every value is kept.
 */
class IntervalTally {
  #counts: Map<number, number> | null = new Map();
  #column: Column | null = null;

  add(v: number): void {
    const counts = this.#counts;
    if (counts === null) {
      this.#column?.push(v);
      return;
    }
    const c = counts.get(v);
    if (c !== undefined) counts.set(v, c + 1);
    else if (counts.size < MAX_DISTINCT_INTERVALS) counts.set(v, 1);
    else {
      const column = new Column();
      for (const [value, count] of counts) for (let k = 0; k < count; k++) column.push(value);
      column.push(v);
      this.#column = column;
      this.#counts = null;
    }
  }

  /** The statistics, as over the values sorted. Null without any. */
  stats(basis: ReportPeriodStats['basis']): ReportPeriodStats | null {
    if (this.#counts === null) return periodStats(this.#column?.view().sort() ?? new Float64Array(0), null, basis);
    const values = Float64Array.from(this.#counts.keys()).sort();
    const counts = Float64Array.from(values, (v) => this.#counts?.get(v) ?? 0);
    return periodStats(values, counts, basis);
  }
}

/**
 * Statistics of sorted intervals: `values` ascending, each `counts[i]` times (once each without
 * `counts`). Sums run over the values in ascending order one by one, so counting by value gives
 * the very numbers the sorted list of every interval gives. Null without any.
 */
function periodStats(values: Float64Array, counts: Float64Array | null, basis: ReportPeriodStats['basis']): ReportPeriodStats | null {
  const countOf = (i: number): number => (counts === null ? 1 : (counts[i] ?? 0));
  let n = 0;
  for (let i = 0; i < values.length; i++) n += countOf(i);
  if (n === 0) return null;
  let sum = 0;
  for (let i = 0; i < values.length; i++) {
    const v = values[i] ?? 0;
    for (let k = countOf(i); k > 0; k--) sum += v;
  }
  const mean = sum / n;
  let sq = 0;
  for (let i = 0; i < values.length; i++) {
    const d = (values[i] ?? 0) - mean;
    for (let k = countOf(i); k > 0; k--) sq += d * d;
  }
  /** Nearest-rank percentile. */
  const percentile = (p: number): number => {
    const rank = Math.min(n - 1, Math.max(0, Math.ceil((p / 100) * n) - 1));
    let below = 0;
    for (let i = 0; i < values.length; i++) {
      below += countOf(i);
      if (rank < below) return values[i] ?? NaN;
    }
    return NaN;
  };
  return {
    intervals: n,
    meanUs: r1(mean),
    stdDevUs: r1(Math.sqrt(sq / n)),
    minUs: r1(values[0] ?? NaN),
    maxUs: r1(values[values.length - 1] ?? NaN),
    p50Us: r1(percentile(50)),
    p95Us: r1(percentile(95)),
    p99Us: r1(percentile(99)),
    basis,
  };
}

export type RawGlitch = Omit<ReportGlitch, 'timeUs'> & { absUs: number };

/** What one port's decode leaves for the report: sums, not a record per frame. */
export interface PortData {
  port: number;
  remote: ReturnType<typeof decodeCapture>;
  /** Frames seen, and the first and last one's time (µs, capture clock). */
  frames: number;
  firstUs: number;
  lastUs: number;
  /** RSSI over the frames that carried a level, and the loss reports (−128). */
  rssiFrames: number;
  rssiLoss: number;
  rssiLo: number;
  rssiHi: number;
  rssiTotal: number;
  /** The ordinary frame intervals' statistics (the link monitor's `lastIntervalUs`). */
  period: ReportPeriodStats | null;
  channelFrames: Uint32Array;
  channelMin: Float64Array;
  channelMax: Float64Array;
  channelSum: Float64Array;
  glitchesRaw: RawGlitch[];
  glitchCount: number;
  glitchFrames: number;
  formatChanges: number;
  bytes: number;
  /** Whether any frame carried a fade counter other than 0. */
  fadeCounterMoved: boolean;
  /** For `readPorts`: the decoder's reading and counters. */
  format: FormatInfo;
  stats: Readonly<DecoderStats>;
}

/** Where a port's decode starts and ends, and who else listens. */
export interface PortPass {
  originUs: number;
  endUs: number;
  doctor: Doctor | undefined;
}

/**
 * One port's sums, frame by frame: what `decodePort` keeps. A class with fields rather than a
 * closure over local variables, so that its per-frame work stays in registers and plain loads.
 */
class PortTally {
  frames = 0;
  firstUs = NaN;
  lastUs = NaN;
  rssiFrames = 0;
  rssiLoss = 0;
  rssiLo = Infinity;
  rssiHi = -Infinity;
  rssiTotal = 0;
  fadeCounterMoved = false;
  readonly intervals = new IntervalTally();
  readonly channelFrames = new Uint32Array(CHANNEL_COUNT);
  readonly channelMin = new Float64Array(CHANNEL_COUNT).fill(Infinity);
  readonly channelMax = new Float64Array(CHANNEL_COUNT).fill(-Infinity);
  readonly channelSum = new Float64Array(CHANNEL_COUNT);
  // The last two appearances of each channel: % travel, µs, time, frame index. [2·id] is the
  // older (A), [2·id + 1] the newer (B); the frame being read is C.
  readonly #pct = new Float64Array(CHANNEL_COUNT * 2);
  readonly #us = new Float64Array(CHANNEL_COUNT * 2);
  readonly #at = new Float64Array(CHANNEL_COUNT * 2);
  readonly #idx = new Float64Array(CHANNEL_COUNT * 2);
  readonly #seen = new Uint32Array(CHANNEL_COUNT);
  /** Each channel's last position and the resolution it was read at. */
  readonly #lastPos = new Float64Array(CHANNEL_COUNT).fill(-1);
  readonly #lastRes = new Uint16Array(CHANNEL_COUNT);
  readonly glitchesRaw: RawGlitch[] = [];
  glitchCount = 0;
  glitchFrames = 0;
  #lastGlitchFrame = -1;

  frame(f: DecodedFrame, link: LinkMonitor): void {
    const t = f.timeUs;
    if (this.frames === 0) this.firstUs = t;
    this.lastUs = t;
    this.frames++;
    const interval = link.lastIntervalUs;
    if (Number.isFinite(interval)) this.intervals.add(interval);
    const rs = f.rssi;
    if (rs !== null && !Number.isNaN(rs)) {
      if (rs === -128) this.rssiLoss++;
      else {
        this.rssiFrames++;
        this.rssiTotal += rs;
        if (rs < this.rssiLo) this.rssiLo = rs;
        if (rs > this.rssiHi) this.rssiHi = rs;
      }
    }
    if (f.fades !== null && f.fades !== 0) this.fadeCounterMoved = true;
    const timed = Number.isFinite(t);
    const { ids, positions } = f;
    for (let i = 0; i < f.count; i++) this.#channel(ids[i] ?? 0, positions[i] ?? 0, f.resolution, t, timed, f.index);
  }

  #channel(id: number, pos: number, linkResolution: Resolution, t: number, timed: boolean, index: number): void {
    const res = channelResolution(id, linkResolution);
    const a = 2 * id;
    const n = this.#seen[id] ?? 0;
    if (n >= 1 && pos === this.#lastPos[id] && res === this.#lastRes[id]) {
      // The value B had (about half of all appearances in a flight): the same µs and % travel,
      // already within the channel's range, and no spike, since C returns exactly to B.
      const u = this.#us[a + 1] ?? NaN;
      this.channelFrames[id] = (this.channelFrames[id] ?? 0) + 1;
      this.channelSum[id] = (this.channelSum[id] ?? 0) + u;
      this.#pct[a] = this.#pct[a + 1] ?? NaN;
      this.#us[a] = u;
      this.#at[a] = this.#at[a + 1] ?? NaN;
      this.#idx[a] = this.#idx[a + 1] ?? NaN;
      this.#at[a + 1] = t;
      this.#idx[a + 1] = index;
      this.#seen[id] = n + 1;
      return;
    }
    this.#lastPos[id] = pos;
    this.#lastRes[id] = res;
    const u = servoToMicros(pos, res);
    const p = servoToPercent(pos, res);
    this.channelFrames[id] = (this.channelFrames[id] ?? 0) + 1;
    if (u < (this.channelMin[id] ?? Infinity)) this.channelMin[id] = u;
    if (u > (this.channelMax[id] ?? -Infinity)) this.channelMax[id] = u;
    this.channelSum[id] = (this.channelSum[id] ?? 0) + u;
    const pct = this.#pct;
    const us = this.#us;
    const at = this.#at;
    const idx = this.#idx;
    if (n >= 2) {
      const pA = pct[a] ?? NaN;
      const pB = pct[a + 1] ?? NaN;
      const atA = at[a] ?? NaN;
      const up = pB - pA;
      const down = pB - p;
      const span = timed && Number.isFinite(atA) ? t - atA <= SPIKE_WINDOW_US : index - (idx[a] ?? NaN) <= SPIKE_WINDOW_FRAMES;
      if (
        span &&
        Math.abs(up) >= SPIKE_MIN_JUMP_PERCENT &&
        Math.abs(down) >= SPIKE_MIN_JUMP_PERCENT &&
        Math.sign(up) === Math.sign(down) &&
        Math.abs(p - pA) <= SPIKE_RETURN_PERCENT
      ) {
        this.glitchCount++;
        const frameIndex = idx[a + 1] ?? NaN;
        if (frameIndex !== this.#lastGlitchFrame) this.glitchFrames++;
        this.#lastGlitchFrame = frameIndex;
        if (this.glitchesRaw.length < MAX_LISTED_GLITCHES) {
          this.glitchesRaw.push({
            kind: 'spike',
            absUs: at[a + 1] ?? NaN,
            frameIndex,
            channel: id,
            name: channelName(id),
            beforeUs: us[a] ?? NaN,
            spikeUs: us[a + 1] ?? NaN,
            afterUs: u,
            jumpPercent: r1(up),
          });
        }
      }
    }
    if (n >= 1) {
      pct[a] = pct[a + 1] ?? NaN;
      us[a] = us[a + 1] ?? NaN;
      at[a] = at[a + 1] ?? NaN;
      idx[a] = idx[a + 1] ?? NaN;
    }
    pct[a + 1] = p;
    us[a + 1] = u;
    at[a + 1] = t;
    idx[a + 1] = index;
    this.#seen[id] = n + 1;
  }
}

/** Decodes one port, summing what the report needs per frame, and finds spikes as it goes. */
export function decodePort(
  capture: Capture,
  port: number,
  resolution: 'auto' | Resolution,
  resolutionFrom: 'user' | 'internal-remote',
  pass: PortPass,
): PortData {
  const tally = new PortTally();
  let formatChanges = 0;
  const remote = decodeCapture(
    capture,
    {
      port,
      resolution,
      resolutionFrom,
      binUs: REPORT_BIN_US,
      originUs: pass.originUs,
      endUs: pass.endUs,
      ...(pass.doctor !== undefined ? { doctor: pass.doctor } : {}),
      onEvent: (e) => {
        if (e.type === 'format-changed') formatChanges++;
      },
    },
    (f, link) => tally.frame(f, link),
  );
  const stats = remote.decoder.stats;
  return {
    port,
    remote,
    frames: tally.frames,
    firstUs: tally.firstUs,
    lastUs: tally.lastUs,
    rssiFrames: tally.rssiFrames,
    rssiLoss: tally.rssiLoss,
    rssiLo: tally.rssiLo,
    rssiHi: tally.rssiHi,
    rssiTotal: tally.rssiTotal,
    period: tally.intervals.stats(capture.timing === 'per-byte' ? 'per-byte' : 'per-chunk'),
    channelFrames: tally.channelFrames,
    channelMin: tally.channelMin,
    channelMax: tally.channelMax,
    channelSum: tally.channelSum,
    glitchesRaw: tally.glitchesRaw,
    glitchCount: tally.glitchCount,
    glitchFrames: tally.glitchFrames,
    formatChanges,
    bytes: stats.bytes,
    fadeCounterMoved: tally.fadeCounterMoved,
    format: remote.decoder.format,
    stats,
  };
}
