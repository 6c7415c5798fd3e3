/**
 * Ground truth: what a correct decoder must report for the bytes the simulator emitted.
 */
import type { Resolution } from '../decoder/spec.js';
import type { HeaderMode, RemoteKind, VtxControl } from '../decoder/types.js';

/** One channel value a frame carries. X-Plus positions are on the 2047 scale (`value9 << 2`). */
export interface TruthChannel {
  /** Channel 0–11, or 12–19 for X+1 … X+8. */
  id: number;
  pos: number;
}

/** How the line damaged a frame. A decoder should drop truncated frames; a flipped bit may pass unnoticed. */
export type FrameDamage =
  /** Bytes `removed` (indices 0–15 of the intended frame) never reached the wire; the rest keep their times. */
  | { kind: 'truncated'; removed: number[] }
  /** One bit flipped: `bytes[byte] ^= 1 << bit`. */
  | { kind: 'bit-flip'; byte: number; bit: number };

/** One frame the simulated receiver sent (whole or damaged). */
export interface TruthFrame {
  /** Sequence number among the frames sent (whole and damaged), from 0. */
  index: number;
  /** Frame slot since the start (counts slots where nothing was sent). */
  slot: number;
  /** Byte offset of the frame's first emitted byte in the stream. */
  offset: number;
  /** Bytes emitted: 16, fewer when truncated. */
  length: number;
  /** Time of the frame's first emitted byte, µs. */
  timeUs: number;
  /**
   * What the header says: 'internal' with a system byte, or 'external' (also for a clone's
   * 00 00 header, which reads as an external remote with no fades).
   */
  remote: RemoteKind;
  /** The system byte sent (may lie about the data); `null` for external remotes and 00 00 headers. */
  system: number | null;
  /** The resolution the slots are really encoded in (not what the system byte claims). */
  resolution: Resolution;
  headerMode: HeaderMode;
  /** Fade counter as sent (UINT8 internal, UINT16 external, 0 for 00 00); `null` in RSSI mode. */
  fades: number | null;
  /**
   * Fades since the previous undamaged frame, with the counter's wrap; 0 on the first
   * undamaged frame, in RSSI mode and with a 00 00 header.
   */
  fadesDelta: number;
  /** RSSI in dBm (-42 … -92, -128 after a loss) in RSSI mode, else `null`. */
  rssi: number | null;
  /** Phase bit of the first slot (2048 mode: 1 on frame A of a pair). */
  phase: 0 | 1;
  /** The channels the slots carry, in slot order (no 0xFFFF slots, no VTX slots). */
  channels: TruthChannel[];
  /** The seven slot words as intended (before damage). */
  words: number[];
  /** VTX control in slots 6–7, or `null`. */
  vtx: VtxControl | null;
  damage: FrameDamage | null;
  /** The bytes as emitted (`length` of them, after damage). */
  bytes: Uint8Array;
}

/** Random bytes the line added between frames. */
export interface TruthNoise {
  offset: number;
  length: number;
  timeUs: number;
}

/** Frame slots where the receiver sent nothing, closed by the next frame it sent. */
export interface TruthGap {
  /** Nominal time of the first silent slot. */
  startUs: number;
  /** First byte of the next frame sent. */
  endUs: number;
  /** First byte of the frame sent before the gap, `null` when the stream began with silence. */
  lastFrameUs: number | null;
  missedFrames: number;
  /** 'dropout' when any slot fell in a scenario dropout, else 'fade' (random lost frames). */
  cause: 'dropout' | 'fade';
  /** True when the silence between frames exceeded the one-second failsafe timer (§7.1). */
  failsafe: boolean;
}

/** What the simulator sent: every frame, every stretch of noise and every gap, with times. */
export interface SimTruth {
  frames: TruthFrame[];
  noise: TruthNoise[];
  gaps: TruthGap[];
}

/**
 * A frame as stored in a fixture's `*.expected.json`: `TruthFrame` with `channels` split into
 * `ids`/`positions` (the shape of `DecodedFrame`) and without `words`/`bytes` (they are in the
 * `.bin`). `timeUs` is rounded to 0.001 µs; the exact times are in the `.times.f64` file.
 */
export interface FixtureFrame {
  index: number;
  slot: number;
  offset: number;
  length: number;
  timeUs: number;
  remote: RemoteKind;
  system: number | null;
  resolution: Resolution;
  headerMode: HeaderMode;
  fades: number | null;
  fadesDelta: number;
  rssi: number | null;
  phase: 0 | 1;
  ids: number[];
  positions: number[];
  vtx: VtxControl | null;
  damage: FrameDamage | null;
}

const round3 = (x: number): number => Math.round(x * 1000) / 1000;

/** The fixture form of a frame. */
export function toFixtureFrame(f: TruthFrame): FixtureFrame {
  return {
    index: f.index,
    slot: f.slot,
    offset: f.offset,
    length: f.length,
    timeUs: round3(f.timeUs),
    remote: f.remote,
    system: f.system,
    resolution: f.resolution,
    headerMode: f.headerMode,
    fades: f.fades,
    fadesDelta: f.fadesDelta,
    rssi: f.rssi,
    phase: f.phase,
    ids: f.channels.map((c) => c.id),
    positions: f.channels.map((c) => c.pos),
    vtx: f.vtx,
    damage: f.damage,
  };
}

/** Fixture form of the noise and gap records (times rounded to 0.001 µs). */
export function toFixtureNoise(n: TruthNoise): TruthNoise {
  return { offset: n.offset, length: n.length, timeUs: round3(n.timeUs) };
}

export function toFixtureGap(g: TruthGap): TruthGap {
  return {
    startUs: round3(g.startUs),
    endUs: round3(g.endUs),
    lastFrameUs: g.lastFrameUs === null ? null : round3(g.lastFrameUs),
    missedFrames: g.missedFrames,
    cause: g.cause,
    failsafe: g.failsafe,
  };
}
