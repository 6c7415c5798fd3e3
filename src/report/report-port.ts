/**
 * What the health report reads from one port: the port decoded once (`decodeCapture`, with the
 * doctor listening when one is given), summed up as it goes: frames, RSSI, the ordinary frame
 * intervals' statistics, each channel's pulse widths and its glitches (single-frame spikes, see
 * `SPIKE_MIN_JUMP_PERCENT`). Sums, not a record per frame, so a day-long capture costs the same
 * memory as a minute.
 */
import type { AnyCapture } from '../capture/capture-windows.js';
import { CHANNEL_COUNT, channelName, channelResolution, servoToMicros, servoToPercent, type Resolution } from '../decoder/spec.js';
import type { DecodedFrame, DecoderStats, FormatInfo } from '../decoder/types.js';
import type { LinkMonitor } from '../decoder/link.js';
import { decodeCapture } from './capture-pass.js';
import type { Doctor } from './doctor.js';
import { MAX_LISTED_GLITCHES, REPORT_BIN_US, SPIKE_MIN_JUMP_PERCENT } from './report-thresholds.js';
import { isSpike } from './spikes.js';
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
/** Slots of the tally's hash table: a power of two, twice the distinct values it holds at most. */
const INTERVAL_SLOT_BITS = 13;
const INTERVAL_SLOTS = 1 << INTERVAL_SLOT_BITS;

/**
 * The ordinary frame intervals. Chunk-timed frames take few distinct intervals (a day of
 * DSMX 11 ms through a USB adapter: about 120), so they are counted by value, in an
 * open-addressing table of typed arrays (a frame costs a hash and a probe or two, and allocates
 * nothing); past `MAX_DISTINCT_INTERVALS` values (a logic analyser's times) every value is kept.
 */
class IntervalTally {
  /** The values (NaN: an empty slot) and how often each came; null once every value is kept. */
  #keys: Float64Array | null = new Float64Array(INTERVAL_SLOTS).fill(NaN);
  #counts = new Float64Array(INTERVAL_SLOTS);
  #distinct = 0;
  #column: Column | null = null;
  /**
   * An interval's 64 bits, mixed into its slot. Chunk times give intervals that differ only far
   * below the µs (1388.888888835907 and 1388.8888890743256 µs both come a million times a day),
   * so every bit counts: one probe a frame on the day capture. (Worked out in `add` itself: a
   * double passed to a call V8 does not inline is boxed.)
   */
  readonly #value = new Float64Array(1);
  readonly #bits = new Uint32Array(this.#value.buffer);

  /**
   * The link monitor's last ordinary interval, if it has one. (Read here rather than passed in:
   * a double passed to a call V8 does not inline is boxed, an allocation a frame.)
   */
  add(link: LinkMonitor): void {
    const value = link.lastIntervalUs;
    if (!Number.isFinite(value)) return;
    const keys = this.#keys;
    if (keys === null) {
      this.#column?.push(value);
      return;
    }
    const v = value + 0; // −0 counts as 0
    this.#value[0] = v;
    const bits = this.#bits;
    let slot = Math.imul((bits[0] as number) ^ Math.imul(bits[1] as number, 0x9e3779b1), 0x85ebca6b) >>> (32 - INTERVAL_SLOT_BITS);
    for (;;) {
      const k = keys[slot] as number;
      if (k === v) {
        (this.#counts[slot] as number)++;
        return;
      }
      if (Number.isNaN(k)) break; // an empty slot, so v is new
      slot = (slot + 1) & (INTERVAL_SLOTS - 1);
    }
    if (this.#distinct < MAX_DISTINCT_INTERVALS) {
      keys[slot] = v;
      this.#counts[slot] = 1;
      this.#distinct++;
    } else this.#keepEvery(keys, v);
  }

  /** Past `MAX_DISTINCT_INTERVALS`: every value kept from now on, those counted so far first. */
  #keepEvery(keys: Float64Array, v: number): void {
    const column = new Column();
    for (let i = 0; i < INTERVAL_SLOTS; i++) for (let c = this.#counts[i] ?? 0; c > 0; c--) column.push(keys[i] ?? NaN);
    column.push(v);
    this.#column = column;
    this.#keys = null;
  }

  /** The statistics, as over the values sorted. Null without any. */
  stats(basis: ReportPeriodStats['basis']): ReportPeriodStats | null {
    const keys = this.#keys;
    if (keys === null) return periodStats(this.#column?.view().sort() ?? new Float64Array(0), null, basis);
    const order: number[] = [];
    for (let i = 0; i < INTERVAL_SLOTS; i++) if (!Number.isNaN(keys[i])) order.push(i);
    order.sort((x, y) => (keys[x] ?? 0) - (keys[y] ?? 0));
    const values = Float64Array.from(order, (i) => keys[i] ?? NaN);
    const counts = Float64Array.from(order, (i) => this.#counts[i] ?? 0);
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
  /** The report's doctor: its findings are taken once, at `endUs` (`diagnosedHealthReport`). */
  doctor: Doctor | undefined;
}

/**
 * A position's µs and % travel at its resolution, looked up instead of worked out per value: at
 * `2 × key` its `servoToPercent`, at `2 × key + 1` its `servoToMicros`, the very doubles those
 * give, for every key below `VALUE_KEYS` (`valueKey`: every position 0–2047 at either
 * resolution). Made on first use.
 */
let positionValues: Float64Array | undefined;
const VALUE_KEYS = 4096;

/** A channel value as one number: its position and the resolution it is read at (1024 or 2048). */
function valueKey(position: number, resolution: Resolution): number {
  return position * 2 + (resolution === 2048 ? 0 : 1);
}

function valueTable(): Float64Array {
  if (positionValues === undefined) {
    positionValues = new Float64Array(2 * VALUE_KEYS);
    for (let pos = 0; pos < VALUE_KEYS / 2; pos++) {
      for (const res of [1024, 2048] as const) {
        const key = valueKey(pos, res);
        positionValues[2 * key] = servoToPercent(pos, res);
        positionValues[2 * key + 1] = servoToMicros(pos, res);
      }
    }
  }
  return positionValues;
}

// What `PortTally` keeps of each channel, at `id × CH_STRIDE` in one Float64Array. The spike test
// reads three consecutive appearances A, B, C of a channel (C the one being read); it can only
// pass when B is a value of its own between A and C (no repeat on either side) and
// |B − A| ≥ SPIKE_MIN_JUMP_PERCENT, which is known when B comes. So B is marked a candidate then
// (`CH_CANDIDATE`) and only a candidate keeps A's % travel, µs, time and frame index; anything
// else only moves B's. A repeat of B only counts (`CH_REPEATS`) and moves B's time and frame
// index: its µs is B's, summed when B's run ends (sums of whole µs are exact in any order).
const CH_KEY = 0; // B's `valueKey` (−1 before the first appearance)
const CH_REPEATS = 1; // appearances of B's value since B, not yet in CH_COUNT and CH_SUM
const CH_PCT_B = 2; // NaN before the first appearance, so that nothing is a jump from it
const CH_US_B = 3;
const CH_AT_B = 4;
const CH_IDX_B = 5;
const CH_CANDIDATE = 6; // 1: B came right after A and |B − A| ≥ SPIKE_MIN_JUMP_PERCENT
const CH_PCT_A = 7;
const CH_US_A = 8;
const CH_AT_A = 9;
const CH_IDX_A = 10;
const CH_COUNT = 11; // appearances, less CH_REPEATS
const CH_SUM = 12; // µs summed over those
const CH_MIN = 13;
const CH_MAX = 14;
const CH_STRIDE = 16;

/**
 * One port's sums, frame by frame: what `decodePort` keeps. A class with fields rather than a
 * closure over local variables, so that its per-frame work stays in registers and plain loads;
 * each channel's state in one typed array, and nothing allocated per frame. `channels()` gives
 * each channel's count, range and sum.
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
  readonly #ch = PortTally.#channels();
  readonly #values = valueTable();
  /** The frame being read: its time and index, for `#spike` (a double passed as an argument to a call V8 does not inline is boxed). */
  readonly #frame = new Float64Array(2);
  readonly glitchesRaw: RawGlitch[] = [];
  glitchCount = 0;
  glitchFrames = 0;
  #lastGlitchFrame = -1;

  static #channels(): Float64Array {
    const ch = new Float64Array(CHANNEL_COUNT * CH_STRIDE);
    for (let id = 0; id < CHANNEL_COUNT; id++) {
      const o = id * CH_STRIDE;
      ch[o + CH_KEY] = -1;
      ch[o + CH_PCT_B] = NaN;
      ch[o + CH_MIN] = Infinity;
      ch[o + CH_MAX] = -Infinity;
    }
    return ch;
  }

  frame(f: DecodedFrame, link: LinkMonitor): void {
    const t = f.timeUs;
    if (this.frames === 0) this.firstUs = t;
    this.lastUs = t;
    this.frames++;
    this.intervals.add(link);
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
    const { ids, positions, count, resolution, index } = f;
    const ch = this.#ch;
    const values = this.#values;
    for (let i = 0; i < count; i++) {
      const id = ids[i] as number;
      const pos = positions[i] as number;
      const key = valueKey(pos, channelResolution(id, resolution));
      const o = id * CH_STRIDE;
      if (key === ch[o + CH_KEY]) {
        // B's value again (about half of all appearances in a flight): counted when B's run
        // ends, and no spike, since C returns exactly to B.
        ch[o + CH_REPEATS] = (ch[o + CH_REPEATS] as number) + 1;
        ch[o + CH_AT_B] = t;
        ch[o + CH_IDX_B] = index;
        continue;
      }
      let p: number;
      let u: number;
      if (key < VALUE_KEYS) {
        p = values[2 * key] as number;
        u = values[2 * key + 1] as number;
      } else {
        const res = channelResolution(id, resolution);
        p = servoToPercent(pos, res);
        u = servoToMicros(pos, res);
      }
      const repeats = ch[o + CH_REPEATS] as number;
      const pB = ch[o + CH_PCT_B] as number;
      if (ch[o + CH_CANDIDATE] === 1 && repeats === 0 && Math.abs(pB - p) >= SPIKE_MIN_JUMP_PERCENT) {
        this.#frame[0] = t;
        this.#frame[1] = index;
        this.#spike(id, p, u);
      }
      const usB = ch[o + CH_US_B] as number;
      ch[o + CH_COUNT] = (ch[o + CH_COUNT] as number) + repeats + 1;
      ch[o + CH_SUM] = (ch[o + CH_SUM] as number) + (u + usB * repeats); // usB × 0 is 0: B's µs before B
      if (u < (ch[o + CH_MIN] as number)) ch[o + CH_MIN] = u;
      if (u > (ch[o + CH_MAX] as number)) ch[o + CH_MAX] = u;
      if (Math.abs(p - pB) >= SPIKE_MIN_JUMP_PERCENT) {
        // C is a jump from B (NaN before B: no jump): the next appearance may end a spike at C.
        ch[o + CH_CANDIDATE] = 1;
        ch[o + CH_PCT_A] = pB;
        ch[o + CH_US_A] = usB;
        ch[o + CH_AT_A] = ch[o + CH_AT_B] as number;
        ch[o + CH_IDX_A] = ch[o + CH_IDX_B] as number;
      } else ch[o + CH_CANDIDATE] = 0;
      ch[o + CH_KEY] = key;
      ch[o + CH_REPEATS] = 0;
      ch[o + CH_PCT_B] = p;
      ch[o + CH_US_B] = u;
      ch[o + CH_AT_B] = t;
      ch[o + CH_IDX_B] = index;
    }
  }

  /**
   * Channel `id`'s candidate B, right after A and now left for C (% travel `p`, µs `u`) by at
   * least SPIKE_MIN_JUMP_PERCENT: a spike when the rule (`isSpike`) says so.
   */
  #spike(id: number, p: number, u: number): void {
    const t = this.#frame[0] as number;
    const index = this.#frame[1] as number;
    const ch = this.#ch;
    const o = id * CH_STRIDE;
    const pA = ch[o + CH_PCT_A] as number;
    const pB = ch[o + CH_PCT_B] as number;
    if (!isSpike(pA, pB, p, ch[o + CH_AT_A] as number, t, ch[o + CH_IDX_A] as number, index)) return;
    this.glitchCount++;
    const frameIndex = ch[o + CH_IDX_B] as number;
    if (frameIndex !== this.#lastGlitchFrame) this.glitchFrames++;
    this.#lastGlitchFrame = frameIndex;
    if (this.glitchesRaw.length < MAX_LISTED_GLITCHES) {
      this.glitchesRaw.push({
        kind: 'spike',
        absUs: ch[o + CH_AT_B] as number,
        frameIndex,
        channel: id,
        name: channelName(id),
        beforeUs: ch[o + CH_US_A] as number,
        spikeUs: ch[o + CH_US_B] as number,
        afterUs: u,
        jumpPercent: r1(pB - pA),
      });
    }
  }

  /** Each channel's appearances, lowest and highest µs (±Infinity without any) and µs summed. */
  channels(): Pick<PortData, 'channelFrames' | 'channelMin' | 'channelMax' | 'channelSum'> {
    const ch = this.#ch;
    const channelFrames = new Uint32Array(CHANNEL_COUNT);
    const channelMin = new Float64Array(CHANNEL_COUNT);
    const channelMax = new Float64Array(CHANNEL_COUNT);
    const channelSum = new Float64Array(CHANNEL_COUNT);
    for (let id = 0; id < CHANNEL_COUNT; id++) {
      const o = id * CH_STRIDE;
      const repeats = ch[o + CH_REPEATS] as number;
      channelFrames[id] = (ch[o + CH_COUNT] as number) + repeats;
      channelMin[id] = ch[o + CH_MIN] as number;
      channelMax[id] = ch[o + CH_MAX] as number;
      channelSum[id] = (ch[o + CH_SUM] as number) + (repeats === 0 ? 0 : (ch[o + CH_US_B] as number) * repeats);
    }
    return { channelFrames, channelMin, channelMax, channelSum };
  }
}

/** Decodes one port, summing what the report needs per frame, and finds spikes as it goes. */
export function decodePort(
  capture: AnyCapture,
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
      ...(pass.doctor !== undefined ? { doctor: pass.doctor, doctorJudgedAtEnd: true } : {}),
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
    ...tally.channels(),
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
