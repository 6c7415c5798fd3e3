/**
 * A simulated Spektrum remote receiver: produces the byte stream a real one puts on its
 * serial line, with per-byte times, and (optionally) the ground truth a decoder must recover.
 *
 * Generation is incremental and deterministic: the same scenario (and seed) gives the same
 * bytes however the output is chunked. The bulk path (`generateInto`) allocates nothing per
 * frame when ground truth is off.
 */
import {
  CHANNEL_COUNT,
  EMPTY_SLOT,
  FAILSAFE_TIMEOUT_US,
  FRAME_SIZE,
  MASK_2048_PHASE,
  SLOTS_PER_FRAME,
  XPLUS_CHANNEL_ID,
  XPLUS_FIRST,
} from '../decoder/spec.js';
import type { VtxControl } from '../decoder/types.js';
import { LineDamage } from './damage.js';
import { SHIFT_1024_CHANID, SHIFT_2048_CHANID, SHIFT_XPLUS_SUBID, vtxControl } from './encode.js';
import { channelLayout } from './layouts.js';
import type { FrameLayout } from './layouts.js';
import { StickMotion } from './motion.js';
import { Prng, deriveSeed } from './prng.js';
import { resolveScenario } from './scenario.js';
import type { ResolvedScenario, Scenario } from './scenario.js';
import type { SimTruth, TruthChannel, TruthFrame, TruthGap, TruthNoise } from './truth.js';

/** How a `Simulator` runs beyond its scenario: whether it keeps the ground truth. */
export interface SimulatorOptions {
  /** Record ground truth (`takeTruth()`, `SimChunk.truth`). Default false: costs objects per frame. */
  truth?: boolean;
}

/** A piece of the simulated stream: bytes and the time of each byte (µs). */
export interface SimChunk {
  bytes: Uint8Array;
  timesUs: Float64Array;
  /** Ground truth for the frames, noise and gaps in this chunk; `null` when truth is off. */
  truth: SimTruth | null;
}

/** Slot codes in the compiled layout. */
const CODE_EMPTY = -1;
const CODE_XPLUS = -2;
/** RSSI sent after a lost frame (§8.3.1). */
const RSSI_LOSS = -128;
const RSSI_STRONGEST = -42;
const RSSI_WEAKEST = -92;
/** Room for one frame plus the largest noise burst. */
const UNIT_CAPACITY = 64;
/** Independent random streams, so switching one feature on leaves the others unchanged. */
const STREAM_TIMING = 1;
const STREAM_MOTION = 2;
const STREAM_FADES = 3;
const STREAM_DAMAGE = 4;
const STREAM_NOISE = 5;
const STREAM_RSSI = 6;

/**
 * A simulated remote receiver: generates its serial bytes chunk by chunk with per-byte times and
 * the ground truth (`SimTruth`) a decoder must recover. Deterministic from the scenario's seed.
 */
export class Simulator {
  /** The scenario with defaults filled in. */
  readonly scenario: ResolvedScenario;
  /** The frame shapes in use (one, or a pair sent alternately). */
  readonly layout: readonly FrameLayout[];

  private readonly truthOn: boolean;
  private readonly codes: Int8Array[];
  private readonly rngTiming: Prng;
  private readonly motion: StickMotion;
  private readonly rngFades: Prng;
  private readonly lineDamage: LineDamage;
  private readonly rngNoise: Prng;
  private readonly rngRssi: Prng;

  private slot = 0;
  private fades: number;
  private readonly fadeMask: number;
  private rssiLevel: number;
  private rssiLost = false;
  private xplusCursor = 0;
  private vtxKey = -1;
  private vtxRemaining = 0;
  private vtxBursts = 0;
  private vtxCurrent: VtxControl | null = null;

  // The unit being handed out: one frame (maybe damaged) and/or a noise burst.
  private readonly unitBytes = new Uint8Array(UNIT_CAPACITY);
  private readonly unitTimes = new Float64Array(UNIT_CAPACITY);
  private unitLen = 0;
  private unitPos = 0;

  private readonly words = new Uint16Array(SLOTS_PER_FRAME);
  private readonly frame = new Uint8Array(FRAME_SIZE);
  private readonly frameTimes = new Float64Array(FRAME_SIZE);

  private produced = 0;
  private framesSent = 0;
  private lostRun = 0;
  private gapStartUs = 0;
  private gapDropout = false;
  private lastFrameUs: number | null = null;
  private prevGoodFades: number | null = null;

  private truthFrames: TruthFrame[] = [];
  private truthNoise: TruthNoise[] = [];
  private truthGaps: TruthGap[] = [];

  /** @throws TypeError on an invalid scenario. */
  constructor(scenario: Scenario, options: SimulatorOptions = {}) {
    const s = resolveScenario(scenario);
    this.scenario = s;
    this.truthOn = options.truth ?? false;
    this.layout = channelLayout(s.resolution, s.periodMs, s.channels, s.xplus.channels > 0);
    this.codes = this.layout.map((f) => {
      const c = new Int8Array(SLOTS_PER_FRAME);
      f.slots.forEach((x, i) => {
        c[i] = x === 'xplus' ? CODE_XPLUS : x === 'empty' ? CODE_EMPTY : x;
      });
      return c;
    });
    this.rngTiming = new Prng(deriveSeed(s.seed, STREAM_TIMING));
    this.motion = new StickMotion(s.motion, new Prng(deriveSeed(s.seed, STREAM_MOTION)));
    this.rngFades = new Prng(deriveSeed(s.seed, STREAM_FADES));
    this.lineDamage = new LineDamage(s.damage, new Prng(deriveSeed(s.seed, STREAM_DAMAGE)), this.truthOn);
    this.rngNoise = new Prng(deriveSeed(s.seed, STREAM_NOISE));
    this.rngRssi = new Prng(deriveSeed(s.seed, STREAM_RSSI));
    this.fades = s.fades.start;
    this.fadeMask = s.remote === 'internal' ? 0xff : 0xffff;
    this.rssiLevel = s.rssi.meanDbm;
  }

  /** Nominal time of the next frame slot, µs: everything before it has been generated. */
  get nextSlotUs(): number {
    return this.scenario.timing.startUs + this.slot * this.scenario.periodUs;
  }

  /** Bytes generated so far (including any not yet handed out by a full `generateInto`). */
  get bytesGenerated(): number {
    return this.produced;
  }

  /** Frames sent so far (whole and damaged). */
  get framesGenerated(): number {
    return this.framesSent;
  }

  /**
   * Fills `bytes` (and `timesUs`, if given) from index `start` with the stream up to `untilUs`:
   * every frame slot whose nominal time is before `untilUs` (a frame's last bytes may fall a
   * little after it). Stops early when the arrays are full; the rest follows on the next call.
   * Returns the number of bytes written. Allocates nothing per frame when truth is off.
   */
  generateInto(bytes: Uint8Array, timesUs: Float64Array | null, untilUs: number, start = 0): number {
    if (Number.isNaN(untilUs)) throw new TypeError('untilUs is NaN');
    if (!Number.isInteger(start) || start < 0) throw new RangeError(`start must be a non-negative integer, got ${start}`);
    const cap = timesUs ? Math.min(bytes.length, timesUs.length) : bytes.length;
    let n = start;
    if (n >= cap) return 0;
    for (;;) {
      if (this.unitPos < this.unitLen) {
        const end = Math.min(this.unitLen, this.unitPos + (cap - n));
        for (let i = this.unitPos; i < end; i++, n++) {
          bytes[n] = this.unitBytes[i]!;
          if (timesUs) timesUs[n] = this.unitTimes[i]!;
        }
        this.unitPos = end;
        if (end < this.unitLen) return n - start;
      }
      if (this.nextSlotUs >= untilUs) return n - start;
      this.step();
    }
  }

  /**
   * The stream up to `untilUs` (see `generateInto`), in new arrays, with its ground truth.
   * Times are on the simulator's clock, which starts at `scenario.timing.startUs`; a live demo
   * either sets `timing.startUs` to its own clock's start or adds an offset.
   */
  generate(untilUs: number): SimChunk {
    if (!Number.isFinite(untilUs)) throw new RangeError('generate() needs a finite untilUs');
    const s = this.scenario;
    const slots = Math.max(0, Math.ceil((untilUs - this.nextSlotUs) / s.periodUs));
    const perSlot = FRAME_SIZE + (s.damage.noiseRate > 0 ? s.damage.noiseMaxBytes : 0);
    const cap = this.unitLen - this.unitPos + slots * perSlot;
    const bytes = new Uint8Array(cap);
    const timesUs = new Float64Array(cap);
    const n = this.generateInto(bytes, timesUs, untilUs);
    return {
      bytes: n === cap ? bytes : bytes.subarray(0, n),
      timesUs: n === cap ? timesUs : timesUs.subarray(0, n),
      truth: this.truthOn ? this.takeTruth() : null,
    };
  }

  /** The next `durationUs` of stream (from `nextSlotUs`). */
  generateFor(durationUs: number): SimChunk {
    return this.generate(this.nextSlotUs + durationUs);
  }

  /** Chunks of `chunkUs` each, until `endUs` (forever by default: the web demo's loop). */
  *chunks(chunkUs: number, endUs = Infinity): Generator<SimChunk, void, undefined> {
    if (!(chunkUs > 0) || !Number.isFinite(chunkUs)) throw new RangeError('chunkUs must be a positive number');
    let t = this.nextSlotUs;
    while (t < endUs) {
      t = Math.min(t + chunkUs, endUs);
      yield this.generate(t);
    }
  }

  /**
   * Holds channel `id` (0–19) at `percent` travel (±100 % is the normal stick range, ±150 % the
   * full one) from the next frame on, instead of its scenario motion; null gives the motion back.
   */
  setChannel(id: number, percent: number | null): void {
    checkChannelId(id);
    if (percent !== null && !Number.isFinite(percent)) throw new RangeError(`percent must be a finite number, got ${percent}`);
    this.motion.override(id, percent);
  }

  /** Keeps channel `id` (0–19) at or below `percent` travel from the next frame on, however it moves; null lifts it. */
  setCeiling(id: number, percent: number | null): void {
    checkChannelId(id);
    if (percent !== null && !Number.isFinite(percent)) throw new RangeError(`percent must be a finite number, got ${percent}`);
    this.motion.ceiling(id, percent);
  }

  /** Ground truth recorded since the last call (empty when truth is off). */
  takeTruth(): SimTruth {
    const t: SimTruth = { frames: this.truthFrames, noise: this.truthNoise, gaps: this.truthGaps };
    this.truthFrames = [];
    this.truthNoise = [];
    this.truthGaps = [];
    return t;
  }

  // ---------------------------------------------------------------------------------------

  private inWindow(atUs: number, durationUs: number, t: number): boolean {
    return t >= atUs && t < atUs + durationUs;
  }

  /** One frame slot: maybe a frame, maybe silence, maybe line noise. */
  private step(): void {
    const s = this.scenario;
    const k = this.slot++;
    const nominal = s.timing.startUs + k * s.periodUs;
    const tau = k * s.periodUs;
    const cyc = s.cycleUs !== null ? tau % s.cycleUs : tau;
    const cycleNo = s.cycleUs !== null ? Math.floor(tau / s.cycleUs) : 0;
    this.unitLen = 0;
    this.unitPos = 0;

    this.motion.advance();
    if (s.headerMode === 'rssi') {
      // A slow swing (near and far) plus a mean-reverting random walk, clamped to §8.3.1's range.
      const target = s.rssi.meanDbm + s.rssi.swingDb * Math.sin((2 * Math.PI * tau) / s.rssi.swingPeriodUs);
      const r = this.rssiLevel + 0.05 * (target - this.rssiLevel) + s.rssi.stepDb * this.rngRssi.gauss();
      this.rssiLevel = r > RSSI_STRONGEST ? RSSI_STRONGEST : r < RSSI_WEAKEST ? RSSI_WEAKEST : r;
    }

    const frameNo = this.codes.length === 2 ? k & 1 : 0;
    const layout = this.layout[frameNo]!;
    const codes = this.codes[frameNo]!;

    // X-Plus rotates through its channels, one per frame, whether or not the frame arrives.
    let xplusChannel = -1;
    const xw = s.xplus.window;
    if (s.xplus.channels > 0 && (!xw || this.inWindow(xw.atUs, xw.durationUs, cyc))) {
      xplusChannel = XPLUS_FIRST + (this.xplusCursor++ % s.xplus.channels);
    }

    // VTX bursts.
    const vtx = s.vtx;
    if (vtx && cyc >= vtx.firstUs) {
      const key = cycleNo * 1e9 + Math.floor((cyc - vtx.firstUs) / vtx.everyUs);
      if (key !== this.vtxKey) {
        this.vtxKey = key;
        this.vtxRemaining = vtx.burst;
        this.vtxCurrent = vtxControl(vtx.settings[this.vtxBursts++ % vtx.settings.length]!);
      }
    }

    // Silence: a scenario dropout or a random lost frame.
    let dropout = false;
    for (const w of s.dropouts) {
      if (this.inWindow(w.atUs, w.durationUs, cyc)) {
        dropout = true;
        break;
      }
    }
    if (dropout || this.rngFades.chance(s.fades.lossRate)) {
      this.fades++;
      this.rssiLost = true;
      if (this.lostRun++ === 0) {
        this.gapStartUs = nominal;
        this.gapDropout = false;
      }
      if (dropout) this.gapDropout = true;
      this.noise(nominal);
      return;
    }
    if (this.rngFades.chance(s.fades.randomRate)) this.fades++;

    // Slots.
    const words = this.words;
    const res = s.resolution;
    const useVtx = this.vtxRemaining > 0 && layout.phase === 0 && this.vtxCurrent !== null;
    const channels: TruthChannel[] | null = this.truthOn ? [] : null;
    for (let i = 0; i < SLOTS_PER_FRAME; i++) {
      if (useVtx && i >= SLOTS_PER_FRAME - 2) {
        const raw = this.vtxCurrent!.raw;
        words[i] = i === SLOTS_PER_FRAME - 2 ? raw >>> 16 : raw & 0xffff;
        continue;
      }
      const code = codes[i]!;
      if (code >= 0) {
        const pos = this.motion.position(code, tau, res);
        words[i] =
          res === 1024
            ? (code << SHIFT_1024_CHANID) | pos
            : (i === 0 && layout.phase ? MASK_2048_PHASE : 0) | (code << SHIFT_2048_CHANID) | pos;
        channels?.push({ id: code, pos });
      } else if (code === CODE_XPLUS && xplusChannel >= 0) {
        const v9 = this.motion.position(xplusChannel, tau, 2048) >> 2;
        const sub = (xplusChannel - XPLUS_FIRST) & 3;
        words[i] =
          (xplusChannel - XPLUS_FIRST >= 4 ? MASK_2048_PHASE : 0) |
          (XPLUS_CHANNEL_ID << SHIFT_2048_CHANID) |
          (sub << SHIFT_XPLUS_SUBID) |
          v9;
        channels?.push({ id: xplusChannel, pos: v9 << 2 });
      } else {
        words[i] = EMPTY_SLOT;
      }
    }
    const vtxSent = useVtx ? this.vtxCurrent : null;
    if (useVtx) this.vtxRemaining--;

    // Header.
    const f = this.frame;
    let fadesOut: number | null = null;
    let rssiOut: number | null = null;
    if (s.header === 'zero') {
      f[0] = 0;
      f[1] = 0;
      fadesOut = 0;
    } else if (s.remote === 'external') {
      fadesOut = this.fades & 0xffff;
      f[0] = fadesOut >> 8;
      f[1] = fadesOut & 0xff;
    } else {
      if (s.headerMode === 'rssi') {
        rssiOut = this.rssiLost ? RSSI_LOSS : Math.round(this.rssiLevel);
        f[0] = rssiOut & 0xff;
      } else {
        fadesOut = this.fades & 0xff;
        f[0] = fadesOut;
      }
      f[1] = s.systemByte!;
    }
    this.rssiLost = false;
    for (let i = 0; i < SLOTS_PER_FRAME; i++) {
      f[2 + 2 * i] = words[i]! >> 8;
      f[3 + 2 * i] = words[i]! & 0xff;
    }

    // Times.
    const bt = s.timing.byteTimeUs;
    const bj = s.timing.byteJitterUs;
    const t0 = nominal + s.timing.frameJitterUs * (2 * this.rngTiming.next() - 1);
    for (let i = 0; i < FRAME_SIZE; i++) {
      this.frameTimes[i] = t0 + i * bt + (bj > 0 ? bj * (2 * this.rngTiming.next() - 1) : 0);
    }

    // Line damage.
    const damage = this.lineDamage.apply(f, this.framesSent === 0);
    const removed = this.lineDamage.removed;
    const damaged = this.lineDamage.removedCount > 0 || damage !== null;

    // Emit.
    const offset = this.produced;
    let len = 0;
    for (let i = 0; i < FRAME_SIZE; i++) {
      if (removed[i]) continue;
      this.unitBytes[len] = f[i]!;
      this.unitTimes[len] = this.frameTimes[i]!;
      len++;
    }
    this.unitLen = len;
    this.produced += len;
    const timeUs = this.unitTimes[0]!;

    if (this.truthOn) {
      if (this.lostRun > 0) {
        this.truthGaps.push({
          startUs: this.gapStartUs,
          endUs: timeUs,
          lastFrameUs: this.lastFrameUs,
          missedFrames: this.lostRun,
          cause: this.gapDropout ? 'dropout' : 'fade',
          failsafe: this.lastFrameUs !== null && timeUs - this.lastFrameUs > FAILSAFE_TIMEOUT_US,
        });
      }
      let fadesDelta = 0;
      if (!damaged && fadesOut !== null) {
        if (this.prevGoodFades !== null) fadesDelta = (fadesOut - this.prevGoodFades) & this.fadeMask;
        this.prevGoodFades = fadesOut;
      }
      const internal = s.header === 'spec' && s.remote === 'internal';
      this.truthFrames.push({
        index: this.framesSent,
        slot: k,
        offset,
        length: len,
        timeUs,
        remote: internal ? 'internal' : 'external',
        system: internal ? s.systemByte : null,
        resolution: res,
        headerMode: s.headerMode,
        fades: fadesOut,
        fadesDelta: s.header === 'zero' ? 0 : fadesDelta,
        rssi: rssiOut,
        phase: layout.phase,
        channels: channels!,
        words: Array.from(words),
        vtx: vtxSent ? { ...vtxSent } : null,
        damage,
        bytes: this.unitBytes.slice(0, len),
      });
    }
    this.lostRun = 0;
    this.lastFrameUs = timeUs;
    this.framesSent++;
    this.noise(nominal);
  }

  /** Maybe a burst of random bytes in the idle gap after slot time `nominal`. */
  private noise(nominal: number): void {
    const s = this.scenario;
    const d = s.damage;
    if (!this.rngNoise.chance(d.noiseRate)) return;
    const n = 1 + this.rngNoise.int(d.noiseMaxBytes);
    const bt = s.timing.byteTimeUs;
    const j = s.timing.frameJitterUs;
    const lo = nominal + j + FRAME_SIZE * bt + 500;
    const hi = nominal + s.periodUs - j - 500 - n * bt;
    const t0 = this.rngNoise.uniform(lo, hi);
    const offset = this.produced;
    for (let i = 0; i < n; i++) {
      this.unitBytes[this.unitLen] = this.rngNoise.int(256);
      this.unitTimes[this.unitLen] = t0 + i * bt;
      this.unitLen++;
    }
    this.produced += n;
    if (this.truthOn) this.truthNoise.push({ offset, length: n, timeUs: t0 });
  }
}

function checkChannelId(id: number): void {
  if (!Number.isInteger(id) || id < 0 || id >= CHANNEL_COUNT)
    throw new RangeError(`channel id must be an integer 0–${CHANNEL_COUNT - 1}, got ${id}`);
}

/**
 * Runs `scenario` for `durationUs` (default: the scenario's `durationUs`) from its first slot
 * and returns the whole stream.
 */
export function simulate(scenario: Scenario, durationUs?: number, options: SimulatorOptions = {}): SimChunk {
  const sim = new Simulator(scenario, options);
  const d = durationUs ?? sim.scenario.durationUs;
  return sim.generate(sim.scenario.timing.startUs + d);
}
