/**
 * What each byte of a 16-byte frame means, in words, for the frame inspector: the header
 * (§8.3, §8.3.1, §8.4) and the seven slots (§8.1, §8.2, §8.6), with empty slots (0xFFFF) and
 * Spektrum VTX control as real receivers send them. The reading itself is the library's
 * `readFrameFields`, made with the decoder's own tables, so the inspector shows a frame
 * exactly as the decoder read it; this file only says it.
 */
import { FRAME_SIZE, channelName, systemInfo, type Resolution } from '../decoder/spec.js';
import { readFrameFields, type FrameFields, type SlotFields, type SlotKind } from '../decoder/fields.js';
import type { HeaderMode, RemoteKind, VtxControl } from '../decoder/types.js';

export type { SlotKind };

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

/** One of the seven 16-bit slots, as the library reads it, with words to show. */
export interface SlotField extends SlotFields {
  /** Byte range in the frame, inclusive (2–3 … 14–15). */
  last: number;
  /** The word as four hex digits. */
  hex: string;
  /** The channel's name, or null. */
  name: string | null;
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

const hex2 = (v: number) => `0x${v.toString(16).toUpperCase().padStart(2, '0')}`;
const hex4 = (v: number) => v.toString(16).toUpperCase().padStart(4, '0');

function vtxText(v: VtxControl): string {
  return `VTX band ${v.band} ch ${v.channel} power ${v.power} ${v.region === 1 ? 'EU' : 'US'}${v.pit ? ' pit' : ''}`;
}

function describeHeader(f: FrameFields): HeaderField[] {
  if (f.remote === 'external') {
    const fades = f.fades ?? 0;
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
  const b1 = f.system ?? 0;
  const first: HeaderField =
    f.rssi !== null
      ? (() => {
          const dBm = f.rssi;
          const loss = dBm === -128;
          return {
            field: 'rssi' as const,
            first: 0,
            last: 0,
            raw: dBm & 0xff,
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
          raw: f.fades ?? 0,
          value: f.fades ?? 0,
          valid: true,
          label: 'fades',
          text: `fades ${f.fades ?? 0}`,
          title: `byte 0: fade count, UINT8 (internal remote, §8.3) = ${f.fades ?? 0}`,
        };
  const info = systemInfo(b1);
  let title = `byte 1: system ${hex2(b1)}`;
  if (info === undefined) {
    title += ': not a valid system byte (§8.3 allows 0x01, 0x12, 0xA2, 0xB2; a receiver sending another value is not bound)';
  } else {
    title += ` = ${info.name} (§8.3)`;
    if (info.resolution !== f.resolution) title += `; but the channel IDs read at ${f.resolution}, not ${info.resolution}`;
  }
  const system: HeaderField = {
    field: 'system',
    first: 1,
    last: 1,
    raw: b1,
    value: b1,
    valid: f.systemValid,
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
  const f = readFrameFields(bytes, resolution, remote, headerMode);
  const header = describeHeader(f);
  const vtx = f.vtx;
  const slots = f.slots.map((read): SlotField => {
    const s: SlotField = {
      ...read,
      last: read.first + 1,
      hex: hex4(read.word),
      name: read.channel === null ? null : channelName(read.channel),
      label: '',
      text: '',
      title: '',
    };
    const where = `bytes ${s.first}–${s.last}, slot ${s.index + 1}, word 0x${s.hex}`;
    const phaseNote = s.phase === null ? '' : `, phase ${s.phase}`;
    if (s.kind === 'vtx' && vtx !== null) {
      // Slots 6 and 7 together carry one 32-bit VTX value: both get the whole decode.
      s.label = 'VTX';
      s.text = s.index === 5 ? vtxText(vtx) : '';
      s.title =
        `${where}: Spektrum VTX control (bytes 12–15 = 0x${hex4(vtx.raw >>> 16)}${hex4(vtx.raw & 0xffff)}, both words' top nibble 0xE in a phase-0 frame): ` +
        `band ${vtx.band}, channel ${vtx.channel}, power ${vtx.power}, region ${vtx.region === 1 ? 'EU' : 'US'}, pit mode ${vtx.pit ? 'on' : 'off'}`;
    } else if (s.kind === 'empty') {
      s.label = 'empty';
      s.text = 'empty';
      s.title = `${where}: empty slot (0xFFFF: unused, not a channel)`;
    } else if (s.kind === 'invalid') {
      const decoded = s.channel !== null ? `; reads as ${s.name} ${s.position}` : '';
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
    return s;
  });
  const parts = [...header.map((h) => h.text), ...slots.filter((s) => s.kind !== 'empty' && s.text !== '').map((s) => s.text)];
  if (f.emptySlots > 0) parts.push(`${f.emptySlots} empty`);
  return {
    resolution,
    remote,
    headerMode,
    header,
    slots,
    vtx,
    phase: f.phase,
    summary: parts.join(' · '),
    parts,
    emptySlots: f.emptySlots,
  };
}

/**
 * Empty (0xFFFF) slots and whether it is a VTX frame, for counting over many frames without
 * describing each (the same rules as describeFrame: VTX slots 6–7 are not empty slots).
 */
export function countSlots(bytes: Uint8Array): { empty: number; vtx: boolean } {
  if (bytes.length < FRAME_SIZE) return { empty: 0, vtx: false };
  const f = readFrameFields(bytes, 2048, 'internal', 'fades');
  return { empty: f.emptySlots, vtx: f.vtx !== null };
}
