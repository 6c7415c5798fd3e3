/**
 * What the doctor keeps per port: its thresholds, one-second bins of counters over the last
 * 64 seconds, and the state its rules read (activity, packets, frames, formats, restarts).
 */
import type { Absences } from './absences.js';
import type { Resolution } from '../decoder/spec.js';
import type { BurstClock, BurstClockCheckpoint } from './burst-clock.js';
import { PACKET_KINDS, type PacketKind, type PacketScanner, type PacketScannerCheckpoint } from './doctor-line.js';
import type { ArduPilotGuess, ArduPilotGuessCheckpoint, ForeignProtocol } from './doctor-stacks.js';
import type { DoctorPortSource } from './doctor-types.js';

/** Silence after the port opened before "nothing arrives": a linked satellite sends every 11 or 22 ms, so 1 s is 45 missed frames. */
export const NOTHING_AFTER_US = 1_000_000;
/** …and after this long it is certain. */
export const NOTHING_CERTAIN_US = 3_000_000;
/** Line findings look at the last 3 one-second bins. */
export const LINE_WINDOW_BINS = 3;

/** The seconds (from `fromS` to `toS`, inclusive) the line findings at `nowUs` look at. */
export function lineWindow(nowUs: number): { fromS: number; toS: number } {
  const toS = Math.floor(nowUs / 1e6);
  return { fromS: toS - LINE_WINDOW_BINS + 1, toS };
}
/** Seconds with fades on two remotes or more, out of the seconds with fades on any, above which they fade together. */
export const TOGETHER_RATIO = 0.6;
export const TOGETHER_MIN_SECONDS = 3;
/** Clean bytes that decode as nothing are judged only after this long (a satellite locks within a few frames). */
export const UNKNOWN_AFTER_US = 1_500_000;
/** Fades in the last 10 s before a fade rate is judged. */
export const MIN_FADES = 5;
/** Frames a remote must have sent before its format counts for setup findings. */
export const SETUP_MIN_FRAMES = 20;
/** Guess decisions before predicting ArduPilot's or PX4's outcome. */
export const GUESS_MIN_DECISIONS = 3;

export const BIN_COUNT = 64;
export const M_BYTES = 0;
export const M_FRAME_BYTES = 1;
export const M_CHAR_ERRORS = 2;
export const M_BREAKS = 3;
export const M_OVERRUNS = 4;
export const M_FADES = 5;
/** The link monitor's missed frames (the receiver's count where it counts) and its lost frames (frames that did not arrive, every receiver). */
export const M_MISSED = 6;
export const M_LOST = 7;
/** What bytes are, counted while a port has shown no frame (`noSatelliteFinding`): 0x00, 0xFF, printable text. */
export const M_ZERO = 8;
export const M_FF = 9;
export const M_TEXT = 10;
export const M_PACKETS = 11; // + index in PACKET_KINDS
export const METRICS = M_PACKETS + PACKET_KINDS.length;

/** Counters in one-second bins, the last 64 seconds. */
export class Bins {
  readonly #data = new Float64Array(BIN_COUNT * METRICS);
  readonly #second = new Float64Array(BIN_COUNT).fill(NaN);
  readonly #time = new Float64Array(1);

  add(metric: number, timeUs: number, n: number): void {
    this.#time[0] = timeUs;
    this.addTo(this.#slot(), metric, n);
  }

  /**
   * The slot for the counters of frame `f` (its time's second, cleared if it held an older
   * second), or −1 when they go nowhere (no time, or older than the window): found once a frame,
   * then `addTo` for each counter. (It takes the frame, not its time: a double passed to a call
   * V8 does not inline is boxed, an allocation a frame.)
   */
  slotOf(f: { readonly timeUs: number }): number {
    this.#time[0] = f.timeUs;
    return this.#slot();
  }

  /** `slotOf` for a time that is not a frame's (not on the per-frame path). */
  slotAt(timeUs: number): number {
    this.#time[0] = timeUs;
    return this.#slot();
  }

  /** Adds `n` to `metric` in `slot` (from `slotOf`; −1: nowhere). */
  addTo(slot: number, metric: number, n: number): void {
    if (slot >= 0) this.#data[slot * METRICS + metric] = (this.#data[slot * METRICS + metric] ?? 0) + n;
  }

  /** The slot for the time in `#time[0]` (handed over there, not as an argument: see `slotOf`). */
  #slot(): number {
    const timeUs = this.#time[0] as number;
    if (!Number.isFinite(timeUs)) return -1;
    const s = Math.floor(timeUs / 1e6);
    const slot = ((s % BIN_COUNT) + BIN_COUNT) % BIN_COUNT;
    if (this.#second[slot] !== s) {
      if (s < (this.#second[slot] ?? NaN)) return -1; // older than the window
      this.#second[slot] = s;
      this.#data.fill(0, slot * METRICS, slot * METRICS + METRICS);
    }
    return slot;
  }

  /** Sum over the seconds fromS…toS (inclusive). */
  sum(metric: number, fromS: number, toS: number): number {
    let total = 0;
    for (let slot = 0; slot < BIN_COUNT; slot++) {
      const s = this.#second[slot] ?? NaN;
      if (s >= fromS && s <= toS) total += this.#data[slot * METRICS + metric] ?? 0;
    }
    return total;
  }

  /** The value of one second. */
  at(metric: number, s: number): number {
    const slot = ((s % BIN_COUNT) + BIN_COUNT) % BIN_COUNT;
    return this.#second[slot] === s ? (this.#data[slot * METRICS + metric] ?? 0) : 0;
  }

  clear(): void {
    this.#second.fill(NaN);
  }

  /** The counters and the second each slot holds, as copies (`Doctor.portCheckpoint`). */
  checkpoint(): BinsCheckpoint {
    return { data: this.#data.slice(), second: this.#second.slice() };
  }

  /** Back to where `checkpoint()` was taken; `cp` is copied, so it can be restored again. */
  restore(cp: BinsCheckpoint): void {
    this.#data.set(cp.data);
    this.#second.set(cp.second);
  }
}

/** `Bins.checkpoint()`. */
export interface BinsCheckpoint {
  readonly data: Float64Array;
  readonly second: Float64Array;
}

export interface FormatSnapshot {
  system: number | null;
  resolution: Resolution;
  remote: 'internal' | 'external';
  /** The decoder's `remoteAmbiguous`: read internal, but the header could be an external count. */
  ambiguous: boolean;
  timeUs: number;
}

export interface PortState {
  port: number;
  label: string;
  source: DoctorPortSource | null;
  openUs: number;
  baudRate: number;
  /** First byte or error since the port opened. */
  firstActivityUs: number;
  lastActivityUs: number;
  /** Bytes and errors since the port opened. */
  activity: number;
  /** Bytes ever, and the first few of them (a file's signature). */
  bytes: number;
  head: number[];
  /** The port's stream is over (`Doctor.ended`): judged on what it held, however short. */
  ended: boolean;
  /** The times its adapter went away (`Doctor.close`) until its next data. */
  away: Absences;
  /** Time of the latest data: a chunk without a time takes it. */
  lastTimeUs: number;
  bins: Bins;
  scanner: PacketScanner;
  /** Time to book the scanner's packets at (the chunk being scanned). */
  scanTimeUs: number;
  burst: BurstClock;
  /** A protocol recognised at another speed while probing, kept until a satellite shows up. */
  confirmed: { protocol: ForeignProtocol; timeUs: number; packets: number; baudRate: number } | null;
  probePackets: Record<PacketKind, number>;
  /** Foreign packets ever seen on this port, at any speed (what its bytes were once they stop). */
  packetsEver: Record<PacketKind, number>;
  // Frames
  frames: number;
  guess: ArduPilotGuess;
  xplusMask: number;
  xplusFirstUs: number;
  vtxFrames: number;
  vtxFirstUs: number;
  /** The first and the last frame's time (NaN: none, or untimed). */
  firstFrameUs: number;
  prevFrameUs: number;
  /** The link monitor's `missedFrames` and `lostFrames` at the last frame. */
  prevMissed: number;
  prevLost: number;
  /** Decoder's discarded bytes at the last frame, and the frame times that came after a discard (line damage). */
  prevDiscarded: number;
  damagedAtUs: number[];
  first: FormatSnapshot | null;
  changes: { timeUs: number; from: FormatSnapshot; to: FormatSnapshot }[];
  rssiFrames: number;
}

/**
 * `Doctor.portCheckpoint()`: a port's whole state as plain data (structured-clonable), without
 * the decoder and link monitor it reads (`source`, attached again by whoever restores).
 */
export type PortCheckpoint = Omit<PortState, 'source' | 'bins' | 'scanner' | 'burst' | 'guess'> & {
  readonly bins: BinsCheckpoint;
  readonly scanner: PacketScannerCheckpoint;
  readonly burst: BurstClockCheckpoint;
  readonly guess: ArduPilotGuessCheckpoint;
};

/**
 * The parts of a port's state that later bytes change in place (lists, counts by key), copied:
 * a checkpoint and the port restored from it never share one. The snapshots and records in the
 * lists never change once made, so the lists are copied, not their items.
 */
export function copiedParts(p: Pick<PortState, 'away' | 'head' | 'probePackets' | 'packetsEver' | 'damagedAtUs' | 'changes'>) {
  return {
    away: { ...p.away },
    head: [...p.head],
    probePackets: { ...p.probePackets },
    packetsEver: { ...p.packetsEver },
    damagedAtUs: [...p.damagedAtUs],
    changes: [...p.changes],
  };
}

/** "2.4 s" */
export const dur = (us: number): string => `${(us / 1e6).toFixed(1)} s`;
