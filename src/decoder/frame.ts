/**
 * Reading one 16-byte frame: slot validation (used to find frames without a sync byte) and
 * decoding into the arrays a `DecodedFrame` shows. Pure functions over a byte array and an offset.
 */
import {
  FRAME_SIZE,
  MASK_1024_CHANID,
  MASK_1024_SXPOS,
  MASK_2048_CHANID,
  MASK_2048_PHASE,
  MASK_2048_SXPOS,
  MASK_XPLUS_POS,
  MAX_NORMAL_CHANNEL,
  SLOTS_PER_FRAME,
  XPLUS_CHANNEL_ID,
  XPLUS_FIRST,
  XPLUS_POSITION_SHIFT,
  type Resolution,
} from './spec.js';
import type { DecodedFrame, VtxControl } from './types.js';

/**
 * `b[i]` at an index the caller knows is inside `b`: a typed read under noUncheckedIndexedAccess
 * (an index past the end, a bug, reads as 0). Optimised code inlines it to the plain load.
 */
export function byteAt(b: Uint8Array, i: number): number {
  return b[i] ?? 0;
}

/**
 * A layout holds a 4-bit code per slot (slot i in bits 4i…4i+3): 0–11 a channel ID, then
 * CODE_XPLUS, 13 for an empty slot (EMPTY_SLOT) and CODE_VTX; bit 28 is the first slot's phase
 * bit (frames of a pair differ there). `slotLayout` and `readFrame` write these numbers out.
 */
const CODE_XPLUS = 12;
const CODE_VTX = 14;
const CODE_BITS = 4;
const CODE_MASK = 0x0f;
/** Slots 6 and 7 (indices 5 and 6) of a VTX frame. */
const VTX_CODES = (CODE_VTX << (CODE_BITS * 5)) | (CODE_VTX << (CODE_BITS * 6));

/**
 * A slot's channel, layout code and position bits depend on its high byte alone (the ID bits,
 * and for X-Plus the two extra ID bits and the phase bit, all lie in bits 15–9), so each
 * resolution has a table with one entry per high byte: -1 for an impossible ID (§8.5, §8.6),
 * else the slot's code in a layout (bits 0–3), its channel 0–19 (bits 4–8), and where its
 * position lies in the word: `(word & mask) << shift` with the shift in bits 9–10 and the mask
 * from bit 11 (§8.1, §8.2; §8.6 scales X-Plus's 9 bits to the 2047 scale). 0xFFFF (both bytes)
 * is an empty slot and is tested before the table. Validation and decoding both read these.
 */
const SLOT_2048 = new Int32Array(256);
const SLOT_1024 = new Int32Array(256);
const ENTRY_CHANNEL_SHIFT = 4;
const ENTRY_POSITION_SHIFT = 9;
const ENTRY_MASK_SHIFT = 11;
const NO_SLOT = -1;

function slotEntry(code: number, channel: number, mask: number, shift: number): number {
  return code | (channel << ENTRY_CHANNEL_SHIFT) | (shift << ENTRY_POSITION_SHIFT) | (mask << ENTRY_MASK_SHIFT);
}

for (let hi = 0; hi < 256; hi++) {
  const word = hi << 8;
  const id = (word & MASK_2048_CHANID) >> 11;
  if (id <= MAX_NORMAL_CHANNEL) {
    SLOT_2048[hi] = slotEntry(id, id, MASK_2048_SXPOS, 0);
  } else if (id === XPLUS_CHANNEL_ID) {
    const channel = XPLUS_FIRST + ((word >> 9) & 0x03) + ((word & MASK_2048_PHASE) !== 0 ? 4 : 0);
    SLOT_2048[hi] = slotEntry(CODE_XPLUS, channel, MASK_XPLUS_POS, XPLUS_POSITION_SHIFT);
  } else {
    SLOT_2048[hi] = NO_SLOT;
  }
  const id1024 = (word & MASK_1024_CHANID) >> 10;
  SLOT_1024[hi] = id1024 <= MAX_NORMAL_CHANNEL ? slotEntry(id1024, id1024, MASK_1024_SXPOS, 0) : NO_SLOT;
}

/** A layout that is not one: the slots do not form a valid frame. */
export const INVALID = -1;

/**
 * Whether bytes 12–15 carry Spektrum VTX control instead of two channels: both words' top
 * nibble 0xE (mask 0xF000F000 = 0xE000E000) in a frame whose first slot has phase 0. The phase
 * test keeps apart two X-Plus words X+5…X+8 (also 0xE…, but only sent in phase-1 frames).
 */
export function isVtxFrame(b: Uint8Array, o: number): boolean {
  // Plain loads (readFrame inlines this): a byte past the end reads as undefined, which `&` takes as 0.
  return (b[o + 12]! & 0xf0) === 0xe0 && (b[o + 14]! & 0xf0) === 0xe0 && (b[o + 2]! & 0x80) === 0;
}

/**
 * The frame's slot layout under `resolution`: a small integer naming which channel ID each
 * slot holds (X-Plus, empty and VTX slots as codes of their own) plus the first slot's phase
 * bit, or `INVALID` when a slot holds an impossible ID or an ID repeats. A frame of seven
 * empty slots is valid: a receiver sends it, and reading it as anything else (its next frame's
 * header as a slot) invents a channel. Frames of one transmitter repeat a few layouts, so a known layout is strong evidence
 * that the decoder is aligned. `readFrame` gives the same layout and decodes the slots too.
 */
export function slotLayout(b: Uint8Array, o: number, resolution: Resolution): number {
  // Numbers written out as in readFrame, for the same reason.
  const vtx = isVtxFrame(b, o);
  const slots = vtx ? 5 : 7; // SLOTS_PER_FRAME less the two VTX slots
  const table = resolution === 2048 ? SLOT_2048 : SLOT_1024;
  let seen = 0;
  let layout = 0;
  for (let i = 0; i < slots; i++) {
    const hi = byteAt(b, o + 2 + 2 * i);
    if (hi === 0xff && b[o + 3 + 2 * i] === 0xff) {
      layout |= 13 << (4 * i); // EMPTY_SLOT: CODE_EMPTY
      continue;
    }
    const entry = table[hi] ?? -1;
    if (entry === -1) return -1; // NO_SLOT: INVALID
    const bit = 1 << ((entry >> 4) & 0x1f);
    if ((seen & bit) !== 0) return -1; // INVALID
    seen |= bit;
    layout |= (entry & 0x0f) << (4 * i);
  }
  if (vtx) layout |= VTX_CODES;
  if ((byteAt(b, o + 2) & 0x80) !== 0) layout |= 1 << 28; // LAYOUT_PHASE_BIT
  return layout;
}

/**
 * In the valid 2048-mode frame at `o` (its layout `layout`): the slots after the first that carry
 * an ordinary channel (0–11) with bit 15, the phase bit, set. Transmitters set it on a frame's
 * first slot (X-Plus words carry it for X+5 to X+8, §8.6): elsewhere it marks bytes read off the
 * frames' alignment (the first slot of a frame read as a later one).
 */
export function phaseBitsAfterFirst(b: Uint8Array, o: number, layout: number): number {
  let n = 0;
  for (let i = 1; i < SLOTS_PER_FRAME; i++) {
    const code = (layout >> (CODE_BITS * i)) & CODE_MASK;
    if (code <= MAX_NORMAL_CHANNEL && (byteAt(b, o + 2 + 2 * i) & 0x80) !== 0) n++;
  }
  return n;
}

/** Bit mask (bit n = channel n, normal channels 0–11 only) of the channels in a valid layout. */
export function layoutChannels(layout: number): number {
  let mask = 0;
  for (let i = 0; i < SLOTS_PER_FRAME; i++) {
    const code = (layout >> (CODE_BITS * i)) & CODE_MASK;
    if (code <= MAX_NORMAL_CHANNEL) mask |= 1 << code;
  }
  return mask;
}

/**
 * How much the valid frame at `o` (its layout `layout`) says about a transmitter: the bytes of
 * its channel words (0–11 and X-Plus) that are not filler, 0x00 (a line held low) or 0xFF (the
 * empty slot's and an idle line's), in words whose two bytes differ (a run of one byte is
 * filler whatever its value). Runs and patterns of filler read as valid frames (seven 0xFFFF
 * slots are one, and 0x00FF reads as channel 0) and carry none; a shifted reading of frames of
 * filler slots takes a header for slots, two bytes at most. A transmitter's frame carries four
 * channels or more, each with one such byte at least.
 */
export function channelEvidence(b: Uint8Array, o: number, layout: number): number {
  let n = 0;
  for (let i = 0; i < SLOTS_PER_FRAME; i++) {
    if (((layout >> (CODE_BITS * i)) & CODE_MASK) > CODE_XPLUS) continue; // empty or VTX
    const hi = byteAt(b, o + 2 + 2 * i);
    const lo = byteAt(b, o + 3 + 2 * i);
    if (hi === lo) continue;
    if (hi !== 0 && hi !== 0xff) n++;
    if (lo !== 0 && lo !== 0xff) n++;
  }
  return n;
}

/** Whether a layout has a slot with a given raw 16-bit word of zero (a header read as a slot). */
export function countZeroWords(b: Uint8Array, o: number): number {
  let n = 0;
  for (let i = 0; i < SLOTS_PER_FRAME; i++) if (b[o + 2 + 2 * i] === 0 && b[o + 3 + 2 * i] === 0) n++;
  return n;
}

/**
 * One frame's decoded slots: the arrays a `DecodedFrame` shows. The decoder keeps two and
 * swaps them into its frame, so that a frame can be decoded while the one before it is still
 * shown (see `readFrame`).
 */
export class FrameSlots {
  readonly ids = new Uint8Array(SLOTS_PER_FRAME);
  readonly positions = new Uint16Array(SLOTS_PER_FRAME);
  readonly words = new Uint16Array(SLOTS_PER_FRAME);
  readonly bytes = new Uint8Array(FRAME_SIZE);
  /** `bytes` as four 32-bit words, for a copy in four moves. */
  readonly bytes32 = new Uint32Array(this.bytes.buffer);
  /** The VTX record this set fills; shown only when `hasVtx`. */
  readonly vtx: VtxControl = createVtx();
  /** Channel values in `ids` and `positions`. */
  count = 0;
  /** Slots that held 0xFFFF. */
  empty = 0;
  hasVtx = false;
}

/** A copy of `from`'s slot arrays and counts in `into` (a fresh set when none is given). */
export function copySlots(from: FrameSlots, into: FrameSlots = new FrameSlots()): FrameSlots {
  into.ids.set(from.ids);
  into.positions.set(from.positions);
  into.words.set(from.words);
  into.bytes.set(from.bytes);
  Object.assign(into.vtx, from.vtx);
  into.count = from.count;
  into.empty = from.empty;
  into.hasVtx = from.hasVtx;
  return into;
}

/** A fresh, empty `DecodedFrame` showing `slots`' arrays. */
export function createFrame(slots: FrameSlots): DecodedFrame {
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
    ids: slots.ids,
    positions: slots.positions,
    words: slots.words,
    vtx: null,
    bytes: slots.bytes,
  };
}

/** Makes `frame` show the slots (arrays, count and VTX record) of `slots`. */
export function showSlots(frame: DecodedFrame, slots: FrameSlots): void {
  frame.ids = slots.ids;
  frame.positions = slots.positions;
  frame.words = slots.words;
  frame.bytes = slots.bytes;
  frame.count = slots.count;
  frame.vtx = slots.hasVtx === true ? slots.vtx : null; // a strict test: optimised code otherwise tests for every falsy kind
}

/**
 * `slotLayout` and decoding in one pass: the frame's layout under `resolution` (or INVALID),
 * with its 16 raw bytes, slot words, channel IDs and positions, empty slots and VTX control
 * written to `into`. `b32` is `b` as 32-bit words (`b.byteOffset` 0). On INVALID `into` is
 * left part written. This is the decoder's hottest function: one table lookup per slot (VTX
 * control, rare, is read in a function of its own).
 *
 * The frame is read as four 32-bit words in little-endian order (four loads where the frame
 * lies at a multiple of 4 on a little-endian platform, as a compacted buffer puts it; else
 * assembled from its bytes) and each slot's big-endian word taken from them: a quarter less
 * time than sixteen byte loads, each checked against the array's length (measured, node 20).
 * The same words, stored, copy the frame's bytes.
 *
 * The seven slots are written out one after the other, not looped over: optimised code checks
 * every typed array it touches (its map, length and data pointer) again on each pass of a loop,
 * because the loop's interrupt check may run anything; in straight code it checks each once.
 * Written out, a frame decodes in about three quarters of the loop's time (measured, node 20).
 * An empty slot (0xFFFF) is any slot that carries no channel, so `empty` is counted at the end.
 *
 * Its numbers are written out too, each beside the constant it is: optimised code reads a
 * module's constants from the module's context with a check each time, and named here they
 * cost a quarter of this function's time (measured, node 20). The slot tables' entries: code
 * in bits 0–3, channel in bits 4–8 (ENTRY_CHANNEL_SHIFT), position shift in bits 9–10
 * (ENTRY_POSITION_SHIFT), mask from bit 11 (ENTRY_MASK_SHIFT); -1 is NO_SLOT. A slot's code
 * goes to bits 4i…4i+3 of the layout (CODE_BITS).
 */
export function readFrame(b: Uint8Array, b32: Uint32Array, o: number, resolution: Resolution, into: FrameSlots): number {
  const table = resolution === 2048 ? SLOT_2048 : SLOT_1024;
  const { ids, positions, words, bytes32 } = into;
  let x0: number;
  let x1: number;
  let x2: number;
  let x3: number;
  if ((o & 3) === 0 && LITTLE_ENDIAN) {
    const k = o >> 2;
    x0 = b32[k]!;
    x1 = b32[k + 1]!;
    x2 = b32[k + 2]!;
    x3 = b32[k + 3]!;
    bytes32[0] = x0;
    bytes32[1] = x1;
    bytes32[2] = x2;
    bytes32[3] = x3;
  } else {
    x0 = littleEndianAt(b, o);
    x1 = littleEndianAt(b, o + 4);
    x2 = littleEndianAt(b, o + 8);
    x3 = littleEndianAt(b, o + 12);
    const bytes = into.bytes;
    for (let i = 0; i < 16; i++) bytes[i] = b[o + i]!; // FRAME_SIZE
  }
  const vtx = isVtxFrame(b, o);
  let seen = 0;
  let layout = 0;
  let count = 0;
  let word = 0;
  let entry = 0;
  let bit = 0;
  let shift = 0; // 4i: slot i's place in the layout
  word = ((x0 >>> 8) & 0xff00) | (x0 >>> 24);
  words[shift >> 2] = word;
  if (word === 0xffff) {
    layout |= 13 << shift; // EMPTY_SLOT: code 13
  } else {
    entry = table[word >> 8]!;
    bit = 1 << ((entry >> 4) & 0x1f);
    if (entry === -1 || (seen & bit) !== 0) return -1; // NO_SLOT, or an ID twice: INVALID
    seen |= bit;
    layout |= (entry & 0x0f) << shift;
    ids[count] = (entry >> 4) & 0x1f;
    positions[count++] = (word & (entry >> 11)) << ((entry >> 9) & 0x03);
  }
  shift += 4;
  word = ((x1 & 0xff) << 8) | ((x1 >>> 8) & 0xff);
  words[shift >> 2] = word;
  if (word === 0xffff) {
    layout |= 13 << shift; // EMPTY_SLOT: code 13
  } else {
    entry = table[word >> 8]!;
    bit = 1 << ((entry >> 4) & 0x1f);
    if (entry === -1 || (seen & bit) !== 0) return -1; // NO_SLOT, or an ID twice: INVALID
    seen |= bit;
    layout |= (entry & 0x0f) << shift;
    ids[count] = (entry >> 4) & 0x1f;
    positions[count++] = (word & (entry >> 11)) << ((entry >> 9) & 0x03);
  }
  shift += 4;
  word = ((x1 >>> 8) & 0xff00) | (x1 >>> 24);
  words[shift >> 2] = word;
  if (word === 0xffff) {
    layout |= 13 << shift; // EMPTY_SLOT: code 13
  } else {
    entry = table[word >> 8]!;
    bit = 1 << ((entry >> 4) & 0x1f);
    if (entry === -1 || (seen & bit) !== 0) return -1; // NO_SLOT, or an ID twice: INVALID
    seen |= bit;
    layout |= (entry & 0x0f) << shift;
    ids[count] = (entry >> 4) & 0x1f;
    positions[count++] = (word & (entry >> 11)) << ((entry >> 9) & 0x03);
  }
  shift += 4;
  word = ((x2 & 0xff) << 8) | ((x2 >>> 8) & 0xff);
  words[shift >> 2] = word;
  if (word === 0xffff) {
    layout |= 13 << shift; // EMPTY_SLOT: code 13
  } else {
    entry = table[word >> 8]!;
    bit = 1 << ((entry >> 4) & 0x1f);
    if (entry === -1 || (seen & bit) !== 0) return -1; // NO_SLOT, or an ID twice: INVALID
    seen |= bit;
    layout |= (entry & 0x0f) << shift;
    ids[count] = (entry >> 4) & 0x1f;
    positions[count++] = (word & (entry >> 11)) << ((entry >> 9) & 0x03);
  }
  shift += 4;
  word = ((x2 >>> 8) & 0xff00) | (x2 >>> 24);
  words[shift >> 2] = word;
  if (word === 0xffff) {
    layout |= 13 << shift; // EMPTY_SLOT: code 13
  } else {
    entry = table[word >> 8]!;
    bit = 1 << ((entry >> 4) & 0x1f);
    if (entry === -1 || (seen & bit) !== 0) return -1; // NO_SLOT, or an ID twice: INVALID
    seen |= bit;
    layout |= (entry & 0x0f) << shift;
    ids[count] = (entry >> 4) & 0x1f;
    positions[count++] = (word & (entry >> 11)) << ((entry >> 9) & 0x03);
  }
  shift += 4;
  if (vtx) {
    layout |= VTX_CODES;
    readVtx(b, o, into);
  } else {
    word = ((x3 & 0xff) << 8) | ((x3 >>> 8) & 0xff);
    words[shift >> 2] = word;
    if (word === 0xffff) {
      layout |= 13 << shift; // EMPTY_SLOT: code 13
    } else {
      entry = table[word >> 8]!;
      bit = 1 << ((entry >> 4) & 0x1f);
      if (entry === -1 || (seen & bit) !== 0) return -1; // NO_SLOT, or an ID twice: INVALID
      seen |= bit;
      layout |= (entry & 0x0f) << shift;
      ids[count] = (entry >> 4) & 0x1f;
      positions[count++] = (word & (entry >> 11)) << ((entry >> 9) & 0x03);
    }
    shift += 4;
    word = ((x3 >>> 8) & 0xff00) | (x3 >>> 24);
    words[shift >> 2] = word;
    if (word === 0xffff) {
      layout |= 13 << shift; // EMPTY_SLOT: code 13
    } else {
      entry = table[word >> 8]!;
      bit = 1 << ((entry >> 4) & 0x1f);
      if (entry === -1 || (seen & bit) !== 0) return -1; // NO_SLOT, or an ID twice: INVALID
      seen |= bit;
      layout |= (entry & 0x0f) << shift;
      ids[count] = (entry >> 4) & 0x1f;
      positions[count++] = (word & (entry >> 11)) << ((entry >> 9) & 0x03);
    }
  }
  into.count = count;
  into.empty = (vtx ? 5 : 7) - count; // SLOTS_PER_FRAME less the two VTX slots
  into.hasVtx = vtx;
  return (x0 & 0x800000) !== 0 ? layout | (1 << 28) : layout; // byte 2's top bit: LAYOUT_PHASE_BIT
}

/** Whether this platform stores a 32-bit word's low byte first (then a Uint32Array reads four bytes in the order `littleEndianAt` assembles them). */
const LITTLE_ENDIAN = new Uint8Array(new Uint32Array([1]).buffer)[0] === 1;

/** The four bytes at `p` as a little-endian 32-bit word, on any platform. */
function littleEndianAt(b: Uint8Array, p: number): number {
  return b[p]! | (b[p + 1]! << 8) | (b[p + 2]! << 16) | (b[p + 3]! << 24);
}

/** The VTX words (slots 5 and 6) and record of the VTX frame at `o`. */
function readVtx(b: Uint8Array, o: number, into: FrameSlots): void {
  into.words[5] = (byteAt(b, o + 12) << 8) | byteAt(b, o + 13);
  into.words[6] = (byteAt(b, o + 14) << 8) | byteAt(b, o + 15);
  readVtxControl(b, o, into.vtx);
}

/** A fresh VTX record whose fields `readVtxControl` overwrites. */
export function createVtx(): VtxControl {
  return { raw: 0, band: 0, channel: 0, power: 0, region: 0, pit: false };
}

/**
 * The channel 0–19 a slot whose high byte is `hi` carries under `resolution` (X-Plus resolved,
 * §8.6), or -1 for an ID that does not exist (§8.5). An empty slot (0xFFFF) is the caller's test.
 */
export function slotChannel(hi: number, resolution: Resolution): number {
  const entry = (resolution === 2048 ? SLOT_2048 : SLOT_1024)[hi & 0xff] ?? NO_SLOT;
  return entry === NO_SLOT ? -1 : (entry >> ENTRY_CHANNEL_SHIFT) & 0x1f;
}

/**
 * §8.1, §8.2, §8.6: the position a slot's word carries (X-Plus's 9 bits scaled to 11), or -1
 * for an ID that does not exist.
 */
export function slotPosition(word: number, resolution: Resolution): number {
  const entry = (resolution === 2048 ? SLOT_2048 : SLOT_1024)[(word >> 8) & 0xff] ?? NO_SLOT;
  return entry === NO_SLOT ? -1 : (word & (entry >> ENTRY_MASK_SHIFT)) << ((entry >> ENTRY_POSITION_SHIFT) & 0x03);
}

/** Bytes 12–15 at `o` as Spektrum VTX control, written into `store` (the layout PX4 and Betaflight read). */
export function readVtxControl(b: Uint8Array, o: number, store: VtxControl): VtxControl {
  const raw = ((byteAt(b, o + 12) << 24) | (byteAt(b, o + 13) << 16) | (byteAt(b, o + 14) << 8) | byteAt(b, o + 15)) >>> 0;
  store.raw = raw;
  store.band = (raw >>> 21) & 0x07;
  store.channel = (raw >>> 16) & 0x0f;
  store.pit = ((raw >>> 4) & 1) === 1;
  store.region = (raw >>> 3) & 1;
  store.power = raw & 0x07;
  return store;
}

/**
 * How far a valid layout's slot order is from the order a single-shape transmitter sends
 * (22 ms, up to 7 channels: channel IDs ascending, empty slots after them): the normal-channel
 * slots that come after an empty, X-Plus or VTX slot or after a higher channel ID. A reading
 * shifted by words rotates the slots (the fade count read as a channel lands last, after the
 * empties, or first): the real reading is 0 where the shifted one is not. A preference, not a
 * rule of the spec (§8.5 leaves the order to the transmitter).
 */
export function slotDisorder(layout: number): number {
  let n = 0;
  let prev = (layout & CODE_MASK) as number;
  for (let i = 1; i < SLOTS_PER_FRAME; i++) {
    const code = (layout >> (CODE_BITS * i)) & CODE_MASK;
    if (code <= MAX_NORMAL_CHANNEL && prev > code) n++;
    prev = code;
  }
  return n;
}
