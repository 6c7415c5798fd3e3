/**
 * Reading one 16-byte frame: slot validation (used to find frames without a sync byte) and
 * filling the reusable `DecodedFrame`. Pure functions over a byte array and an offset.
 */
import {
  EMPTY_SLOT,
  MASK_1024_SXPOS,
  MASK_2048_PHASE,
  MASK_2048_SXPOS,
  MAX_NORMAL_CHANNEL,
  SLOTS_PER_FRAME,
  XPLUS_CHANNEL_ID,
  XPLUS_FIRST,
  type Resolution,
} from './spec.js';
import type { DecodedFrame, VtxControl } from './types.js';

/** Slot codes inside a layout: 0–11 a channel ID, then these. */
const CODE_XPLUS = 12;
const CODE_EMPTY = 13;
const CODE_VTX = 14;
const CODE_BITS = 4;
/** Bit 28 of a layout: the phase bit of the first slot (frames of a pair differ there). */
const LAYOUT_PHASE_BIT = 1 << 28;

/**
 * A slot's channel and layout code depend on its high byte alone (the ID bits, and for X-Plus
 * the two extra ID bits and the phase bit, all lie in bits 15–9), so each resolution has a
 * table: the channel 0–19 the high byte names, or -1 for an impossible ID (§8.5, §8.6), and its
 * code in a layout. 0xFFFF (both bytes) is an empty slot and is tested before the table.
 */
const CHANNEL_2048 = new Int8Array(256);
const CODE_2048 = new Int8Array(256);
const CHANNEL_1024 = new Int8Array(256);
const CODE_1024 = new Int8Array(256);
for (let hi = 0; hi < 256; hi++) {
  const word = hi << 8;
  const id = (word >> 11) & 0x0f;
  if (id <= MAX_NORMAL_CHANNEL) {
    CHANNEL_2048[hi] = id;
    CODE_2048[hi] = id;
  } else if (id === XPLUS_CHANNEL_ID) {
    CHANNEL_2048[hi] = XPLUS_FIRST + ((word >> 9) & 0x03) + ((word & MASK_2048_PHASE) !== 0 ? 4 : 0);
    CODE_2048[hi] = CODE_XPLUS;
  } else {
    CHANNEL_2048[hi] = -1;
    CODE_2048[hi] = -1;
  }
  const id1024 = word >> 10;
  CHANNEL_1024[hi] = id1024 <= MAX_NORMAL_CHANNEL ? id1024 : -1;
  CODE_1024[hi] = id1024 <= MAX_NORMAL_CHANNEL ? id1024 : -1;
}

/** A layout that is not one: the slots do not form a valid frame. */
export const INVALID = -1;

/**
 * Whether bytes 12–15 carry Spektrum VTX control instead of two channels: both words' top
 * nibble 0xE (mask 0xF000F000 = 0xE000E000) in a frame whose first slot has phase 0. The phase
 * test keeps apart two X-Plus words X+5…X+8 (also 0xE…, but only sent in phase-1 frames).
 */
export function isVtxFrame(b: Uint8Array, o: number): boolean {
  return ((b[o + 12] as number) & 0xf0) === 0xe0 && ((b[o + 14] as number) & 0xf0) === 0xe0 && ((b[o + 2] as number) & 0x80) === 0;
}

/**
 * The frame's slot layout under `resolution`: a small integer naming which channel ID each
 * slot holds (X-Plus, empty and VTX slots as codes of their own) plus the first slot's phase
 * bit, or `INVALID` when a slot holds an impossible ID or an ID repeats. A frame of seven
 * empty slots is valid: a receiver sends it, and reading it as anything else (its next frame's
 * header as a slot) invents a channel. Frames of one transmitter repeat a few layouts, so a known layout is strong evidence
 * that the decoder is aligned.
 */
export function slotLayout(b: Uint8Array, o: number, resolution: Resolution): number {
  const vtx = isVtxFrame(b, o);
  const slots = vtx ? SLOTS_PER_FRAME - 2 : SLOTS_PER_FRAME;
  const channels = resolution === 2048 ? CHANNEL_2048 : CHANNEL_1024;
  const codes = resolution === 2048 ? CODE_2048 : CODE_1024;
  let seen = 0;
  let layout = 0;
  for (let i = 0; i < slots; i++) {
    const hi = b[o + 2 + 2 * i] as number;
    if (hi === 0xff && b[o + 3 + 2 * i] === 0xff) {
      layout |= CODE_EMPTY << (CODE_BITS * i); // EMPTY_SLOT
      continue;
    }
    const channel = channels[hi] as number;
    if (channel < 0) return INVALID;
    const bit = 1 << channel;
    if ((seen & bit) !== 0) return INVALID;
    seen |= bit;
    layout |= (codes[hi] as number) << (CODE_BITS * i);
  }
  if (vtx) layout |= (CODE_VTX << (CODE_BITS * 5)) | (CODE_VTX << (CODE_BITS * 6));
  if (((b[o + 2] as number) & 0x80) !== 0) layout |= LAYOUT_PHASE_BIT;
  return layout;
}

/** Bit mask (bit n = channel n, normal channels 0–11 only) of the channels in a valid layout. */
export function layoutChannels(layout: number): number {
  let mask = 0;
  for (let i = 0; i < SLOTS_PER_FRAME; i++) {
    const code = (layout >> (CODE_BITS * i)) & 0x0f;
    if (code <= MAX_NORMAL_CHANNEL) mask |= 1 << code;
  }
  return mask;
}

/** Whether a layout has a slot with a given raw 16-bit word of zero (a header read as a slot). */
export function countZeroWords(b: Uint8Array, o: number): number {
  let n = 0;
  for (let i = 0; i < SLOTS_PER_FRAME; i++) if (b[o + 2 + 2 * i] === 0 && b[o + 3 + 2 * i] === 0) n++;
  return n;
}

/** A fresh, empty `DecodedFrame` whose arrays the decoder reuses. */
export function createFrame(): DecodedFrame {
  return {
    index: -1,
    offset: 0,
    timeUs: NaN,
    remote: 'external',
    system: null,
    resolution: 2048,
    fades: null,
    fadesDelta: 0,
    rssi: null,
    count: 0,
    ids: new Uint8Array(SLOTS_PER_FRAME),
    positions: new Uint16Array(SLOTS_PER_FRAME),
    words: new Uint16Array(SLOTS_PER_FRAME),
    vtx: null,
    bytes: new Uint8Array(16),
  };
}

/** A fresh VTX record whose fields the decoder overwrites. */
export function createVtx(): VtxControl {
  return { raw: 0, band: 0, channel: 0, power: 0, region: 0, pit: false };
}

/**
 * Fills the slots of `frame` from the 16 bytes at `o` of `b` (header fields are the caller's).
 * The slots must have passed `slotLayout` under the same resolution; `vtx` is what
 * `isVtxFrame` said. Returns the number of empty slots.
 */
export function readSlots(
  frame: DecodedFrame,
  b: Uint8Array,
  o: number,
  resolution: Resolution,
  vtx: boolean,
  vtxStore: VtxControl,
): number {
  const bytes = frame.bytes;
  for (let i = 0; i < 16; i++) bytes[i] = b[o + i] as number;
  return decodeSlots(frame, b, o, resolution, vtx, vtxStore);
}

/**
 * `readSlots` without copying the raw bytes to `frame.bytes` (the caller has). This is the
 * decoder's hottest function: plain byte arithmetic on the Uint8Array and table lookups, no
 * DataView calls.
 */
export function decodeSlots(
  frame: DecodedFrame,
  b: Uint8Array,
  o: number,
  resolution: Resolution,
  vtx: boolean,
  vtxStore: VtxControl,
): number {
  const { ids, positions, words } = frame;
  const channels = resolution === 2048 ? CHANNEL_2048 : CHANNEL_1024;
  const slots = vtx ? SLOTS_PER_FRAME - 2 : SLOTS_PER_FRAME;
  let count = 0;
  let empty = 0;
  for (let i = 0; i < SLOTS_PER_FRAME; i++) {
    const hi = b[o + 2 + 2 * i] as number;
    const word = (hi << 8) | (b[o + 3 + 2 * i] as number);
    words[i] = word;
    if (i >= slots) continue;
    if (word === EMPTY_SLOT) {
      empty++;
      continue;
    }
    const channel = channels[hi] as number;
    ids[count] = channel;
    // §8.6: an X-Plus slot's 9 bits scale to 11; otherwise the position is the low 10 or 11 bits.
    positions[count] =
      resolution === 1024 ? word & MASK_1024_SXPOS : channel >= XPLUS_FIRST ? (word & 0x01ff) << 2 : word & MASK_2048_SXPOS;
    count++;
  }
  frame.count = count;
  if (vtx) {
    const raw =
      (((b[o + 12] as number) << 24) | ((b[o + 13] as number) << 16) | ((b[o + 14] as number) << 8) | (b[o + 15] as number)) >>> 0;
    vtxStore.raw = raw;
    vtxStore.band = (raw >>> 21) & 0x07;
    vtxStore.channel = (raw >>> 16) & 0x0f;
    vtxStore.pit = ((raw >>> 4) & 1) === 1;
    vtxStore.region = (raw >>> 3) & 1;
    vtxStore.power = raw & 0x07;
    frame.vtx = vtxStore;
  } else {
    frame.vtx = null;
  }
  return empty;
}

/**
 * The channel 0–19 a slot whose high byte is `hi` carries under `resolution` (X-Plus resolved,
 * §8.6), or -1 for an ID that does not exist (§8.5). An empty slot (0xFFFF) is the caller's test.
 */
export function slotChannel(hi: number, resolution: Resolution): number {
  return (resolution === 2048 ? CHANNEL_2048 : CHANNEL_1024)[hi & 0xff] ?? -1;
}

/** §8.1, §8.2, §8.6: the position a slot's word carries for `channel` (X-Plus's 9 bits scaled to 11). */
export function slotPosition(word: number, channel: number, resolution: Resolution): number {
  return resolution === 1024 ? word & MASK_1024_SXPOS : channel >= XPLUS_FIRST ? (word & 0x01ff) << 2 : word & MASK_2048_SXPOS;
}

/** Bytes 12–15 at `o` as Spektrum VTX control, written into `store` (the layout PX4 and Betaflight read). */
export function readVtxControl(b: Uint8Array, o: number, store: VtxControl): VtxControl {
  const raw = (((b[o + 12] ?? 0) << 24) | ((b[o + 13] ?? 0) << 16) | ((b[o + 14] ?? 0) << 8) | (b[o + 15] ?? 0)) >>> 0;
  store.raw = raw;
  store.band = (raw >>> 21) & 0x07;
  store.channel = (raw >>> 16) & 0x0f;
  store.pit = ((raw >>> 4) & 1) === 1;
  store.region = (raw >>> 3) & 1;
  store.power = raw & 0x07;
  return store;
}
