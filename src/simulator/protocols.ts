/**
 * Byte-exact streams of what a user may have plugged in instead of a satellite (SRXL v1, SRXL2,
 * FlySky IBUS, SBUS, CRSF), each at its own line setting, and a satellite's own stream as a
 * transmission: what the line model (line.ts) puts on the wire for the doctor's tests.
 *
 * Pure ECMAScript: no DOM, no Node, no timers; deterministic from a seed.
 */
import { UART_115200_8N1, characterTimeUs, type SerialFormat, type Transmission } from './line.js';
import { Prng } from './prng.js';
import type { SimChunk } from './simulator.js';

/** Common options of the packet generators. */
export interface StreamOptions {
  /** How long to send for, µs (packets that start before the end are sent whole). */
  durationUs: number;
  /** First packet's start, µs. Default 1000. */
  startUs?: number;
  /** Packet period, µs (each protocol has its usual default). */
  periodUs?: number;
  /** Seed of the stick motion. Default 1. */
  seed?: number;
}

/**
 * Packets sent every `periodUs`, bytes back to back within a packet. `make(i, rng)` builds
 * packet i.
 */
function packetStream(
  format: SerialFormat,
  options: StreamOptions,
  defaultPeriodUs: number,
  make: (index: number, rng: Prng) => Uint8Array,
): Transmission {
  const charUs = characterTimeUs(format);
  const period = options.periodUs ?? defaultPeriodUs;
  if (!(period > 0)) throw new RangeError(`periodUs must be positive, not ${period}`);
  const start = options.startUs ?? 1000;
  const rng = new Prng(options.seed ?? 1);
  const packets: Uint8Array[] = [];
  const starts: number[] = [];
  for (let i = 0; start + i * period < start + options.durationUs; i++) {
    packets.push(make(i, rng));
    starts.push(start + i * period);
  }
  let total = 0;
  for (const p of packets) total += p.length;
  const bytes = new Uint8Array(total);
  const timesUs = new Float64Array(total);
  let k = 0;
  for (const [i, p] of packets.entries()) {
    bytes.set(p, k);
    const start = starts[i] ?? NaN;
    for (let j = 0; j < p.length; j++) timesUs[k++] = start + j * charUs;
  }
  return { format, bytes, timesUs };
}

/** Smooth stick-like channel values in 0…1 for packet i, channel c. */
function stick(i: number, c: number, rng: Prng): number {
  return 0.5 + 0.4 * Math.sin((i * (c + 1)) / 37 + c) + 0.01 * (rng.next() - 0.5);
}

/** CRC-16/XMODEM (poly 0x1021, init 0), as SRXL2 frames carry it. */
function crc16Xmodem(bytes: Uint8Array, start: number, end: number): number {
  let crc = 0;
  for (const byte of bytes.subarray(start, end)) {
    crc ^= byte << 8;
    for (let b = 0; b < 8; b++) crc = crc & 0x8000 ? ((crc << 1) ^ 0x1021) & 0xffff : (crc << 1) & 0xffff;
  }
  return crc;
}

/** CRC-8/DVB-S2 (poly 0xD5, init 0), as CRSF frames carry it over type and payload. */
function crc8DvbS2(bytes: Uint8Array, start: number, end: number): number {
  let crc = 0;
  for (const byte of bytes.subarray(start, end)) {
    crc ^= byte;
    for (let b = 0; b < 8; b++) crc = crc & 0x80 ? ((crc << 1) ^ 0xd5) & 0xff : (crc << 1) & 0xff;
  }
  return crc;
}

/**
 * A Spektrum satellite's stream (from `simulate`) as a transmission at 115200 8N1, optionally
 * inverted: what arrives through an SBUS inverter or an inverted adapter input.
 */
export function spektrumTransmission(chunk: Pick<SimChunk, 'bytes' | 'timesUs'>, inverted = false): Transmission {
  return { format: { ...UART_115200_8N1, inverted }, bytes: chunk.bytes, timesUs: chunk.timesUs };
}

/**
 * Spektrum SRXL (v1), as a Spektrum receiver's SRXL port (e.g. AR7700) sends it at 115200 8N1,
 * in the layout ArduPilot reads (AP_RCProtocol_SRXL, SRXL_HEADER_V5): 0xA5, a status byte
 * (bit 1 set while the link holds), seven 2048-mode channel words big-endian, and a
 * CRC-16/XMODEM of the first 16 bytes, big-endian: 18 bytes every 11 ms.
 */
export function srxlV1Stream(options: StreamOptions): Transmission {
  const LENGTH = 18;
  return packetStream(UART_115200_8N1, options, 11_000, (i, rng) => {
    const p = new Uint8Array(LENGTH);
    p[0] = 0xa5;
    p[1] = 0x02;
    for (let s = 0; s < 7; s++) {
      const id = (i & 1) * 7 + s < 12 ? (i & 1) * 7 + s : s;
      const word = (id << 11) | Math.round(stick(i, id, rng) * 2047);
      p[2 + 2 * s] = word >> 8;
      p[3 + 2 * s] = word & 0xff;
    }
    const crc = crc16Xmodem(p, 0, LENGTH - 2);
    p[LENGTH - 2] = crc >> 8;
    p[LENGTH - 1] = crc & 0xff;
    return p;
  });
}

/**
 * SRXL2, as a Spektrum serial receiver (e.g. SPM4651T) sends it at 115200 8N1 (its default
 * rate): a few handshake packets (0xA6 0x21, 14 bytes) at start, then channel-data control
 * packets (0xA6 0xCD) every 11 ms; each ends with a CRC-16/XMODEM, big-endian.
 */
export function srxl2Stream(options: StreamOptions & { channels?: number }): Transmission {
  const channels = options.channels ?? 8;
  return packetStream(UART_115200_8N1, options, 11_000, (i, rng) => {
    if (i < 3) {
      const p = new Uint8Array(14);
      p.set([0xa6, 0x21, 14, 0x21, i === 2 ? 0xff : 0x30 + i, 10, 0x00, 0x07, 0x5d, 0x74, 0x6c, 0xbe]);
      const crc = crc16Xmodem(p, 0, 12);
      p[12] = crc >> 8;
      p[13] = crc & 0xff;
      return p;
    }
    const length = 5 + 1 + 1 + 1 + 2 + 4 + 2 * channels; // header, cmd, reply id, rssi, losses, mask, values
    const p = new Uint8Array(length);
    p[0] = 0xa6;
    p[1] = 0xcd;
    p[2] = length;
    p[3] = 0x00; // channel data
    p[4] = 0x00; // reply id
    p[5] = 100; // rssi %
    const mask = (1 << channels) - 1;
    p[8] = mask & 0xff;
    p[9] = (mask >> 8) & 0xff;
    for (let c = 0; c < channels; c++) {
      const v = Math.round(stick(i, c, rng) * 0xffff) & 0xfffc;
      p[12 + 2 * c] = v & 0xff;
      p[13 + 2 * c] = v >> 8;
    }
    const crc = crc16Xmodem(p, 0, length - 2);
    p[length - 2] = crc >> 8;
    p[length - 1] = crc & 0xff;
    return p;
  });
}

/**
 * FlySky IBUS at 115200 8N1: 0x20 0x40, 14 channels little-endian (1000–2000), and a checksum
 * (0xFFFF minus the sum of the 30 bytes before it) little-endian; 32 bytes every 7 ms.
 */
export function ibusStream(options: StreamOptions): Transmission {
  return packetStream(UART_115200_8N1, options, 7_000, (i, rng) => {
    const p = new Uint8Array(32);
    p[0] = 0x20;
    p[1] = 0x40;
    for (let c = 0; c < 14; c++) {
      const v = 1000 + Math.round(stick(i, c, rng) * 1000);
      p[2 + 2 * c] = v & 0xff;
      p[3 + 2 * c] = v >> 8;
    }
    let sum = 0;
    for (const byte of p.subarray(0, 30)) sum += byte;
    const check = (0xffff - sum) & 0xffff;
    p[30] = check & 0xff;
    p[31] = check >> 8;
    return p;
  });
}

/** SBUS's line setting: 100000 baud, 8 data bits, even parity, 2 stop bits, inverted. */
export const SBUS_FORMAT: Readonly<SerialFormat> = Object.freeze({
  baudRate: 100_000,
  dataBits: 8,
  parity: 'even',
  stopBits: 2,
  inverted: true,
});

/**
 * SBUS: 0x0F, 16 channels of 11 bits packed LSB first in 22 bytes, a flags byte and 0x00;
 * 25 bytes every 14 ms (or 7 ms in fast mode) at 100000 8E2, inverted.
 */
export function sbusStream(options: StreamOptions): Transmission {
  return packetStream(SBUS_FORMAT, options, 14_000, (i, rng) => {
    const p = new Uint8Array(25);
    p[0] = 0x0f;
    let bit = 0;
    for (let c = 0; c < 16; c++) {
      const v = 172 + Math.round(stick(i, c, rng) * 1639);
      for (let b = 0; b < 11; b++, bit++) if ((v >> b) & 1) p[1 + (bit >> 3)]! |= 1 << (bit & 7);
    }
    p[23] = 0;
    p[24] = 0;
    return p;
  });
}

/** CRSF's line setting: 420000 baud 8N1, not inverted. */
export const CRSF_FORMAT: Readonly<SerialFormat> = Object.freeze({
  baudRate: 420_000,
  dataBits: 8,
  parity: 'none',
  stopBits: 1,
  inverted: false,
});

/**
 * CRSF RC channels: 0xC8 (flight controller address), length 24, type 0x16, 16 channels of
 * 11 bits packed in 22 bytes, CRC-8/DVB-S2 over type and payload; every 4 ms (250 Hz) at
 * 420000 8N1.
 */
export function crsfStream(options: StreamOptions): Transmission {
  return packetStream(CRSF_FORMAT, options, 4_000, (i, rng) => {
    const p = new Uint8Array(26);
    p[0] = 0xc8;
    p[1] = 24;
    p[2] = 0x16;
    let bit = 0;
    for (let c = 0; c < 16; c++) {
      const v = 172 + Math.round(stick(i, c, rng) * 1639);
      for (let b = 0; b < 11; b++, bit++) if ((v >> b) & 1) p[3 + (bit >> 3)]! |= 1 << (bit & 7);
    }
    p[25] = crc8DvbS2(p, 2, 25);
    return p;
  });
}
