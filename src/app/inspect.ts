/**
 * What each byte of a 16-byte frame means, field by field, for the frame inspector: the header
 * (§8.3, §8.3.1, §8.4), then the seven slots read as the spec says (§8.1, §8.2, §8.6), with
 * empty slots (0xFFFF) and Spektrum VTX control as real receivers send them. A pure function
 * of the bytes and the format the decoder settled on, so it shows the frame the way a firmware
 * decoder should read it, slot by slot, including what is wrong with a slot.
 */
import {
  EMPTY_SLOT,
  FRAME_SIZE,
  XPLUS_FIRST,
  channelName,
  servoToMicros,
  systemInfo,
  type HeaderMode,
  type RemoteKind,
  type Resolution,
  type VtxControl,
} from '../decoder/index.js';

// §8.1 and §8.2's masks. The library keeps them internal, so they are restated here.
/** §8.1: 1024 mode, bits 15–10 channel ID, bits 9–0 position. */
const SHIFT_1024_CHANID = 10;
const MASK_1024_SXPOS = 0x03ff;
/** §8.2: 2048 mode, bit 15 phase, bits 14–11 channel ID, bits 10–0 position. */
const MASK_2048_PHASE = 0x8000;
const SHIFT_2048_CHANID = 11;
const MASK_2048_SXPOS = 0x07ff;
/** §8.5: IDs 0–11 are ordinary channels. */
const MAX_NORMAL_CHANNEL = 11;
/** §8.6: channel ID 12 in 2048 mode is X-Plus; bits 10–9 add 0–3, the phase bit adds 4. */
const XPLUS_CHANNEL_ID = 12;
const MASK_XPLUS_VALUE = 0x01ff;

export type SlotKind = 'channel' | 'xplus' | 'empty' | 'vtx' | 'invalid';

/** One header field. */
export interface HeaderField {
  field: 'fades' | 'rssi' | 'system';
  /** Byte range in the frame, inclusive. */
  first: number;
  last: number;
  /** The raw unsigned value of the bytes. */
  raw: number;
  /** The value as read: fades, RSSI in dBm (signed), the system byte. */
  value: number;
  /** False for a system byte §8.3 does not allow. */
  valid: boolean;
  /** A short tag to print under the bytes. */
  label: string;
  /** The field in the one-line summary, e.g. "fades 62", "0xB2 DSMX 11 ms". */
  text: string;
  /** The full explanation (tooltip). */
  title: string;
}

/** One of the seven 16-bit slots. */
export interface SlotField {
  /** 0–6. */
  index: number;
  /** Byte range in the frame, inclusive (2–3 … 14–15). */
  first: number;
  last: number;
  word: number;
  /** The word as four hex digits. */
  hex: string;
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
  name: string | null;
  /** What is wrong with an invalid slot. */
  problem: string | null;
  /** A short tag to print under the bytes: "1p", "X+2", "empty", "VTX", "!". */
  label: string;
  /** The slot in the one-line summary (empty for the second VTX slot). */
  text: string;
  /** The full explanation (tooltip). */
  title: string;
}

export interface FrameDescription {
  resolution: Resolution;
  remote: RemoteKind;
  headerMode: HeaderMode;
  header: HeaderField[];
  slots: SlotField[];
  /** Spektrum VTX control in slots 5–6 (bytes 12–15), or null. */
  vtx: VtxControl | null;
  /** The frame's phase: the first slot's bit 15 in 2048 mode (the two frames of a pair differ there). */
  phase: 0 | 1 | null;
  /** Everything in one line: "fades 62 · 0xB2 DSMX 11 ms · 1p Aileron 1023 1500 µs · …". */
  summary: string;
  /** The summary's items, each one value that must not be broken across lines. */
  parts: string[];
  /** Slots sent as 0xFFFF. */
  emptySlots: number;
}

/** A frame's bytes for typed reads: bytes and big-endian words (spec §8), checked against its length. */
const frameView = (bytes: Uint8Array) => new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);

const hex2 = (v: number) => `0x${v.toString(16).toUpperCase().padStart(2, '0')}`;
const hex4 = (v: number) => v.toString(16).toUpperCase().padStart(4, '0');

/**
 * Whether bytes 12–15 carry VTX control: both words' top nibble 0xE, in a frame whose first
 * slot has phase 0 (two X-Plus words X+5…X+8 also start with 0xE, but only in phase-1 frames).
 * This is the decoder's `isVtxFrame` rule restated: that function lives in the library's
 * internal frame module, which the app does not import (only the public API), and the rule is
 * three comparisons.
 */
function isVtx(b: DataView): boolean {
  return (b.getUint8(12) & 0xf0) === 0xe0 && (b.getUint8(14) & 0xf0) === 0xe0 && (b.getUint8(2) & 0x80) === 0;
}

/** Bytes 12–15 as Spektrum VTX control (the layout PX4 and Betaflight read). */
function readVtx(b: DataView): VtxControl {
  const raw = b.getUint32(12);
  return {
    raw,
    band: (raw >>> 21) & 0x07,
    channel: (raw >>> 16) & 0x0f,
    pit: ((raw >>> 4) & 1) === 1,
    region: (raw >>> 3) & 1,
    power: raw & 0x07,
  };
}

function vtxText(v: VtxControl): string {
  return `VTX band ${v.band} ch ${v.channel} power ${v.power} ${v.region === 1 ? 'EU' : 'US'}${v.pit ? ' pit' : ''}`;
}

function describeHeader(b: DataView, resolution: Resolution, remote: RemoteKind, headerMode: HeaderMode): HeaderField[] {
  const b0 = b.getUint8(0);
  const b1 = b.getUint8(1);
  if (remote === 'external') {
    const fades = (b0 << 8) | b1;
    return [
      {
        field: 'fades',
        first: 0,
        last: 1,
        raw: fades,
        value: fades,
        valid: true,
        label: 'fades',
        text: `fades ${fades}`,
        title: `bytes 0–1: fade count, UINT16 big-endian (external remote, §8.4) = ${fades}`,
      },
    ];
  }
  const first: HeaderField =
    headerMode === 'rssi'
      ? (() => {
          const dBm = b0 >= 0x80 ? b0 - 0x100 : b0;
          const loss = dBm === -128;
          return {
            field: 'rssi' as const,
            first: 0,
            last: 0,
            raw: b0,
            value: dBm,
            valid: true,
            label: 'RSSI',
            text: `RSSI ${dBm}\u00a0dBm${loss ? ' (loss)' : ''}`,
            title: `byte 0: RSSI, INT8 dBm (SPM4649T, §8.3.1) = ${dBm}\u00a0dBm${loss ? ': connection or packet loss' : dBm >= 0 ? ': not negative, so not RSSI?' : ''}`,
          };
        })()
      : {
          field: 'fades',
          first: 0,
          last: 0,
          raw: b0,
          value: b0,
          valid: true,
          label: 'fades',
          text: `fades ${b0}`,
          title: `byte 0: fade count, UINT8 (internal remote, §8.3) = ${b0}`,
        };
  const info = systemInfo(b1);
  let title = `byte 1: system ${hex2(b1)}`;
  if (info === undefined) {
    title += ': not a valid system byte (§8.3 allows 0x01, 0x12, 0xA2, 0xB2; a receiver sending another value is not bound)';
  } else {
    title += ` = ${info.name} (§8.3)`;
    if (info.resolution !== resolution) title += `; but the channel IDs read at ${resolution}, not ${info.resolution}`;
  }
  const system: HeaderField = {
    field: 'system',
    first: 1,
    last: 1,
    raw: b1,
    value: b1,
    valid: info !== undefined,
    label: 'sys',
    text: info === undefined ? `${hex2(b1)} not a valid system byte` : `${hex2(b1)} ${info.protocol} ${info.periodMs} ms`,
    title,
  };
  return [first, system];
}

/**
 * The fields of one frame for display. `bytes` holds the frame's 16 bytes (more are ignored);
 * `resolution`, `remote` and `headerMode` are what the decoder read it with.
 * @throws {RangeError} when fewer than 16 bytes are given.
 */
export function describeFrame(bytes: Uint8Array, resolution: Resolution, remote: RemoteKind, headerMode: HeaderMode): FrameDescription {
  if (bytes.length < FRAME_SIZE) throw new RangeError(`a frame is ${FRAME_SIZE} bytes, got ${bytes.length}`);
  const view = frameView(bytes);
  const header = describeHeader(view, resolution, remote, headerMode);
  const vtxFrame = isVtx(view);
  const vtx = vtxFrame ? readVtx(view) : null;
  const slots: SlotField[] = [];
  /** Slot index (+1) that carried each channel 0–19, to catch a repeated one. */
  const seenIn = new Int8Array(20);
  for (let i = 0; i < 7; i++) {
    const first = 2 + 2 * i;
    const word = view.getUint16(first);
    const s: SlotField = {
      index: i,
      first,
      last: first + 1,
      word,
      hex: hex4(word),
      kind: 'invalid',
      phase: resolution === 2048 ? ((word & MASK_2048_PHASE) !== 0 ? 1 : 0) : null,
      id: null,
      subId: null,
      value9: null,
      channel: null,
      position: null,
      us: null,
      name: null,
      problem: null,
      label: '',
      text: '',
      title: '',
    };
    const where = `bytes ${first}–${first + 1}, slot ${i + 1}, word 0x${s.hex}`;
    const phaseNote = s.phase === null ? '' : `, phase ${s.phase}`;
    if (vtx !== null && i >= 5) {
      // Slots 6 and 7 together carry one 32-bit VTX value: both get the whole decode.
      s.kind = 'vtx';
      s.label = 'VTX';
      s.text = i === 5 ? vtxText(vtx) : '';
      s.title =
        `${where}: Spektrum VTX control (bytes 12–15 = 0x${hex4(vtx.raw >>> 16)}${hex4(vtx.raw & 0xffff)}, both words' top nibble 0xE in a phase-0 frame): ` +
        `band ${vtx.band}, channel ${vtx.channel}, power ${vtx.power}, region ${vtx.region === 1 ? 'EU' : 'US'}, pit mode ${vtx.pit ? 'on' : 'off'}`;
      slots.push(s);
      continue;
    }
    if (word === EMPTY_SLOT) {
      s.kind = 'empty';
      s.label = 'empty';
      s.text = 'empty';
      s.title = `${where}: empty slot (0xFFFF: unused, not a channel)`;
      slots.push(s);
      continue;
    }
    if (resolution === 2048) {
      const id = (word >> SHIFT_2048_CHANID) & 0x0f;
      s.id = id;
      if (id <= MAX_NORMAL_CHANNEL) {
        s.kind = 'channel';
        s.channel = id;
        s.position = word & MASK_2048_SXPOS;
      } else if (id === XPLUS_CHANNEL_ID) {
        // §8.6: bits 10–9 add 0–3 to 12, the phase bit adds 4, and 9 bits scale to 11.
        s.kind = 'xplus';
        s.subId = (word >> 9) & 0x03;
        s.value9 = word & MASK_XPLUS_VALUE;
        s.channel = XPLUS_FIRST + s.subId + (s.phase === 1 ? 4 : 0);
        s.position = s.value9 << 2;
      } else {
        s.problem = `channel ID ${id} does not exist (2048 mode: 0–11, or 12 for X-Plus)`;
      }
    } else {
      const id = word >> SHIFT_1024_CHANID;
      s.id = id;
      if (id <= MAX_NORMAL_CHANNEL) {
        s.kind = 'channel';
        s.channel = id;
        s.position = word & MASK_1024_SXPOS;
      } else {
        s.problem = `channel ID ${id} does not exist (1024 mode: 0–11; X-Plus is 2048 only)`;
      }
    }
    if (s.channel !== null && s.position !== null) {
      // X-Plus positions are on the 2047 scale whatever the link's resolution.
      s.us = servoToMicros(s.position, s.kind === 'xplus' ? 2048 : resolution);
      s.name = channelName(s.channel);
      const before = seenIn[s.channel] ?? 0;
      if (before > 0) s.problem = `${s.name} again (slot ${before} has it): a frame carries each channel once`;
      else seenIn[s.channel] = i + 1;
    }
    if (s.problem !== null) {
      const decoded = s.channel !== null ? `; reads as ${s.name} ${s.position}` : '';
      s.kind = 'invalid';
      s.label = '!';
      s.text = `invalid 0x${s.hex} (${s.channel !== null ? `${s.name} again` : `ID ${s.id}`})`;
      s.title = `${where}${phaseNote}: invalid: ${s.problem}${decoded}`;
    } else if (s.kind === 'xplus') {
      s.label = s.name ?? '';
      s.text = `${s.name} ${s.position} ${s.us}\u00a0µs`;
      s.title =
        `${where}${phaseNote}, channel ID 12 = X-Plus (§8.6): sub-ID ${s.subId}${s.phase === 1 ? ' + 4 for phase 1' : ''} → channel ${s.channel} (${s.name}), ` +
        `9-bit value ${s.value9} × 4 = ${s.position} = ${s.us}\u00a0µs`;
    } else {
      const p = s.phase === 1 ? 'p' : '';
      s.label = `${s.channel}${p}`;
      s.text = `${s.channel}${p} ${s.name} ${s.position} ${s.us}\u00a0µs`;
      s.title = `${where}${phaseNote}, channel ID ${s.channel} (${s.name}), position ${s.position} of ${resolution - 1} = ${s.us}\u00a0µs`;
    }
    slots.push(s);
  }
  const empty = slots.filter((s) => s.kind === 'empty').length;
  const parts = [...header.map((h) => h.text), ...slots.filter((s) => s.kind !== 'empty' && s.text !== '').map((s) => s.text)];
  if (empty > 0) parts.push(`${empty} empty`);
  return {
    resolution,
    remote,
    headerMode,
    header,
    slots,
    vtx,
    phase: resolution === 2048 ? ((view.getUint8(2) & 0x80) !== 0 ? 1 : 0) : null,
    summary: parts.join(' · '),
    parts,
    emptySlots: empty,
  };
}

/**
 * Empty (0xFFFF) slots and whether it is a VTX frame, for counting over many frames without
 * describing each (the same rules as describeFrame: VTX slots 6–7 are not empty slots).
 */
export function countSlots(bytes: Uint8Array): { empty: number; vtx: boolean } {
  if (bytes.length < FRAME_SIZE) return { empty: 0, vtx: false };
  const view = frameView(bytes);
  const vtx = isVtx(view);
  let empty = 0;
  for (let i = 0; i < (vtx ? 5 : 7); i++) if (view.getUint16(2 + 2 * i) === EMPTY_SLOT) empty++;
  return { empty, vtx };
}
