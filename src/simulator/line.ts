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
 * Also here: plain noise. What else a user may have plugged in instead of a satellite is
 * protocols.ts.
 *
 * Pure ECMAScript: no DOM, no Node, no timers; deterministic from a seed.
 */
import { BAUD_RATE } from '../decoder/spec.js';
import { Prng } from './prng.js';

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
