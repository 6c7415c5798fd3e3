/**
 * The line model: what is on the wire, bit by bit, and what a UART makes of it.
 *
 * A transmitter puts bytes on a line at some speed, parity, stop bits and polarity
 * (`lineSignal`); `uartReceive` samples that line as a 16550-style UART at another (or the
 * same) setting would, and returns the bytes it delivers and the errors it reports, each with
 * its position. That is how a USB adapter opened at 115200 8N1 sees an SBUS receiver, a CRSF
 * receiver, a satellite wired through an inverter, or noise, and it lets the doctor be tested
 * without hardware.
 *
 * Also here: byte-exact generators of the foreign protocols a user may have plugged in instead
 * of a satellite (SRXL v1, SRXL2, FlySky IBUS, SBUS, CRSF) and plain noise.
 *
 * Pure ECMAScript: no DOM, no Node, no timers; deterministic from a seed.
 */
import { BAUD_RATE } from '../decoder/spec.js';
import { Prng } from './prng.js';
import type { SimChunk } from './simulator.js';

export type Parity = 'none' | 'even' | 'odd';

/** A serial line setting, as a transmitter uses it or a receiver is opened with. */
export interface SerialFormat {
  baudRate: number;
  /** Default 8. */
  dataBits?: 7 | 8;
  /** Default 'none'. */
  parity?: Parity;
  /** Default 1. */
  stopBits?: 1 | 2;
  /** Idle low, start bit high: e.g. SBUS, or any line through an inverter. Default false. */
  inverted?: boolean;
}

/** §7.1: what a satellite sends and what SatScope opens the port with. */
export const UART_115200_8N1: Readonly<SerialFormat> = Object.freeze({
  baudRate: BAUD_RATE,
  dataBits: 8,
  parity: 'none',
  stopBits: 1,
  inverted: false,
});

/** Bytes as a transmitter sends them: each byte's start-bit edge time, µs. */
export interface Transmission {
  format: SerialFormat;
  bytes: Uint8Array;
  /** Start of each byte's start bit, µs, non-decreasing. A byte that would overlap the previous one starts when it ends. */
  timesUs: Float64Array;
}

/**
 * A line's level over time: `initial` until the first edge, then it toggles at each of
 * `edgesUs` (increasing). Level 1 is high (mark, the idle state of a normal UART line).
 */
export interface LineSignal {
  initial: 0 | 1;
  edgesUs: Float64Array;
  startUs: number;
  endUs: number;
}

/** A read error as WebSerial names them (the stream errors with a DOMException of this name). */
export type UartErrorKind = 'FramingError' | 'ParityError' | 'BreakError';

export interface UartError {
  kind: UartErrorKind;
  /** Start of the character that failed, µs. */
  timeUs: number;
  /** Bytes delivered before this error (its position in `bytes`). */
  offset: number;
  /** The data bits the UART sampled (0 for a break). */
  value: number;
}

/** What a UART delivers. Characters with errors are dropped, as Chrome's serial reader does, and reported in `errors`. */
export interface UartResult {
  bytes: Uint8Array;
  /** Start of each delivered byte's start bit, µs. */
  timesUs: Float64Array;
  errors: UartError[];
}

interface Resolved {
  bitUs: number;
  dataBits: number;
  parity: Parity;
  stopBits: number;
  inverted: boolean;
  /** Bits in one character, start to last stop bit. */
  frameBits: number;
}

function resolve(format: SerialFormat): Resolved {
  const { baudRate } = format;
  if (!(Number.isFinite(baudRate) && baudRate > 0)) throw new RangeError(`baudRate must be a positive number, not ${baudRate}`);
  const dataBits = format.dataBits ?? 8;
  if (dataBits !== 7 && dataBits !== 8) throw new RangeError(`dataBits must be 7 or 8, not ${String(dataBits)}`);
  const parity = format.parity ?? 'none';
  if (parity !== 'none' && parity !== 'even' && parity !== 'odd')
    throw new RangeError(`parity must be none, even or odd, not ${String(parity)}`);
  const stopBits = format.stopBits ?? 1;
  if (stopBits !== 1 && stopBits !== 2) throw new RangeError(`stopBits must be 1 or 2, not ${String(stopBits)}`);
  return {
    bitUs: 1e6 / baudRate,
    dataBits,
    parity,
    stopBits,
    inverted: format.inverted ?? false,
    frameBits: 1 + dataBits + (parity === 'none' ? 0 : 1) + stopBits,
  };
}

/** Number of 1 bits in the low `bits` bits of `value`. */
function ones(value: number, bits: number): number {
  let n = 0;
  for (let i = 0; i < bits; i++) n += (value >> i) & 1;
  return n;
}

/** Time one character occupies on the line in this format, µs. */
export function characterTimeUs(format: SerialFormat): number {
  const r = resolve(format);
  return r.frameBits * r.bitUs;
}

/**
 * The line while `tx` is sent: idle before the first byte (from `startUs`, default 1 ms before
 * it) and after the last (until `endUs`, default 1 ms after it).
 *
 * @throws {RangeError} on a format the model does not know, or times that go backwards.
 */
export function lineSignal(tx: Transmission, options: { startUs?: number; endUs?: number } = {}): LineSignal {
  const f = resolve(tx.format);
  const n = tx.bytes.length;
  if (tx.timesUs.length !== n) throw new RangeError(`timesUs has length ${tx.timesUs.length}, bytes ${n}`);
  const idle = f.inverted ? 0 : 1;
  const first = tx.timesUs[0] ?? 0;
  const startUs = options.startUs ?? first - 1000;
  const edges: number[] = [];
  let level = idle;
  let lastEnd = -Infinity;
  const set = (l: number, t: number): void => {
    if (l !== level) {
      edges.push(t);
      level = l;
    }
  };
  let previous = -Infinity;
  for (const [i, b] of tx.bytes.entries()) {
    const at = tx.timesUs[i] ?? NaN;
    if (!(at >= previous)) throw new RangeError(`timesUs[${i}] goes backwards`);
    previous = at;
    const t0 = Math.max(at, lastEnd);
    const byte = b & ((1 << f.dataBits) - 1);
    let bit = 0;
    const put = (logical: number): void => {
      set(f.inverted ? 1 - logical : logical, t0 + bit * f.bitUs);
      bit++;
    };
    put(0); // start
    for (let b = 0; b < f.dataBits; b++) put((byte >> b) & 1); // LSB first
    if (f.parity !== 'none') put((ones(byte, f.dataBits) + (f.parity === 'odd' ? 1 : 0)) & 1);
    for (let s = 0; s < f.stopBits; s++) put(1);
    lastEnd = t0 + f.frameBits * f.bitUs;
  }
  const endUs = options.endUs ?? (n > 0 ? lastEnd + 1000 : startUs + 1000);
  return { initial: idle as 0 | 1, edgesUs: Float64Array.from(edges), startUs, endUs };
}

/** Level of the signal at `t`, with a cursor that only moves forward (sample times increase). */
class Sampler {
  #k = 0;
  constructor(readonly signal: LineSignal) {}
  level(t: number): 0 | 1 {
    const e = this.signal.edgesUs;
    while ((e[this.#k] ?? Infinity) <= t) this.#k++;
    return (this.signal.initial ^ (this.#k & 1)) as 0 | 1;
  }
  /** First time ≥ t where the line falls (a high-to-low edge), or Infinity. */
  nextFall(t: number): number {
    if (this.level(t) === 0) {
      // Already low: the fall happened before t; wait for it to rise, then fall.
      const rise = this.nextEdge(t);
      return rise === Infinity ? Infinity : this.nextEdge(rise);
    }
    return this.nextEdge(t);
  }
  /** First time ≥ t where the line is high, or Infinity. */
  nextHigh(t: number): number {
    return this.level(t) === 1 ? t : this.nextEdge(t);
  }
  /** Time of the first edge strictly after t. */
  nextEdge(t: number): number {
    this.level(t);
    const e = this.signal.edgesUs;
    return e[this.#k] ?? Infinity;
  }
}

/**
 * Samples a line as a UART opened with `format` would (default 115200 8N1, not inverted):
 * it waits for a falling edge, checks the start bit at its middle, samples every bit at its
 * middle, and checks parity and the first stop bit. A low stop bit is a framing error (the
 * UART then takes that low level as the next start bit, as a 16550 does), or a break when
 * every bit of the character was low (the UART then waits for the line to go high). Characters
 * with errors are not delivered.
 */
export function uartReceive(signal: LineSignal, format: SerialFormat = UART_115200_8N1): UartResult {
  const f = resolve(format);
  const sampler = new Sampler(signal);
  // A receiver opened "inverted" reads the complement; WebSerial cannot, but a probe model may.
  const read = (t: number): number => (f.inverted ? 1 - sampler.level(t) : sampler.level(t));
  const bytes: number[] = [];
  const times: number[] = [];
  const errors: UartError[] = [];
  const lastSample = (f.frameBits - f.stopBits) * f.bitUs; // from the start bit's middle to the stop bit's
  // The line must be seen idle before the first start bit.
  let t = f.inverted ? nextLow(sampler, signal.startUs) : sampler.nextHigh(signal.startUs);
  let midStart = NaN;
  for (;;) {
    if (Number.isNaN(midStart)) {
      const fall = f.inverted ? nextRise(sampler, t) : sampler.nextFall(t);
      if (fall === Infinity) break;
      midStart = fall + f.bitUs / 2;
    }
    if (midStart + lastSample > signal.endUs) break;
    if (read(midStart) !== 0) {
      // A glitch, not a start bit: hunt again from here.
      t = midStart;
      midStart = NaN;
      continue;
    }
    let value = 0;
    for (let b = 0; b < f.dataBits; b++) value |= read(midStart + (1 + b) * f.bitUs) << b;
    let parityBit = 0;
    let parityOk = true;
    if (f.parity !== 'none') {
      parityBit = read(midStart + (1 + f.dataBits) * f.bitUs);
      parityOk = ((ones(value, f.dataBits) + parityBit + (f.parity === 'odd' ? 1 : 0)) & 1) === 0;
    }
    const stopAt = midStart + lastSample;
    const stop = read(stopAt);
    const startUs = midStart - f.bitUs / 2;
    if (stop === 1) {
      if (parityOk) {
        bytes.push(value);
        times.push(startUs);
      } else {
        errors.push({ kind: 'ParityError', timeUs: startUs, offset: bytes.length, value });
      }
      t = stopAt;
      midStart = NaN;
    } else if (value === 0 && parityBit === 0) {
      errors.push({ kind: 'BreakError', timeUs: startUs, offset: bytes.length, value: 0 });
      // One break per low stretch: wait for the line to be released.
      const high = f.inverted ? nextLow(sampler, stopAt) : sampler.nextHigh(stopAt);
      if (high === Infinity) break;
      t = high;
      midStart = NaN;
    } else {
      errors.push({ kind: 'FramingError', timeUs: startUs, offset: bytes.length, value });
      // 16550 behaviour: the low "stop bit" is taken as the next start bit, sampled again.
      midStart = stopAt;
    }
  }
  return { bytes: Uint8Array.from(bytes), timesUs: Float64Array.from(times), errors };
}

function nextRise(s: Sampler, t: number): number {
  if (s.level(t) === 1) {
    const fall = s.nextEdge(t);
    return fall === Infinity ? Infinity : s.nextEdge(fall);
  }
  return s.nextEdge(t);
}

function nextLow(s: Sampler, t: number): number {
  return s.level(t) === 0 ? t : s.nextEdge(t);
}

/** Sends `tx` and reads it back with a UART opened at `receiver` (default 115200 8N1). */
export function receiveAs(tx: Transmission, receiver: SerialFormat = UART_115200_8N1): UartResult {
  return uartReceive(lineSignal(tx), receiver);
}

// ---------------------------------------------------------------------------------------------
// What else may be on the wire
// ---------------------------------------------------------------------------------------------

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
  const f = resolve(format);
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
  const charUs = f.frameBits * f.bitUs;
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

/**
 * Plain noise on a floating or badly grounded line: levels that change after random times
 * (exponentially distributed, mean `meanRunUs`, default 120 µs), from `startUs` for
 * `durationUs`.
 */
export function noiseSignal(options: { durationUs: number; startUs?: number; meanRunUs?: number; seed?: number }): LineSignal {
  const start = options.startUs ?? 1000;
  const mean = options.meanRunUs ?? 120;
  if (!(mean > 0)) throw new RangeError(`meanRunUs must be positive, not ${mean}`);
  const rng = new Prng(options.seed ?? 1);
  const edges: number[] = [];
  let t = start;
  const end = start + options.durationUs;
  for (;;) {
    t += -mean * Math.log(1 - rng.next());
    if (t >= end) break;
    edges.push(t);
  }
  return { initial: 1, edgesUs: Float64Array.from(edges), startUs: start - 1000, endUs: end + 1000 };
}
