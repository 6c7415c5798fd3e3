/**
 * Which channel goes in which slot, as real transmitters send them (§8.5: the transmitter
 * decides, and a decoder must read the ID of every slot in every frame).
 *
 * - 11 ms modes always send frame pairs; so do 22 ms modes with more than 7 channels.
 *   The two frames of a pair differ; in 2048 mode the first slot of frame A has its phase
 *   bit set, frame B's does not. The tables follow the PX4 captures (see
 *   /work/shared/captures/README.md): 10 channels `1p 5 2 3 0 7 6` / `1 5 2 3 4 8 9`,
 *   DX9 12 + X-Plus `0p 7 3 8 9 11 X` / `1 5 2 4 6 10 X`.
 * - 22 ms modes with up to 7 channels send one frame shape, IDs ascending, phase bit clear.
 * - Unused slots hold 0xFFFF. X-Plus (2048 only) takes the 7th slot of each frame and
 *   rotates through the active X-Plus channels frame by frame; when X-Plus is off that slot
 *   is 0xFFFF.
 */
import { SLOTS_PER_FRAME } from '../decoder/spec.js';
import type { Resolution } from '../decoder/spec.js';

/** What one slot of a frame carries: a channel ID 0–11, the rotating X-Plus channel, or 0xFFFF. */
export type LayoutSlot = number | 'xplus' | 'empty';

export interface FrameLayout {
  /** The phase bit of the first slot (always 0 in 1024 mode and in single-frame layouts). */
  readonly phase: 0 | 1;
  /** Seven entries. */
  readonly slots: readonly LayoutSlot[];
}

const X = 'xplus' as const;
const E = 'empty' as const;

/** 11 ms order for up to 7 channels (both frames of the pair alike), from the 10-channel capture. */
const SMALL_ORDER = [1, 5, 2, 3, 0, 4, 6];

/** Pair tables for 8–12 channels. */
const PAIRS: Readonly<Record<number, readonly [readonly LayoutSlot[], readonly LayoutSlot[]]>> = {
  8: [
    [1, 5, 2, 3, 0, 7, 6],
    [1, 5, 2, 3, 4, E, E],
  ],
  9: [
    [1, 5, 2, 3, 0, 7, 6],
    [1, 5, 2, 3, 4, 8, E],
  ],
  10: [
    [1, 5, 2, 3, 0, 7, 6],
    [1, 5, 2, 3, 4, 8, 9],
  ],
  11: [
    [0, 7, 3, 8, 9, E, X],
    [1, 5, 2, 4, 6, 10, X],
  ],
  12: [
    [0, 7, 3, 8, 9, 11, X],
    [1, 5, 2, 4, 6, 10, X],
  ],
};

function withXPlus(slots: readonly LayoutSlot[], xplus: boolean): LayoutSlot[] {
  // The X-Plus slot is the 7th; without X-Plus it is filler.
  return slots.map((s) => (s === X ? (xplus ? X : E) : s));
}

/**
 * The frame shapes a transmitter sends for `channels` ordinary channels (1–12): one shape
 * (every frame alike) or two (frames alternate A, B, A, B …). `xplus` reserves the 7th slot of
 * each frame for X-Plus; it needs 2048 mode and a free 7th slot (1–6, 11 or 12 channels).
 *
 * @throws RangeError when the combination does not exist.
 */
export function channelLayout(resolution: Resolution, periodMs: 11 | 22, channels: number, xplus = false): FrameLayout[] {
  if (!Number.isInteger(channels) || channels < 1 || channels > 12) {
    throw new RangeError(`channels must be 1–12, got ${channels}`);
  }
  if (xplus && resolution !== 2048) throw new RangeError('X-Plus exists only in 2048 mode (§8.6)');
  if (xplus && channels > 6 && channels < 11) {
    throw new RangeError(`X-Plus needs the 7th slot, which a ${channels}-channel layout uses`);
  }
  const pairPhase: 0 | 1 = resolution === 2048 ? 1 : 0;
  if (channels <= 7) {
    if (periodMs === 22) {
      const slots: LayoutSlot[] = [];
      for (let id = 0; id < channels; id++) slots.push(id);
      while (slots.length < SLOTS_PER_FRAME - 1) slots.push(E);
      if (slots.length < SLOTS_PER_FRAME) slots.push(xplus ? X : E);
      return [{ phase: 0, slots }];
    }
    const slots: LayoutSlot[] = SMALL_ORDER.filter((id) => id < channels);
    while (slots.length < SLOTS_PER_FRAME - 1) slots.push(E);
    if (slots.length < SLOTS_PER_FRAME) slots.push(xplus ? X : E);
    return [
      { phase: pairPhase, slots },
      { phase: 0, slots: slots.slice() },
    ];
  }
  const pair = PAIRS[channels]!;
  return [
    { phase: pairPhase, slots: withXPlus(pair[0], xplus) },
    { phase: 0, slots: withXPlus(pair[1], xplus) },
  ];
}

/** A layout in the captures README's notation, e.g. `1p 5 2 3 0 7 6 / 1 5 2 3 4 8 9`. */
export function describeLayout(layout: readonly FrameLayout[]): string {
  return layout
    .map((f) => f.slots.map((s, i) => (s === X ? 'X' : s === E ? '--' : String(s)) + (i === 0 && f.phase ? 'p' : '')).join(' '))
    .join(' / ');
}
