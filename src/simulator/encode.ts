/**
 * Frame encoding: the bit layouts of the Spektrum Remote Receiver Interfacing spec (Rev G),
 * the other way round. Each function checks its arguments and throws `RangeError` on values
 * the format cannot carry; the simulator's bulk path uses the same arithmetic inline.
 */
import {
  EMPTY_SLOT,
  FRAME_SIZE,
  MASK_1024_SXPOS,
  MASK_2048_PHASE,
  MASK_2048_SXPOS,
  SLOTS_PER_FRAME,
  XPLUS_CHANNEL_ID,
  XPLUS_FIRST,
  XPLUS_LAST,
  systemInfo,
} from '../decoder/spec.js';
import type { VtxControl } from '../decoder/types.js';

/** Bit position of the channel ID in a 1024-mode word (§8.1: bits 15–10). */
export const SHIFT_1024_CHANID = 10;
/** Bit position of the channel ID in a 2048-mode word (§8.2: bits 14–11). */
export const SHIFT_2048_CHANID = 11;
/** §8.6: the X-Plus sub-ID (0–3) sits in bits 10–9 of the word. */
export const SHIFT_XPLUS_SUBID = 9;
/** §8.6: X-Plus carries a 9-bit value, the top 9 bits of an 11-bit position. */
export const MASK_XPLUS_VALUE = 0x01ff;

/** Spektrum VTX control (bytes 12–15 as one big-endian 32-bit value): field positions. */
export const VTX_BAND_SHIFT = 21; // bits 23–21
export const VTX_CHANNEL_SHIFT = 16; // bits 19–16
export const VTX_PIT_SHIFT = 4; // bit 4
export const VTX_REGION_SHIFT = 3; // bit 3
export const VTX_POWER_MASK = 0x7; // bits 2–0
/** The marker both VTX words carry: top nibble 0xE (`raw & 0xF000F000 === 0xE000E000`). */
export const VTX_MARKER = 0xe000e000;
export const VTX_MARKER_MASK = 0xf000f000;

/** VTX settings a transmitter sends; `raw` is derived. */
export type VtxSettings = Omit<VtxControl, 'raw'>;

function checkInt(name: string, value: number, min: number, max: number): void {
  if (!Number.isInteger(value) || value < min || value > max) {
    throw new RangeError(`${name} must be an integer ${min}–${max}, got ${value}`);
  }
}

/** §8.1: a 1024-mode servo word, `id << 10 | position` (id 0–63, position 0–1023). */
export function encodeServo1024(id: number, position: number): number {
  checkInt('channel id', id, 0, 63);
  checkInt('position', position, 0, MASK_1024_SXPOS);
  return (id << SHIFT_1024_CHANID) | position;
}

/**
 * §8.2: a 2048-mode servo word, `phase << 15 | id << 11 | position` (id 0–15, position 0–2047).
 * Real transmitters set the phase bit only on the first slot of one frame of a pair.
 */
export function encodeServo2048(id: number, position: number, phase: 0 | 1 | boolean = 0): number {
  checkInt('channel id', id, 0, 15);
  checkInt('position', position, 0, MASK_2048_SXPOS);
  return (phase ? MASK_2048_PHASE : 0) | (id << SHIFT_2048_CHANID) | position;
}

/**
 * §8.6: an X-Plus word for channel 12–19 (X+1 … X+8) at an 11-bit `position` (0–2047):
 * channel ID 12, sub-ID `(channel - 12) & 3` in bits 10–9, phase bit set for channels 16–19,
 * and the 9-bit value `position >> 2` in bits 8–0.
 */
export function encodeXPlus(channel: number, position: number): number {
  checkInt('X-Plus channel', channel, XPLUS_FIRST, XPLUS_LAST);
  checkInt('position', position, 0, MASK_2048_SXPOS);
  const sub = (channel - XPLUS_FIRST) & 3;
  const phase = channel - XPLUS_FIRST >= 4 ? MASK_2048_PHASE : 0;
  return phase | (XPLUS_CHANNEL_ID << SHIFT_2048_CHANID) | (sub << SHIFT_XPLUS_SUBID) | (position >> 2);
}

/** §8.6: the position a decoder reports for an X-Plus channel sent at `position`: `(position >> 2) << 2`. */
export function xplusPosition(position: number): number {
  return ((position >> 2) & MASK_XPLUS_VALUE) << 2;
}

/**
 * Spektrum VTX control as the 32-bit value of bytes 12–15: `0xE000E000 | band << 21 |
 * channel << 16 | pit << 4 | region << 3 | power`. Unsigned.
 */
export function encodeVtx(v: VtxSettings): number {
  checkInt('VTX band', v.band, 0, 7);
  checkInt('VTX channel', v.channel, 0, 15);
  checkInt('VTX power', v.power, 0, 7);
  checkInt('VTX region', v.region, 0, 1);
  return (
    (VTX_MARKER |
      (v.band << VTX_BAND_SHIFT) |
      (v.channel << VTX_CHANNEL_SHIFT) |
      ((v.pit ? 1 : 0) << VTX_PIT_SHIFT) |
      (v.region << VTX_REGION_SHIFT) |
      v.power) >>>
    0
  );
}

/** The two slot words (slots 6 and 7, bytes 12–13 and 14–15) that carry `v`. */
export function vtxWords(v: VtxSettings): [high: number, low: number] {
  const raw = encodeVtx(v);
  return [raw >>> 16, raw & 0xffff];
}

/** The `VtxControl` a decoder reports for `v` (a fresh object). */
export function vtxControl(v: VtxSettings): VtxControl {
  return { raw: encodeVtx(v), band: v.band, channel: v.channel, power: v.power, region: v.region, pit: v.pit };
}

/**
 * True when a 32-bit value of bytes 12–15 carries the VTX marker: both top nibbles 0xE
 * (stricter than the spec module's `VTX_MASK` 0xE000E000 test, which looks at three bits).
 */
export function isVtxRaw(raw: number): boolean {
  return (raw & VTX_MARKER_MASK) >>> 0 === VTX_MARKER;
}

function writeSlots(words: ArrayLike<number>, out: Uint8Array, offset: number): void {
  if (words.length > SLOTS_PER_FRAME) {
    throw new RangeError(`a frame has ${SLOTS_PER_FRAME} slots, got ${words.length} words`);
  }
  for (let s = 0; s < SLOTS_PER_FRAME; s++) {
    const w = s < words.length ? words[s]! : EMPTY_SLOT;
    checkInt(`slot ${s} word`, w, 0, 0xffff);
    out[offset + 2 + 2 * s] = w >> 8;
    out[offset + 3 + 2 * s] = w & 0xff;
  }
}

function target(out: Uint8Array | undefined, offset: number): Uint8Array {
  const buf = out ?? new Uint8Array(FRAME_SIZE);
  if (offset < 0 || offset + FRAME_SIZE > buf.length) {
    throw new RangeError(`no room for a ${FRAME_SIZE}-byte frame at offset ${offset}`);
  }
  return buf;
}

/** Byte 0 of an internal remote: the fade counter (UINT8) or, on an SPM4649T, RSSI (INT8 dBm). */
export type InternalHeader = { fades: number; rssi?: undefined; system: number } | { rssi: number; fades?: undefined; system: number };

/**
 * §8.3: an internal remote's frame: byte 0 = fades (UINT8) or RSSI (INT8, §8.3.1), byte 1 =
 * system, then seven big-endian slots (`words`; missing ones are 0xFFFF). Writes into `out` at
 * `offset` (a new 16-byte array by default) and returns it. `system` may be any byte, so that
 * receivers that send a wrong one can be simulated.
 */
export function encodeInternalFrame(header: InternalHeader, words: ArrayLike<number>, out?: Uint8Array, offset = 0): Uint8Array {
  const buf = target(out, offset);
  if (header.rssi !== undefined) checkInt('RSSI', header.rssi, -128, 127);
  else checkInt('fades', header.fades, 0, 0xff);
  checkInt('system', header.system, 0, 0xff);
  buf[offset] = (header.rssi !== undefined ? header.rssi : header.fades) & 0xff;
  buf[offset + 1] = header.system;
  writeSlots(words, buf, offset);
  return buf;
}

/**
 * §8.4: an external remote's frame: bytes 0–1 = fades (UINT16 big-endian), then seven
 * big-endian slots (missing ones are 0xFFFF).
 */
export function encodeExternalFrame(fades: number, words: ArrayLike<number>, out?: Uint8Array, offset = 0): Uint8Array {
  const buf = target(out, offset);
  checkInt('fades', fades, 0, 0xffff);
  buf[offset] = fades >> 8;
  buf[offset + 1] = fades & 0xff;
  writeSlots(words, buf, offset);
  return buf;
}

/** True when `value` is one of the four system bytes §8.3 allows. */
export function isValidSystemByte(value: number): boolean {
  return systemInfo(value) !== undefined;
}
