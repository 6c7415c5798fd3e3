/**
 * MAVLink, as ArduPilot and PX4 speak it on their USB port: frames found and checked, the few
 * messages SatScope reads to grade a flight controller (HEARTBEAT: armed and in failsafe;
 * SYS_STATUS: the RC receiver's health; RC_CHANNELS: the channels it decoded), and the
 * requests it sends (its own HEARTBEAT, SET_MESSAGE_INTERVAL, and REQUEST_DATA_STREAM for an
 * ArduPilot older than SET_MESSAGE_INTERVAL).
 *
 * Framing (mavlink.io, c_library_v2):
 * - v2: `FD len incompat compat seq sys comp msgid(3) payload crc(2) [signature(13)]`; a sender
 *   drops the payload's trailing zero bytes, a reader puts them back.
 * - v1: `FE len seq sys comp msgid payload crc(2)`.
 * The CRC is CRC-16/MCRF4XX from the byte after the start to the payload's end, then the
 * message's CRC_EXTRA; a message whose CRC_EXTRA is not known here cannot be checked and is
 * passed over. Little-endian throughout.
 */

/** Message ids SatScope reads or writes, with their CRC_EXTRA and full payload length (common.xml). */
export const MAVLINK = {
  HEARTBEAT: { id: 0, crcExtra: 50, length: 9 },
  SYS_STATUS: { id: 1, crcExtra: 124, length: 43 },
  RC_CHANNELS_RAW: { id: 35, crcExtra: 244, length: 22 },
  RC_CHANNELS: { id: 65, crcExtra: 118, length: 42 },
  REQUEST_DATA_STREAM: { id: 66, crcExtra: 148, length: 6 },
  COMMAND_LONG: { id: 76, crcExtra: 152, length: 33 },
  COMMAND_ACK: { id: 77, crcExtra: 143, length: 10 },
  STATUSTEXT: { id: 253, crcExtra: 83, length: 54 },
} as const;

const BY_ID = new Map<number, { crcExtra: number; length: number }>(Object.values(MAVLINK).map((m) => [m.id, m]));
const STX_V2 = 0xfd;
const STX_V1 = 0xfe;
const SIGNED = 0x01;
/** MAV_CMD_SET_MESSAGE_INTERVAL. */
const SET_MESSAGE_INTERVAL = 511;
/** MAV_SYS_STATUS_SENSOR_RC_RECEIVER. */
export const SENSOR_RC_RECEIVER = 0x10000;
/** MAV_MODE_FLAG_SAFETY_ARMED. */
const MODE_ARMED = 0x80;
/** MAV_STATE_CRITICAL: ArduPilot's state while a failsafe is on. */
export const MAV_STATE_CRITICAL = 5;

/** One MAVLink message whose check passed, its payload zero-filled to the message's full length. */
export interface MavlinkMessage {
  version: 1 | 2;
  msgid: number;
  sysid: number;
  compid: number;
  seq: number;
  payload: Uint8Array;
}

/** CRC-16/MCRF4XX (MAVLink's X.25) of `bytes[start, end)`, from `crc`. */
export function crc16Mcrf4xx(bytes: Uint8Array, start = 0, end = bytes.length, crc = 0xffff): number {
  let c = crc;
  for (let i = start; i < end; i++) c = crcByte(c, bytes[i] as number);
  return c;
}

function crcByte(crc: number, b: number): number {
  let t = (b ^ crc) & 0xff;
  t = (t ^ (t << 4)) & 0xff;
  return ((crc >> 8) ^ (t << 8) ^ (t << 3) ^ (t >> 4)) & 0xffff;
}

/** A MAVLink v2 frame of message `msgid` (one of `MAVLINK`), its payload's trailing zeros dropped as senders do. */
export function encodeMavlink(
  msgid: number,
  payload: Uint8Array,
  head: { seq?: number; sysid?: number; compid?: number } = {},
): Uint8Array {
  const m = BY_ID.get(msgid);
  if (m === undefined) throw new RangeError(`message ${msgid} has no CRC_EXTRA here`);
  let len = Math.min(payload.length, m.length);
  while (len > 1 && payload[len - 1] === 0) len--;
  const out = new Uint8Array(12 + len);
  out.set([
    STX_V2,
    len,
    0,
    0,
    (head.seq ?? 0) & 0xff,
    head.sysid ?? 255,
    head.compid ?? 190,
    msgid & 0xff,
    (msgid >> 8) & 0xff,
    msgid >> 16,
  ]);
  out.set(payload.subarray(0, len), 10);
  const crc = crcByte(crc16Mcrf4xx(out, 1, 10 + len), m.crcExtra);
  out[10 + len] = crc & 0xff;
  out[11 + len] = crc >> 8;
  return out;
}

/** What a parser has seen: messages, frames that failed their check, frames of messages not known here, and bytes outside frames. */
export interface MavlinkStats {
  messages: number;
  badChecks: number;
  unknown: number;
  discardedBytes: number;
}

/**
 * Finds MAVLink v1 and v2 messages in bytes as they come, whatever the chunking. Never throws
 * on bytes; holds at most one frame (280 bytes).
 */
export class MavlinkParser {
  readonly #buf = new Uint8Array(280);
  #len = 0;
  readonly #out: MavlinkMessage[] = [];
  readonly stats: MavlinkStats = { messages: 0, badChecks: 0, unknown: 0, discardedBytes: 0 };

  push(bytes: Uint8Array): void {
    for (const b of bytes) {
      this.#buf[this.#len++] = b;
      this.#scan();
    }
  }

  /** The next message found, oldest first. */
  next(): MavlinkMessage | undefined {
    return this.#out.shift();
  }

  #scan(): void {
    for (;;) {
      const b = this.#buf;
      const n = this.#len;
      if (n === 0) return;
      const stx = b[0];
      if (stx !== STX_V2 && stx !== STX_V1) {
        this.#drop(1);
        continue;
      }
      const v2 = stx === STX_V2;
      const headLen = v2 ? 10 : 6;
      if (n < headLen) return;
      const len = b[1] as number;
      if (v2 && ((b[2] as number) & ~SIGNED) !== 0) {
        // An incompatibility flag this reader does not know: not a frame it may read.
        this.#drop(1);
        continue;
      }
      const total = headLen + len + 2 + (v2 && ((b[2] as number) & SIGNED) !== 0 ? 13 : 0);
      if (n < total) return;
      const msgid = v2 ? (b[7] as number) | ((b[8] as number) << 8) | ((b[9] as number) << 16) : (b[5] as number);
      const m = BY_ID.get(msgid);
      if (m === undefined) {
        // Not checkable: its bytes are searched on (a real frame may start inside a false start).
        this.stats.unknown++;
        this.#drop(1);
        continue;
      }
      const crc = crcByte(crc16Mcrf4xx(b, 1, headLen + len), m.crcExtra);
      if (crc !== ((b[headLen + len] as number) | ((b[headLen + len + 1] as number) << 8))) {
        this.stats.badChecks++;
        this.#drop(1);
        continue;
      }
      const payload = new Uint8Array(Math.max(m.length, len));
      payload.set(b.subarray(headLen, headLen + len));
      this.#out.push({
        version: v2 ? 2 : 1,
        msgid,
        seq: b[v2 ? 4 : 2] as number,
        sysid: b[v2 ? 5 : 3] as number,
        compid: b[v2 ? 6 : 4] as number,
        payload,
      });
      this.stats.messages++;
      this.#consume(total);
    }
  }

  #consume(k: number): void {
    this.#buf.copyWithin(0, k, this.#len);
    this.#len -= k;
  }

  #drop(k: number): void {
    this.stats.discardedBytes += k;
    this.#consume(k);
  }
}

/** HEARTBEAT: who sent it, armed, and its MAV_STATE (5: critical, ArduPilot's failsafe). */
export interface Heartbeat {
  type: number;
  autopilot: number;
  armed: boolean;
  systemStatus: number;
  customMode: number;
}

/** Reads a HEARTBEAT (message 0): its MAV_TYPE, MAV_AUTOPILOT, armed (MAV_MODE_FLAG_SAFETY_ARMED) and MAV_STATE. */
export function readHeartbeat(m: MavlinkMessage): Heartbeat {
  const v = new DataView(m.payload.buffer, m.payload.byteOffset, m.payload.byteLength);
  return {
    customMode: v.getUint32(0, true),
    type: v.getUint8(4),
    autopilot: v.getUint8(5),
    armed: (v.getUint8(6) & MODE_ARMED) !== 0,
    systemStatus: v.getUint8(7),
  };
}

/** RC_CHANNELS: the channels the autopilot decoded (µs; null for an unused one), how many, and the RSSI (null: unknown). */
export interface RcChannels {
  timeBootMs: number;
  channels: (number | null)[];
  count: number;
  rssi: number | null;
}

/** Reads an RC_CHANNELS (message 65): channels 1–18 in µs (UINT16_MAX: unused, null here), chancount and RSSI (255: unknown, null here). */
export function readRcChannels(m: MavlinkMessage): RcChannels {
  const v = new DataView(m.payload.buffer, m.payload.byteOffset, m.payload.byteLength);
  const channels: (number | null)[] = [];
  for (let i = 0; i < 18; i++) {
    const us = v.getUint16(4 + 2 * i, true);
    channels.push(us === 0xffff ? null : us);
  }
  const rssi = v.getUint8(41);
  return { timeBootMs: v.getUint32(0, true), channels, count: v.getUint8(40), rssi: rssi === 255 ? null : rssi };
}

/** SYS_STATUS: whether the RC receiver is present and healthy (MAV_SYS_STATUS_SENSOR_RC_RECEIVER). */
export function readRcReceiverHealth(m: MavlinkMessage): { present: boolean; healthy: boolean } {
  const v = new DataView(m.payload.buffer, m.payload.byteOffset, m.payload.byteLength);
  const present = (v.getUint32(0, true) & SENSOR_RC_RECEIVER) !== 0;
  return { present, healthy: present && (v.getUint32(8, true) & SENSOR_RC_RECEIVER) !== 0 };
}

/** The GCS HEARTBEAT SatScope sends once a second (MAV_TYPE_GCS, MAV_AUTOPILOT_INVALID), so the autopilot streams to it. */
export function gcsHeartbeat(seq: number): Uint8Array {
  return encodeMavlink(MAVLINK.HEARTBEAT.id, Uint8Array.of(0, 0, 0, 0, 6, 8, 0, 0, 3), { seq });
}

/** COMMAND_LONG SET_MESSAGE_INTERVAL: ask system `target` to send message `msgid` every `intervalUs`. */
export function requestMessageInterval(msgid: number, intervalUs: number, target = { sysid: 1, compid: 1 }, seq = 0): Uint8Array {
  const p = new Uint8Array(MAVLINK.COMMAND_LONG.length);
  const v = new DataView(p.buffer);
  v.setFloat32(0, msgid, true);
  v.setFloat32(4, intervalUs, true);
  v.setUint16(28, SET_MESSAGE_INTERVAL, true);
  v.setUint8(30, target.sysid);
  v.setUint8(31, target.compid);
  return encodeMavlink(MAVLINK.COMMAND_LONG.id, p, { seq });
}

/** MAV_DATA_STREAM ids REQUEST_DATA_STREAM takes (common.xml; deprecated there, still what ArduPilot's SRx_ rates answer). */
export const DATA_STREAM = { EXTENDED_STATUS: 2, RC_CHANNELS: 3 } as const;

/** REQUEST_DATA_STREAM: ask system `target` to start (or stop) stream `streamId` at `rateHz`. */
export function requestDataStream(streamId: number, rateHz: number, target = { sysid: 1, compid: 1 }, seq = 0, start = true): Uint8Array {
  const p = new Uint8Array(MAVLINK.REQUEST_DATA_STREAM.length);
  const v = new DataView(p.buffer);
  v.setUint16(0, rateHz, true);
  v.setUint8(2, target.sysid);
  v.setUint8(3, target.compid);
  v.setUint8(4, streamId);
  v.setUint8(5, start ? 1 : 0);
  return encodeMavlink(MAVLINK.REQUEST_DATA_STREAM.id, p, { seq });
}

/** MAV_AUTOPILOT values SatScope names (common.xml); 8 (INVALID) is a ground station or a component that is no autopilot. */
export const MAV_AUTOPILOT_ARDUPILOTMEGA = 3;
export const MAV_AUTOPILOT_PX4 = 12;
export const MAV_AUTOPILOT_INVALID = 8;

/** The flight stack a HEARTBEAT's autopilot field names ('ArduPilot', 'PX4', or the number). */
export function autopilotName(autopilot: number): string {
  return autopilot === MAV_AUTOPILOT_ARDUPILOTMEGA ? 'ArduPilot' : autopilot === MAV_AUTOPILOT_PX4 ? 'PX4' : `MAV_AUTOPILOT ${autopilot}`;
}
