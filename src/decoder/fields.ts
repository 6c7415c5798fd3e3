/**
 * One frame read field by field, for people: what byte 0–1 carry, and what each of the seven
 * slots is (a channel, X-Plus, empty, VTX control, or invalid and why). It reads with the
 * decoder's own tables (`frame.ts`), so an inspector or a log shows a frame exactly as the
 * decoder read it, including the slots that made it reject one. Allocates; not for a hot path.
 */
import { INVALID, createVtx, isVtxFrame, readVtxControl, slotChannel, slotLayout, slotPosition } from './frame.js';
import { EMPTY_SLOT, FRAME_SIZE, MASK_2048_PHASE, SLOTS_PER_FRAME, XPLUS_FIRST, channelName, servoToMicros, systemInfo } from './spec.js';
import type { Resolution } from './spec.js';
import type { HeaderMode, RemoteKind, VtxControl } from './types.js';

/** What one slot of a frame holds (`readFrameFields`). */
export type SlotKind = 'channel' | 'xplus' | 'empty' | 'vtx' | 'invalid';

/** One of the seven 16-bit slots (§8.1, §8.2, §8.6). */
export interface SlotFields {
  /** 0–6. */
  index: number;
  /** Offset of the slot's first byte in the frame (2, 4, … 14). */
  first: number;
  word: number;
  kind: SlotKind;
  /** §8.2's phase bit (bit 15) in 2048 mode; null in 1024 mode, where bit 15 is part of the ID. */
  phase: 0 | 1 | null;
  /** The channel ID field as sent (bits 14–11 or 15–10); null for empty and VTX slots. */
  id: number | null;
  /** X-Plus: bits 10–9, the offset 0–3 added to channel 12 (§8.6). */
  subId: number | null;
  /** X-Plus: the 9-bit value (bits 8–0) before scaling. */
  value9: number | null;
  /** The channel 0–19 the slot carries (X-Plus resolved), or null. */
  channel: number | null;
  /** Servo position: 0–1023 or 0–2047; X-Plus scaled to 11 bits (value9 << 2). */
  position: number | null;
  /** Pulse width (§9), X-Plus on the 2048 scale. */
  us: number | null;
  /** What is wrong with an invalid slot, in a sentence; null otherwise. */
  problem: string | null;
}

/** A frame's 16 bytes as fields. */
export interface FrameFields {
  resolution: Resolution;
  remote: RemoteKind;
  headerMode: HeaderMode;
  /** The fade count (UINT16 for an external remote, UINT8 for an internal one in fades mode), else null. */
  fades: number | null;
  /** RSSI in dBm (SPM4649T, §8.3.1; -128 on loss) in RSSI mode, else null. */
  rssi: number | null;
  /** The internal remote's system byte, null for an external remote. */
  system: number | null;
  /** Whether `system` is one of §8.3's four values. */
  systemValid: boolean;
  slots: SlotFields[];
  /** Spektrum VTX control in slots 5–6 (bytes 12–15), or null. */
  vtx: VtxControl | null;
  /** The first slot's bit 15 in 2048 mode (the two frames of a pair differ there). */
  phase: 0 | 1 | null;
  /** Slots sent as 0xFFFF. */
  emptySlots: number;
  /** Whether the decoder would take these slots as a frame at this resolution (no invalid slot). */
  valid: boolean;
}

/**
 * Reads the 16 bytes at the start of `bytes` as a frame of `remote` at `resolution`, byte 0 as
 * `headerMode` says.
 * @throws {RangeError} when fewer than 16 bytes are given.
 */
export function readFrameFields(bytes: Uint8Array, resolution: Resolution, remote: RemoteKind, headerMode: HeaderMode): FrameFields {
  if (bytes.length < FRAME_SIZE) throw new RangeError(`a frame is ${FRAME_SIZE} bytes, got ${bytes.length}`);
  const [b0 = 0, b1 = 0] = bytes;
  const external = remote === 'external';
  const rssiMode = !external && headerMode === 'rssi';
  const vtx = isVtxFrame(bytes, 0) ? readVtxControl(bytes, 0, createVtx()) : null;
  const slots: SlotFields[] = [];
  /** Slot index (+1) that carried each channel 0–19, to name a repeated one. */
  const seenIn = new Int8Array(20);
  let emptySlots = 0;
  for (let i = 0; i < SLOTS_PER_FRAME; i++) {
    const first = 2 + 2 * i;
    const hi = bytes[first] ?? 0;
    const word = (hi << 8) | (bytes[first + 1] ?? 0);
    const s: SlotFields = {
      index: i,
      first,
      word,
      kind: 'channel',
      phase: resolution === 2048 ? ((word & MASK_2048_PHASE) !== 0 ? 1 : 0) : null,
      id: null,
      subId: null,
      value9: null,
      channel: null,
      position: null,
      us: null,
      problem: null,
    };
    slots.push(s);
    if (vtx !== null && i >= SLOTS_PER_FRAME - 2) {
      s.kind = 'vtx';
      continue;
    }
    if (word === EMPTY_SLOT) {
      s.kind = 'empty';
      emptySlots++;
      continue;
    }
    s.id = resolution === 2048 ? (word >> 11) & 0x0f : word >> 10;
    const channel = slotChannel(hi, resolution);
    if (channel < 0) {
      s.kind = 'invalid';
      s.problem =
        resolution === 2048
          ? `channel ID ${s.id} does not exist (2048 mode: 0–11, or 12 for X-Plus)`
          : `channel ID ${s.id} does not exist (1024 mode: 0–11; X-Plus is 2048 only)`;
      continue;
    }
    s.channel = channel;
    s.position = slotPosition(word, resolution);
    s.us = servoToMicros(s.position, channel >= XPLUS_FIRST ? 2048 : resolution);
    if (channel >= XPLUS_FIRST) {
      s.kind = 'xplus';
      s.subId = (word >> 9) & 0x03;
      s.value9 = word & 0x01ff;
    }
    const before = seenIn[channel] ?? 0;
    if (before > 0) {
      s.kind = 'invalid';
      s.problem = `${channelName(channel)} again (slot ${before} has it): a frame carries each channel once`;
    } else {
      seenIn[channel] = i + 1;
    }
  }
  return {
    resolution,
    remote,
    headerMode: external ? 'fades' : headerMode,
    fades: external ? (b0 << 8) | b1 : rssiMode ? null : b0,
    rssi: rssiMode ? (b0 >= 0x80 ? b0 - 0x100 : b0) : null,
    system: external ? null : b1,
    systemValid: !external && systemInfo(b1) !== undefined,
    slots,
    vtx,
    phase: slots[0]?.phase ?? null,
    emptySlots,
    valid: slotLayout(bytes, 0, resolution) !== INVALID,
  };
}
