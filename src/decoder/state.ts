/**
 * Everything a decoder has decided, in one record: the options it runs under, the lock, the
 * format, the last frame's header, the slot layouts seen, the staged next frame and the
 * counters. Reset is a fresh record, a checkpoint a copy, a restore a copy back. What the
 * bytes are and when they came is the window's (byte-window.ts); the two make the `Core` the
 * acquisition and the locked path work on.
 */
import { copySlots, FrameSlots, INVALID } from './frame.js';
import type { ByteWindow } from './byte-window.js';
import { B0_FADES } from './header.js';
import type { Resolution } from './spec.js';
import type { DecodedFrame, DecoderEvent, DecoderStats, RemoteKind, ResolutionReason, Withheld } from './types.js';

/** Slot layouts remembered (a transmitter uses two to four). */
const LAYOUT_MEMORY = 16;

export interface DecoderState {
  /** The options in force (`setResolution` changes the resolution) and who fixed the resolution. */
  opts: { resolution: 'auto' | Resolution; remote: 'auto' | RemoteKind; headerMode: 'auto' | 'fades' | 'rssi' };
  fixedBy: 'user' | 'internal-remote';
  locked: boolean;
  everLocked: boolean;
  /** Stream offset up to which acquisition has confirmed frames: they are emitted as they stand. */
  confirmedUntil: number;
  /** The lock's resolution and remote kind (the last ones locked on; `format` shows null until `everLocked`). */
  resolution: Resolution;
  reason: ResolutionReason;
  remote: RemoteKind;
  /** The internal remote's system byte (valid or not), or null. */
  system: number | null;
  /** B0_*: how byte 0 of an internal remote is read. */
  b0Mode: number;
  /** The resolution the bytes fit when a forced one fits nothing, else null. */
  forcedMismatch: Resolution | null;
  /** Why bytes that read as frames give none, until a lock (`format.withheld`). */
  withheld: Withheld | null;
  /** The internal reading may be an external count whose low byte is a §8.3 system byte (`format.remoteAmbiguous`). */
  ambiguous: boolean;
  /**
   * Byte shifts (bit j: the frames start j bytes later, 1–15) at which an external remote's
   * stream reads as well as the lock's reading (`format.alignmentUnproven`, acquire.ts's
   * `shiftedReadings`); 0 when the alignment is proven. `altLast[j]`: the header the reading
   * at shift j read in the last frame weighed, -1 when none is to be judged against.
   */
  alignAlts: number;
  altLast: Int32Array;
  /** Header bytes of the last emitted frame (for deltas and continuity), valid when `haveLast`. */
  last0: number;
  last1: number;
  haveLast: boolean;
  /** Stream offset where the last emitted frame ends. */
  lastEnd: number;
  /** Whether a fade jump at the first frame after a lock is the receiver's own count (same remote, known layouts). */
  jumpTrusted: boolean;
  /**
   * Stream offset below which no start scored at the last acquisition pass (nothing chained,
   * nothing parsed as filler), with every option 'auto': the next pass, under the same state,
   * does not score those starts again (acquire.ts). 0: none.
   */
  noStartBelow: number;
  /** Slot layouts seen, a ring of LAYOUT_MEMORY. */
  layouts: Int32Array;
  layoutCount: number;
  layoutNext: number;
  /**
   * Two sets of slot arrays: the one the frame shows, and one holding the frame at stream offset
   * `stagedAt` (-1: none), read while confirming the frame before it, with its layout
   * `stagedLayout`; a staged frame continues the last frame emitted. Emitting it swaps the sets
   * instead of reading it again.
   */
  shown: FrameSlots;
  staged: FrameSlots;
  stagedAt: number;
  stagedLayout: number;
  stats: DecoderStats;
}

export function initialState(opts: DecoderState['opts'], fixedBy: DecoderState['fixedBy']): DecoderState {
  return {
    opts: { ...opts },
    fixedBy,
    locked: false,
    everLocked: false,
    confirmedUntil: 0,
    resolution: 2048,
    reason: 'unknown',
    remote: 'external',
    system: null,
    b0Mode: B0_FADES,
    forcedMismatch: null,
    withheld: null,
    ambiguous: false,
    alignAlts: 0,
    altLast: new Int32Array(16).fill(-1),
    last0: 0,
    last1: 0,
    haveLast: false,
    lastEnd: -1,
    jumpTrusted: false,
    noStartBelow: 0,
    layouts: new Int32Array(LAYOUT_MEMORY),
    layoutCount: 0,
    layoutNext: 0,
    shown: new FrameSlots(),
    staged: new FrameSlots(),
    stagedAt: -1,
    stagedLayout: INVALID,
    stats: {
      bytes: 0,
      frames: 0,
      frameBytes: 0,
      discardedBytes: 0,
      pendingBytes: 0,
      resyncs: 0,
      badFrames: 0,
      emptySlots: 0,
      vtxFrames: 0,
      fadeJumps: 0,
    },
  };
}

/** A copy of `s` that shares nothing with it (`s` may be a structured clone: its slot sets are read field by field). */
export function copyState(s: Readonly<DecoderState>): DecoderState {
  return {
    ...s,
    opts: { ...s.opts },
    layouts: s.layouts.slice(),
    altLast: s.altLast.slice(),
    shown: copySlots(s.shown),
    staged: copySlots(s.staged),
    stats: { ...s.stats },
  };
}

/**
 * Where acquisition picks the chain it locks on (acquire.ts): the best chain's header reading
 * and length, and the best score of a chain that starts without channels. Rewritten before
 * every read, so not state.
 */
export interface Chain {
  internal: boolean;
  system: number;
  b0: number;
  frames: number;
  /** Index in the chain of a frame with a damaged header, skipped over (not confirmed), or -1. */
  skipped: number;
  fillerScore: number;
  /**
   * A start was refused as an internal stream read late (`readsInternalLate`), which looks at
   * the frame before it: once those bytes go, the same start may read otherwise.
   */
  lateRefused: boolean;
}

/** A decoder's parts as its two paths see them. */
export interface Core {
  readonly w: ByteWindow;
  s: DecoderState;
  /** The borrowed frame `next()` hands out. */
  readonly frame: DecodedFrame;
  readonly chain: Chain;
  readonly onEvent: ((event: DecoderEvent) => void) | undefined;
}

export function createChain(): Chain {
  return { internal: false, system: 0, b0: B0_FADES, frames: 0, skipped: -1, fillerScore: -1, lateRefused: false };
}

type EventBody = DecoderEvent extends infer E ? (E extends DecoderEvent ? Omit<E, 'timeUs' | 'bytes'> : never) : never;

/**
 * Hands `event` to `onEvent` with its time (that of the byte at its offset, dated as a frame's
 * first byte is) and, for a discard, a view of its bytes (borrowed: valid during the call).
 * The byte at the offset is still held (events come before their bytes are dropped), or has
 * not arrived yet (NaN).
 */
export function event(d: Core, body: EventBody): void {
  const onEvent = d.onEvent;
  if (onEvent === undefined) return;
  const w = d.w;
  w.dateAny(body.offset);
  const timeUs = w.when[0] ?? Number.NaN;
  if (body.type === 'discarded') {
    const o = body.offset - w.base;
    onEvent({ ...body, timeUs, bytes: w.buf.subarray(o, o + body.length) });
  } else onEvent({ ...body, timeUs });
}

/** Discards `length` bytes from buffer index `o` (counted, and told as an event). */
export function discard(d: Core, o: number, length: number, reason: 'before-lock' | 'noise' | 'truncated-frame' | 'end-of-stream'): void {
  const stats = d.s.stats;
  stats.discardedBytes += length;
  stats.pendingBytes -= length;
  // Before the chunk records go: the event is timed by them.
  event(d, { type: 'discarded', offset: d.w.base + o, length, reason });
  d.w.consumeTo(o + length);
}

/** Lets the lock go: the next pass acquires. */
export function unlock(s: DecoderState): void {
  s.locked = false;
  s.confirmedUntil = 0;
  s.stagedAt = -1;
}

export function knownLayout(s: DecoderState, layout: number): boolean {
  const layouts = s.layouts;
  for (let i = 0; i < s.layoutCount; i++) if (layouts[i] === layout) return true;
  return false;
}

export function learnLayout(s: DecoderState, layout: number): void {
  if (knownLayout(s, layout)) return;
  s.layouts[s.layoutNext] = layout;
  s.layoutNext = (s.layoutNext + 1) % LAYOUT_MEMORY;
  if (s.layoutCount < LAYOUT_MEMORY) s.layoutCount++;
}
