/**
 * MSP, the MultiWii Serial Protocol Betaflight and iNav answer on their USB port: requests
 * out, replies parsed, and the replies SatScope reads to grade a flight controller (its
 * variant, status and arming-disable flags, the RC channels it decoded, its receiver setting).
 *
 * Framing (Betaflight src/main/msp/msp_serial.c; iNav shares it):
 * - v1: `$ M <dir> size cmd payload xor`, the XOR over size, cmd and payload; a reply of 255
 *   bytes or more has size 0xFF and a U16 length after cmd (a "jumbo" frame, replies only).
 * - v2: `$ X <dir> flags cmd(U16) size(U16) payload crc`, CRC-8/DVB-S2 (poly 0xD5) over flags
 *   to the end of the payload.
 * `<dir>` is `<` to the flight controller, `>` a reply, `!` an error reply. All little-endian.
 * Never write anything but MSP to a Betaflight port: a stray `R` reboots it to its bootloader.
 */

/** The MSP commands SatScope uses. */
export const MSP = {
  API_VERSION: 1,
  FC_VARIANT: 2,
  FC_VERSION: 3,
  RX_CONFIG: 44,
  RX_MAP: 64,
  STATUS: 101,
  RC: 105,
  STATUS_EX: 150,
  INAV_STATUS: 0x2000,
} as const;

/** One MSP message, either way. */
export interface MspMessage {
  version: 1 | 2;
  direction: 'request' | 'reply' | 'error';
  cmd: number;
  /** v2 flags (0 in v1). */
  flags: number;
  payload: Uint8Array;
}

/** The longest payload a parser takes: replies are at most a few hundred bytes; anything longer is noise. */
const MAX_PAYLOAD = 4096;
const DOLLAR = 0x24;
const V1 = 0x4d; // 'M'
const V2 = 0x58; // 'X'
const DIRECTIONS: Record<number, MspMessage['direction']> = { 60: 'request', 62: 'reply', 33: 'error' };
const DIRECTION_BYTE = { request: 0x3c, reply: 0x3e, error: 0x21 } as const;

/** CRC-8/DVB-S2 (polynomial 0xD5, no reflection) of `bytes[start, end)`, from `crc`. */
export function crc8DvbS2(bytes: Uint8Array, start = 0, end = bytes.length, crc = 0): number {
  let c = crc;
  for (let i = start; i < end; i++) {
    c ^= bytes[i] as number;
    for (let k = 0; k < 8; k++) c = c & 0x80 ? ((c << 1) ^ 0xd5) & 0xff : (c << 1) & 0xff;
  }
  return c;
}

/**
 * An MSP frame: a request by default (`direction`), in v1 where the command and payload fit it
 * (command below 255, payload below 255 bytes, or a v1 jumbo reply), else v2.
 */
export function encodeMsp(
  cmd: number,
  payload: Uint8Array = new Uint8Array(0),
  options: { direction?: MspMessage['direction']; version?: 1 | 2; flags?: number } = {},
): Uint8Array {
  if (!Number.isInteger(cmd) || cmd < 0 || cmd > 0xffff) throw new RangeError(`an MSP command is 0–65535, not ${cmd}`);
  if (payload.length > 0xffff) throw new RangeError('an MSP payload is at most 65535 bytes');
  const direction = DIRECTION_BYTE[options.direction ?? 'request'];
  const version = options.version ?? (cmd < 255 && (payload.length < 255 || direction !== DIRECTION_BYTE.request) ? 1 : 2);
  if (version === 1) {
    if (cmd > 254) throw new RangeError(`MSP v1 carries commands 0–254, not ${cmd}`);
    const jumbo = payload.length >= 255;
    if (jumbo && direction === DIRECTION_BYTE.request) throw new RangeError('MSP v1 requests carry under 255 bytes');
    const head = jumbo ? 7 : 5;
    const out = new Uint8Array(head + payload.length + 1);
    out.set([DOLLAR, V1, direction, jumbo ? 0xff : payload.length, cmd]);
    if (jumbo) out.set([payload.length & 0xff, payload.length >> 8], 5);
    out.set(payload, head);
    let x = 0;
    for (let i = 3; i < head + payload.length; i++) x ^= out[i] as number;
    out[head + payload.length] = x;
    return out;
  }
  const out = new Uint8Array(8 + payload.length + 1);
  out.set([DOLLAR, V2, direction, options.flags ?? 0, cmd & 0xff, cmd >> 8, payload.length & 0xff, payload.length >> 8]);
  out.set(payload, 8);
  out[8 + payload.length] = crc8DvbS2(out, 3, 8 + payload.length);
  return out;
}

/** What a parser has seen: messages, frames whose check failed, and bytes that were no MSP. */
export interface MspStats {
  messages: number;
  badChecks: number;
  discardedBytes: number;
}

/**
 * Finds MSP messages in bytes as they come (any chunking, noise between them: a flight
 * controller's port may carry its CLI or debug text too). Never throws on bytes; holds at most
 * one frame's bytes.
 */
export class MspParser {
  #buf = new Uint8Array(256);
  #len = 0;
  readonly #out: MspMessage[] = [];
  readonly stats: MspStats = { messages: 0, badChecks: 0, discardedBytes: 0 };

  push(bytes: Uint8Array): void {
    for (const b of bytes) {
      if (this.#len === this.#buf.length) {
        const grown = new Uint8Array(this.#buf.length * 2);
        grown.set(this.#buf);
        this.#buf = grown;
      }
      this.#buf[this.#len++] = b;
      this.#scan();
    }
  }

  /** The next message found, oldest first. */
  next(): MspMessage | undefined {
    return this.#out.shift();
  }

  /** Decides on the bytes held: a whole message, a frame still arriving, or bytes to drop. */
  #scan(): void {
    for (;;) {
      const n = this.#len;
      if (n === 0) return;
      const b = this.#buf;
      const need = this.#frameLength();
      if (need === 0) return; // still arriving
      if (need < 0) {
        this.#drop(1);
        continue;
      }
      if (n < need) return;
      const m = this.#message(need);
      if (m === null) {
        this.stats.badChecks++;
        this.#drop(1);
        continue;
      }
      this.#out.push(m);
      this.stats.messages++;
      b.copyWithin(0, need, n);
      this.#len = n - need;
    }
  }

  /** The whole frame's length from what is held: 0 when more bytes must come first, -1 when the bytes at the front start none. */
  #frameLength(): number {
    const b = this.#buf;
    const n = this.#len;
    if (b[0] !== DOLLAR) return -1;
    if (n < 2) return 0;
    if (b[1] !== V1 && b[1] !== V2) return -1;
    if (n < 3) return 0;
    if (DIRECTIONS[b[2] as number] === undefined) return -1;
    if (b[1] === V1) {
      if (n < 5) return 0;
      if (b[3] !== 0xff) return 5 + (b[3] as number) + 1;
      if (n < 7) return 0;
      const size = (b[5] as number) | ((b[6] as number) << 8);
      return size > MAX_PAYLOAD ? -1 : 7 + size + 1;
    }
    if (n < 8) return 0;
    const size = (b[6] as number) | ((b[7] as number) << 8);
    return size > MAX_PAYLOAD ? -1 : 8 + size + 1;
  }

  /** The frame of `length` bytes at the front, checked; null when its check fails. */
  #message(length: number): MspMessage | null {
    const b = this.#buf;
    const direction = DIRECTIONS[b[2] as number] as MspMessage['direction'];
    if (b[1] === V1) {
      let x = 0;
      for (let i = 3; i < length - 1; i++) x ^= b[i] as number;
      if (x !== b[length - 1]) return null;
      const head = b[3] === 0xff ? 7 : 5;
      return { version: 1, direction, cmd: b[4] as number, flags: 0, payload: b.slice(head, length - 1) };
    }
    if (crc8DvbS2(b, 3, length - 1) !== b[length - 1]) return null;
    return {
      version: 2,
      direction,
      cmd: (b[4] as number) | ((b[5] as number) << 8),
      flags: b[3] as number,
      payload: b.slice(8, length - 1),
    };
  }

  #drop(k: number): void {
    this.stats.discardedBytes += k;
    this.#buf.copyWithin(0, k, this.#len);
    this.#len -= k;
  }
}

/** The flight stack an MSP_FC_VARIANT reply names ("BTFL", "INAV", …), or null for a payload that is none. */
export function readFcVariant(payload: Uint8Array): string | null {
  if (payload.length < 4) return null;
  return String.fromCharCode(...payload.subarray(0, 4));
}

/** MSP_RC: the channels the flight controller decoded, µs, in its own order (roll, pitch, yaw, throttle, aux… after its channel map). */
export function readRc(payload: Uint8Array): number[] {
  const out: number[] = [];
  for (let i = 0; i + 1 < payload.length; i += 2) out.push((payload[i] as number) | ((payload[i + 1] as number) << 8));
  return out;
}

/** MSP_RX_MAP: for each of the flight controller's channels (roll, pitch, yaw, throttle, aux 1–4), the receiver channel it takes. */
export function readRxMap(payload: Uint8Array): number[] {
  return Array.from(payload);
}

/** The Betaflight arming-disable flag that says the receiver's frames stopped (shown as RXLOSS). */
export const BF_ARMING_DISABLED_RX_FAILSAFE = 1 << 2;

/** Betaflight's status (MSP_STATUS or MSP_STATUS_EX): the arming-disable flags (and how many there are). */
export interface BetaflightStatus {
  armed: boolean;
  armingDisableFlags: number;
  armingDisableCount: number;
  /** RXLOSS: no valid receiver frames (`BF_ARMING_DISABLED_RX_FAILSAFE`). */
  rxLoss: boolean;
}

/** Reads a Betaflight MSP_STATUS or MSP_STATUS_EX reply; null when it is too short to hold the flags. */
export function readBetaflightStatus(payload: Uint8Array): BetaflightStatus | null {
  if (payload.length < 16) return null;
  const v = new DataView(payload.buffer, payload.byteOffset, payload.byteLength);
  const extra = v.getUint8(15);
  if (payload.length < 16 + extra + 5) return null;
  const flags = v.getUint32(17 + extra, true);
  return {
    armed: (v.getUint32(6, true) & 1) === 1,
    armingDisableFlags: flags,
    armingDisableCount: v.getUint8(16 + extra),
    rxLoss: (flags & BF_ARMING_DISABLED_RX_FAILSAFE) !== 0,
  };
}

/** iNav's arming flags that matter here (MSP2_INAV_STATUS, src/main/fc/runtime_config.h). */
export const INAV_ARMED = 1 << 2;
export const INAV_ARMING_DISABLED_FAILSAFE_SYSTEM = 1 << 7;
export const INAV_ARMING_DISABLED_RC_LINK = 1 << 18;

/** iNav's status (MSP2_INAV_STATUS): armed, and whether it reports the RC link lost. */
export interface InavStatus {
  armed: boolean;
  armingFlags: number;
  /** RC_LINK: no valid receiver data (evaluated while disarmed). */
  rxLoss: boolean;
}

/** Reads an iNav MSP2_INAV_STATUS reply; null when it is too short. */
export function readInavStatus(payload: Uint8Array): InavStatus | null {
  if (payload.length < 13) return null;
  const flags = new DataView(payload.buffer, payload.byteOffset, payload.byteLength).getUint32(9, true);
  return { armed: (flags & INAV_ARMED) !== 0, armingFlags: flags, rxLoss: (flags & INAV_ARMING_DISABLED_RC_LINK) !== 0 };
}

/** `serialrx_provider` values for Spektrum in Betaflight and iNav (src/main/rx/rx.h): the same 0 and 1 in both. */
export const SERIALRX_SPEKTRUM1024 = 0;
export const SERIALRX_SPEKTRUM2048 = 1;

/** MSP_RX_CONFIG: the serial receiver protocol the flight controller expects (offset 0 in Betaflight and iNav). */
export function readSerialRxProvider(payload: Uint8Array): number | null {
  return payload.length >= 1 ? (payload[0] as number) : null;
}
