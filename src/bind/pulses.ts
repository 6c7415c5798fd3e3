/**
 * Binding a Spektrum satellite from a USB-serial adapter (spec Rev G §7.2).
 *
 * Within 200 ms of power-up the host must give the satellite's DATA line N falling pulses
 * (3–10); N picks the bind mode. Flight controllers bit-bang them: Betaflight and PX4 drive the
 * pin low 120 µs, high 120 µs, 60–72 ms after power-up. A web page cannot bit-bang, but it can
 * write bytes: the adapter's TX line idles high, and a UART frame is a start bit (low), 8 data
 * bits LSB first and 1 or 2 stop bits (high). Choosing the baud rate and the bytes so that the
 * frames draw N low phases of about 120 µs does the job, and everything here derives that from
 * a bit-level model of the line and of how each adapter chip makes its baud rate.
 *
 * Pure ECMAScript: no DOM, no Node, no timers. `bindTimeline` only says what a driver should do
 * and when; the driver (WebSerial) does it.
 */
import {
  SYSTEM_DSM2_11MS_2048, SYSTEM_DSM2_22MS_1024, SYSTEM_DSMX_11MS_2048, SYSTEM_DSMX_22MS_2048,
} from '../decoder/spec.js';

// ---------------------------------------------------------------------------------------------
// §7.2 bind modes

export interface BindMode {
  /** Falling pulses the host sends (3–10). */
  readonly pulses: number;
  /** §7.3: exactly one remote in a system may be internal (the "A" receiver). */
  readonly remote: 'internal' | 'external';
  readonly protocol: 'DSM2' | 'DSMX';
  /** The fastest frame period the bind accepts; 11 ms also allows 22 ms. */
  readonly periodMs: 11 | 22;
  /** §7.2 recommends DSMX 11 ms: 9 pulses (internal) or 10 (external). */
  readonly recommended: boolean;
  /**
   * The system byte (§8.3) an internal remote reports once bound, when the transmitter runs this
   * protocol (a DSMX bind falls back to DSM2, and 11 ms to 22 ms, when the transmitter cannot).
   */
  readonly systemByte: number;
  readonly description: string;
}

function mode(pulses: number, remote: BindMode['remote'], protocol: BindMode['protocol'], periodMs: 11 | 22, systemByte: number): BindMode {
  const recommended = protocol === 'DSMX' && periodMs === 11;
  const also = [
    periodMs === 11 ? 'also accepts 22 ms' : '',
    protocol === 'DSMX' ? 'falls back to DSM2' : 'not recommended; DSM2 transmitters are not sold in Europe',
  ].filter(Boolean).join('; ');
  return {
    pulses, remote, protocol, periodMs, recommended, systemByte,
    description: `${pulses} pulses: ${remote} remote, ${protocol} ${periodMs} ms (${also})`
      + (remote === 'internal' ? '. Only one remote in a system may be internal.' : '.'),
  };
}

/** §7.2's two tables, by pulse count. */
export const BIND_MODES: readonly BindMode[] = [
  mode(3, 'internal', 'DSM2', 22, SYSTEM_DSM2_22MS_1024),
  mode(4, 'external', 'DSM2', 22, SYSTEM_DSM2_22MS_1024),
  mode(5, 'internal', 'DSM2', 11, SYSTEM_DSM2_11MS_2048),
  mode(6, 'external', 'DSM2', 11, SYSTEM_DSM2_11MS_2048),
  mode(7, 'internal', 'DSMX', 22, SYSTEM_DSMX_22MS_2048),
  mode(8, 'external', 'DSMX', 22, SYSTEM_DSMX_22MS_2048),
  mode(9, 'internal', 'DSMX', 11, SYSTEM_DSMX_11MS_2048),
  mode(10, 'external', 'DSMX', 11, SYSTEM_DSMX_11MS_2048),
];

export const MIN_BIND_PULSES = 3;
export const MAX_BIND_PULSES = 10;

/** The mode `n` pulses select; RangeError unless n is an integer 3–10. */
export function bindMode(n: number): BindMode {
  checkPulses(n);
  return BIND_MODES[n - MIN_BIND_PULSES]!;
}

/** The pulse count for a mode. */
export function bindPulsesFor(remote: BindMode['remote'], protocol: BindMode['protocol'] = 'DSMX', periodMs: 11 | 22 = 11): number {
  const m = BIND_MODES.find((b) => b.remote === remote && b.protocol === protocol && b.periodMs === periodMs);
  if (!m) throw new RangeError(`no bind mode ${remote} ${protocol} ${periodMs} ms`);
  return m.pulses;
}

function checkPulses(n: number): void {
  if (!Number.isInteger(n) || n < MIN_BIND_PULSES || n > MAX_BIND_PULSES) {
    throw new RangeError(`bind pulses must be an integer ${MIN_BIND_PULSES}–${MAX_BIND_PULSES}, not ${String(n)}`);
  }
}

// ---------------------------------------------------------------------------------------------
// Timing targets

/** What firmware does (Betaflight, PX4, ArduPilot): each phase 120 µs. */
export const BIND_PULSE_TARGET_US = 120;
/**
 * Accepted phase widths. The spec gives a count, not widths, so the receiver counts edges; hosts
 * known to bind use 116 µs (MultiWii-derived code) and 120 µs (Betaflight, PX4, ArduPilot). We
 * allow ±25 %: three times the worst deviation of the plan every adapter can make (+8.5 %),
 * still far from glitch widths (a few µs) and from the millisecond gaps an edge counter may use
 * to end a sequence. Only the phases between pulses are bounded above: the high after the last
 * pulse is the idle line.
 */
export const BIND_PULSE_MIN_US = 90;
export const BIND_PULSE_MAX_US = 150;
/**
 * When pulses may start, in ms after power-up. Spec: all within 200 ms. Betaflight notes the
 * window "is around 20-140ms after powerup" and waits 60 ms; PX4 waits 72 ms; MultiWii tuned
 * for ~68 ms. 60 ms leaves 40 ms for a late boot and 140 ms for host jitter.
 */
export const BIND_WINDOW = { earliestMs: 20, recommendedMs: 60, latestMs: 200 } as const;

// ---------------------------------------------------------------------------------------------
// USB-serial chips: the baud rate they really make for a requested one

/**
 * Chips, and how their baud rate is made, as the Linux drivers compute it (the dividers are the
 * chip's, so other systems reach the same rates; their drivers may round a little differently):
 * - `ft232r`: FTDI FT232R/FT232BM/FT231X: 3 MHz / (n + k/8), n ≥ 2, k 0–7; the driver rounds
 *   the divisor 3 MHz / baud to the nearest eighth.
 * - `cp2102`: Silicon Labs CP2102/CP2103: only the rates of AN205 table 1 (the table lives in the
 *   chip); a request maps to the first entry whose range covers it (41667 → 51200!).
 * - `cp2102n`: CP2102N/CP2104/CP2105/CP2108: 24 MHz / n, any n (CP2102N shares the CP2102's
 *   USB ID, so a page cannot tell them apart).
 * - `ch340`: WCH CH340/CH341: 48 MHz / (2^(12−3·ps−fact) · div), ps 0–3, fact 0–1, div 2–255,
 *   the Linux driver's search.
 * - `pl2303`: Prolific PL2303HX(A)/HXD: the standard rates directly, others 12 MHz·32 /
 *   (mantissa · 4^exp), mantissa < 512 (truncating).
 * - `pl2303ta`: PL2303TA/TB: 12 MHz·32 / (mantissa · 2^exp), mantissa < 2048.
 * - `pl2303g`: PL2303G (HXN): the rate is passed to the chip as is; its divider is undocumented,
 *   modelled as exact.
 */
export type UsbSerialChip = 'ft232r' | 'cp2102' | 'cp2102n' | 'ch340' | 'pl2303' | 'pl2303ta' | 'pl2303g';

export const USB_SERIAL_CHIPS: readonly UsbSerialChip[] = ['ft232r', 'cp2102', 'cp2102n', 'ch340', 'pl2303', 'pl2303ta', 'pl2303g'];
/** The four families a user is likely to own; a plan for these works on any of them. */
export const DEFAULT_CHIPS: readonly UsbSerialChip[] = ['ft232r', 'cp2102', 'ch340', 'pl2303'];

/** AN205 table 1: [rate, highest request that maps to it]. */
const CP2102_TABLE: readonly (readonly [number, number])[] = [
  [300, 300], [600, 600], [1200, 1200], [1800, 1800], [2400, 2400], [4000, 4000], [4800, 4803],
  [7200, 7207], [9600, 9612], [14400, 14428], [16000, 16062], [19200, 19250], [28800, 28912],
  [38400, 38601], [51200, 51558], [56000, 56280], [57600, 58053], [64000, 64111], [76800, 77608],
  [115200, 117028], [128000, 129347], [153600, 156868], [230400, 237832], [250000, 254234],
  [256000, 273066], [460800, 491520], [500000, 567138], [576000, 670254], [921600, Infinity],
];
/** Rates a PL2303 sets directly. */
const PL2303_DIRECT: readonly number[] = [
  75, 150, 300, 600, 1200, 1800, 2400, 3600, 4800, 7200, 9600, 14400, 19200, 28800, 38400, 57600,
  115200, 230400, 460800, 614400, 921600, 1228800, 2457600, 3000000, 6000000,
];

/** `Math.round(a / b)` as C's DIV_ROUND_CLOSEST for positive integers. */
const divRoundClosest = (a: number, b: number) => Math.floor((a + Math.floor(b / 2)) / b);

function ch340Rate(requested: number): number {
  const clk = 48_000_000;
  const clkDiv = (ps: number, fact: number) => 2 ** (12 - 3 * ps - fact);
  const minRate = (ps: number) => Math.floor(clk / (clkDiv(ps, 1) * 512));
  const speed = Math.min(Math.max(requested, Math.ceil(clk / (clkDiv(0, 0) * 256))), clk / (clkDiv(3, 0) * 2));
  let fact = 1;
  let ps = 3;
  while (ps > 0 && !(speed > minRate(ps))) ps--;
  let cd = clkDiv(ps, fact);
  let div = Math.floor(clk / (cd * speed));
  if (div < 9 || div > 255) {
    div = Math.floor(div / 2);
    cd *= 2;
    fact = 0;
  }
  // Pick the next divisor when that rate is closer (the driver's ×16 integer comparison).
  if (Math.floor((16 * clk) / (cd * div)) - 16 * speed >= 16 * speed - Math.floor((16 * clk) / (cd * (div + 1)))) div++;
  if (fact === 1 && div % 2 === 0) {
    div /= 2;
    fact = 0;
  }
  return clk / (clkDiv(ps, fact) * div);
}

function pl2303Rate(requested: number, alt: boolean): number {
  if (!alt) {
    let nearest = PL2303_DIRECT[PL2303_DIRECT.length - 1]!;
    for (let i = 0; i < PL2303_DIRECT.length; i++) {
      const hi = PL2303_DIRECT[i]!;
      if (hi > requested) {
        const lo = i > 0 ? PL2303_DIRECT[i - 1]! : hi;
        nearest = i > 0 && hi - requested > requested - lo ? lo : hi;
        break;
      }
    }
    if (nearest === requested) return requested;
  } else if (PL2303_DIRECT.includes(requested)) {
    return requested;
  }
  const baseline = 12_000_000 * 32;
  let mantissa = Math.max(1, Math.floor(baseline / requested));
  let exponent = 0;
  const limit = alt ? 2048 : 512;
  const maxExp = alt ? 15 : 7;
  while (mantissa >= limit) {
    if (exponent < maxExp) {
      mantissa = Math.floor(mantissa / (alt ? 2 : 4));
      exponent++;
    } else {
      mantissa = limit - 1;
      break;
    }
  }
  return Math.floor(Math.floor(baseline / mantissa) / (alt ? 2 ** exponent : 4 ** exponent));
}

/** The baud rate `chip` really runs at when `requested` (an integer, as WebSerial takes) is set. */
export function chipBaudRate(chip: UsbSerialChip, requested: number): number {
  if (!Number.isInteger(requested) || requested <= 0) throw new RangeError(`baud rate must be a positive integer, not ${requested}`);
  switch (chip) {
    case 'ft232r': {
      // Divisor in eighths of 3 MHz, at most 2^17 − 1.
      const d3 = Math.min(Math.max(divRoundClosest(48_000_000, 2 * requested), 8), 0x1ffff);
      return 24_000_000 / d3;
    }
    case 'cp2102': {
      const b = Math.max(requested, 300);
      for (const [rate, high] of CP2102_TABLE) if (b <= high) return rate;
      return 921600;
    }
    case 'cp2102n': {
      const prescale = requested <= 365 ? 4 : 1;
      return 48_000_000 / (2 * prescale * divRoundClosest(48_000_000, 2 * prescale * requested));
    }
    case 'ch340':
      return ch340Rate(requested);
    case 'pl2303':
      return pl2303Rate(requested, false);
    case 'pl2303ta':
      return pl2303Rate(requested, true);
    case 'pl2303g':
      return requested;
  }
}

/**
 * The chips a WebSerial port may be, from `port.getInfo()`. Unknown IDs give every chip in
 * DEFAULT_CHIPS, so the plan stays one that works anywhere.
 */
export function chipsForUsbId(usbVendorId?: number, usbProductId?: number): readonly UsbSerialChip[] {
  switch (usbVendorId) {
    case 0x0403: return ['ft232r'];
    case 0x10c4: return ['cp2102', 'cp2102n'];
    case 0x1a86: return ['ch340'];
    case 0x067b:
      if (usbProductId !== undefined && usbProductId >= 0x23a3 && usbProductId <= 0x23f3 && (usbProductId & 0xf) === 3) return ['pl2303g'];
      return ['pl2303', 'pl2303ta'];
    default: return DEFAULT_CHIPS;
  }
}

// ---------------------------------------------------------------------------------------------
// The line, bit by bit

export type StopBits = 1 | 2;

/** One stretch of constant level on the TX line. 1 is idle (high, mark), 0 is low (space). */
export interface LineSegment {
  readonly level: 0 | 1;
  readonly durationUs: number;
}

/** A byte's frame as line levels, one per bit: start 0, data LSB first, stop bit(s) 1. */
export function frameLevels(byte: number, stopBits: StopBits = 1): (0 | 1)[] {
  const bits: (0 | 1)[] = [0];
  for (let i = 0; i < 8; i++) bits.push(((byte >> i) & 1) as 0 | 1);
  for (let i = 0; i < stopBits; i++) bits.push(1);
  return bits;
}

/**
 * The TX line while `bytes` are sent at `baudRate`, 8 data bits, no parity, `stopBits`: idle
 * high for `idleBeforeUs`, the frames, idle high for `idleAfterUs`. Adjacent equal levels are
 * merged, so every 0 segment is one low pulse. `gapsUs` inserts idle time after byte i (before
 * byte i + 1), as adapters may between bytes; an array or a function of i.
 */
export function uartWaveform(
  bytes: ArrayLike<number>,
  baudRate: number,
  stopBits: StopBits = 1,
  idleBeforeUs = 0,
  idleAfterUs = 0,
  gapsUs?: ArrayLike<number> | ((index: number) => number),
): LineSegment[] {
  if (!(baudRate > 0) || !Number.isFinite(baudRate)) throw new RangeError(`baud rate must be positive, not ${baudRate}`);
  if (stopBits !== 1 && stopBits !== 2) throw new RangeError(`stop bits must be 1 or 2, not ${String(stopBits)}`);
  if (!(idleBeforeUs >= 0) || !(idleAfterUs >= 0)) throw new RangeError('idle times must be ≥ 0');
  const bitUs = 1e6 / baudRate;
  const out: { level: 0 | 1; durationUs: number }[] = [];
  const put = (level: 0 | 1, durationUs: number) => {
    if (durationUs <= 0) return;
    const last = out[out.length - 1];
    if (last && last.level === level) last.durationUs += durationUs;
    else out.push({ level, durationUs });
  };
  const gapAfter = (i: number): number => {
    if (!gapsUs) return 0;
    const g = typeof gapsUs === 'function' ? gapsUs(i) : (gapsUs[i] ?? 0);
    if (!(g >= 0)) throw new RangeError(`gap after byte ${i} must be ≥ 0, not ${g}`);
    return g;
  };
  put(1, idleBeforeUs);
  for (let i = 0; i < bytes.length; i++) {
    const b = bytes[i]!;
    if (!Number.isInteger(b) || b < 0 || b > 255) throw new RangeError(`byte ${i} is not 0–255: ${b}`);
    // Count equal bits before multiplying, so durations are whole multiples of the bit time.
    const levels = frameLevels(b, stopBits);
    let run = 1;
    for (let k = 1; k <= levels.length; k++) {
      if (k < levels.length && levels[k] === levels[k - 1]) run++;
      else {
        put(levels[k - 1]!, run * bitUs);
        run = 1;
      }
    }
    if (i < bytes.length - 1) put(1, gapAfter(i));
  }
  put(1, idleAfterUs);
  return out;
}

/** Falling edges (1 → 0) on a line that was at `initialLevel` (idle high) before the first segment. */
export function countFallingEdges(waveform: readonly LineSegment[], initialLevel: 0 | 1 = 1): number {
  let edges = 0;
  let prev = initialLevel;
  for (const s of waveform) {
    if (s.durationUs <= 0) continue;
    if (prev === 1 && s.level === 0) edges++;
    prev = s.level;
  }
  return edges;
}

export interface PulseMeasurement {
  /** Falling edges. */
  readonly edges: number;
  /** Each low phase, µs. */
  readonly lowUs: number[];
  /** Each high phase between two low phases, µs (edges − 1 of them). */
  readonly highUs: number[];
  /** Time of the first falling edge and of the last rising edge, µs from the waveform's start. */
  readonly firstFallUs: number;
  readonly lastRiseUs: number;
}

/** The low phases and the high phases between them, as a receiver counting edges sees them. */
export function measurePulses(waveform: readonly LineSegment[], initialLevel: 0 | 1 = 1): PulseMeasurement {
  const lowUs: number[] = [];
  const highUs: number[] = [];
  let t = 0;
  let prev = initialLevel;
  let pendingHigh: number | undefined;
  let firstFallUs = NaN;
  let lastRiseUs = NaN;
  let currentLow = 0;
  for (const s of waveform) {
    if (s.durationUs <= 0) continue;
    if (s.level === 0) {
      if (prev === 1) {
        if (Number.isNaN(firstFallUs)) firstFallUs = t;
        if (pendingHigh !== undefined) highUs.push(pendingHigh);
        pendingHigh = undefined;
        lowUs.push(0);
        currentLow = lowUs.length - 1;
      }
      lowUs[currentLow]! += s.durationUs;
      lastRiseUs = t + s.durationUs;
    } else if (lowUs.length > 0) {
      pendingHigh = (pendingHigh ?? 0) + s.durationUs;
    }
    prev = s.level;
    t += s.durationUs;
  }
  return { edges: lowUs.length, lowUs, highUs, firstFallUs, lastRiseUs };
}

// ---------------------------------------------------------------------------------------------
// Planning the bytes

export interface PlanOptions {
  /** Chips the plan must work on (default DEFAULT_CHIPS); `chipsForUsbId` narrows it. */
  chips?: readonly UsbSerialChip[];
  /** Largest accepted |actual − requested| / requested for every chip (default 0.02). */
  baudTolerance?: number;
  /** Target width of each phase, µs (default 120). */
  targetUs?: number;
  /** Only these baud rates (default: derived, see planPulses). */
  baudRates?: readonly number[];
  /** Only these stop-bit settings (default [1, 2]). */
  stopBits?: readonly StopBits[];
  /** Most pulses one byte may carry (default 5, all a frame can hold). */
  maxPulsesPerByte?: number;
  /**
   * Largest accepted worst deviation (default 0.25: BIND_PULSE_MIN_US–BIND_PULSE_MAX_US around 120 µs).
   * When no candidate is this good, planPulses throws a RangeError.
   */
  maxDeviation?: number;
}

export interface ChipRate {
  readonly chip: UsbSerialChip;
  readonly baudRate: number;
  /** (actual − requested) / requested. */
  readonly error: number;
}

export interface PulsePlan {
  /** Pulses (N). */
  readonly pulses: number;
  /** The rate to open the port at (integer, as WebSerial takes it). */
  readonly baudRate: number;
  readonly stopBits: StopBits;
  /** Write these in one `write()`; they go in one USB packet and leave back to back. */
  readonly bytes: Uint8Array;
  /** Low phases at the requested rate, back-to-back bytes, µs. */
  readonly lowUs: number[];
  /** High phases between pulses, µs (pulses − 1). Inter-byte gaps only lengthen these. */
  readonly highUs: number[];
  /** Time the bytes occupy on the wire, µs (first falling edge to the end of the last stop bit). */
  readonly totalUs: number;
  /** Falling edges the bytes make (= pulses). */
  readonly edges: number;
  /** One bit, µs. */
  readonly bitUs: number;
  /** Bits per frame (10 or 11). */
  readonly frameBits: number;
  /** Most pulses carried by one byte. */
  readonly pulsesPerByte: number;
  /** Every chip's real rate for `baudRate`. */
  readonly chipRates: readonly ChipRate[];
  /**
   * The cost that chose this plan: the worst |phase − target| / target over every low phase
   * and every high phase between pulses, at the requested rate and at each chip's real rate.
   */
  readonly worstDeviation: number;
}

/** Rates worth trying: whole-bit multiples of the target, and every rate a fixed-table chip has. */
function candidateRates(targetUs: number): number[] {
  const set = new Set<number>();
  for (let bitsPerPhase = 1; bitsPerPhase <= 9; bitsPerPhase++) set.add(Math.round((bitsPerPhase * 1e6) / targetUs));
  for (const [rate] of CP2102_TABLE) set.add(rate);
  for (const rate of PL2303_DIRECT) set.add(rate);
  // A phase is at least one bit and a frame at most 11: beyond these rates no frame reaches 120 µs.
  const max = Math.ceil((11 * 1e6) / (targetUs * 0.5));
  return [...set].filter((r) => r >= 300 && r <= max).sort((a, b) => a - b);
}

/** Runs of equal bits in a frame: [low, high, low, high, …], always starting low, ending high. */
function frameRuns(byte: number, stopBits: StopBits): number[] {
  const levels = frameLevels(byte, stopBits);
  const runs: number[] = [];
  let run = 1;
  for (let k = 1; k <= levels.length; k++) {
    if (k < levels.length && levels[k] === levels[k - 1]) run++;
    else {
      runs.push(run);
      run = 1;
    }
  }
  return runs;
}

interface ByteChoice {
  byte: number;
  pulses: number;
  /** Cost when another byte follows (its last high is a real phase). */
  inner: number;
  /** Cost as the last byte (its last high runs into the idle line). */
  last: number;
}

/**
 * Plans the bytes for `n` bind pulses.
 *
 * Candidates: for each rate in `baudRates` (default: round(k · 10⁶ / 120) for k = 1–9 bits per
 * phase, plus every rate in the CP2102 and PL2303 fixed tables) that every chip in `chips` makes
 * within `baudTolerance`, each stop-bit setting, and each cap of 1–5 pulses per byte, the best
 * byte sequence is found exactly: every byte's frame splits into runs (low, high, …); a byte is
 * scored by its worst run against the target, at the requested and at every chip's real rate;
 * a small dynamic program over the pulse count picks the sequence whose worst byte is best.
 *
 * Ranking: (1) worst deviation in whole percent (truncated: below 1 % nothing a receiver that
 * counts edges could notice); (2) fewer pulses per byte — one pulse per frame makes every pulse
 * self-contained, so an adapter's gaps between bytes can only lengthen the high phase after a
 * pulse, never split or merge one; (3) smaller worst chip rate error; (4) shorter on the wire.
 *
 * With the default four chips the answer is 38400 baud, 8N1, 0xF0 per pulse: start bit + four
 * 0 bits = 5 bits low (130.2 µs), four 1 bits + stop = 5 bits high (130.2 µs). 41667 baud would
 * give exactly 120/120 µs but the CP2102 turns it into 51200 baud.
 */
export function planPulses(n: number, options: PlanOptions = {}): PulsePlan {
  checkPulses(n);
  const chips = options.chips ?? DEFAULT_CHIPS;
  const tolerance = options.baudTolerance ?? 0.02;
  const target = options.targetUs ?? BIND_PULSE_TARGET_US;
  const stopChoices = options.stopBits ?? [1, 2];
  const maxPerByte = Math.min(5, Math.max(1, Math.floor(options.maxPulsesPerByte ?? 5)));
  const maxDeviation = options.maxDeviation ?? Math.min(BIND_PULSE_MAX_US / BIND_PULSE_TARGET_US - 1, 1 - BIND_PULSE_MIN_US / BIND_PULSE_TARGET_US);
  if (!(target > 0)) throw new RangeError(`target must be positive, not ${target}`);
  const rates = options.baudRates ?? candidateRates(target);

  type Ranked = { plan: Omit<PulsePlan, 'lowUs' | 'highUs' | 'totalUs' | 'edges' | 'bitUs' | 'frameBits'>; key: number[] };
  let best: Ranked | undefined;

  for (const baudRate of rates) {
    if (!Number.isInteger(baudRate) || baudRate <= 0) throw new RangeError(`baud rate must be a positive integer, not ${baudRate}`);
    const chipRates: ChipRate[] = chips.map((chip) => {
      const actual = chipBaudRate(chip, baudRate);
      return { chip, baudRate: actual, error: actual / baudRate - 1 };
    });
    const worstRateError = chipRates.reduce((m, c) => Math.max(m, Math.abs(c.error)), 0);
    if (worstRateError > tolerance) continue;
    const bitTimes = [1e6 / baudRate, ...chipRates.map((c) => 1e6 / c.baudRate)];
    const runCost = (bits: number) => bitTimes.reduce((m, t) => Math.max(m, Math.abs(bits * t - target) / target), 0);

    for (const stopBits of stopChoices) {
      // The best byte for each pulse count, as an inner byte and as the last byte.
      const bestInner: (ByteChoice | undefined)[] = [];
      const bestLast: (ByteChoice | undefined)[] = [];
      for (let byte = 0; byte < 256; byte++) {
        const runs = frameRuns(byte, stopBits);
        const pulses = runs.length / 2;
        let allButLast = 0;
        for (let i = 0; i < runs.length - 1; i++) allButLast = Math.max(allButLast, runCost(runs[i]!));
        const choice: ByteChoice = { byte, pulses, inner: Math.max(allButLast, runCost(runs[runs.length - 1]!)), last: allButLast };
        const bi = bestInner[pulses];
        if (!bi || choice.inner < bi.inner - 1e-12) bestInner[pulses] = choice;
        const bl = bestLast[pulses];
        if (!bl || choice.last < bl.last - 1e-12) bestLast[pulses] = choice;
      }

      for (let cap = 1; cap <= maxPerByte; cap++) {
        // dp[m]: the best sequence of inner bytes carrying m pulses.
        const dp: ({ cost: number; bytes: number[] } | undefined)[] = [{ cost: 0, bytes: [] }];
        for (let m = 1; m < n; m++) {
          for (let k = 1; k <= Math.min(cap, m); k++) {
            const prev = dp[m - k];
            const c = bestInner[k];
            if (!prev || !c) continue;
            const cost = Math.max(prev.cost, c.inner);
            const cur = dp[m];
            if (!cur || cost < cur.cost - 1e-12 || (Math.abs(cost - cur.cost) <= 1e-12 && prev.bytes.length + 1 < cur.bytes.length)) {
              dp[m] = { cost, bytes: [...prev.bytes, c.byte] };
            }
          }
        }
        let seq: { cost: number; bytes: number[] } | undefined;
        for (let k = 1; k <= Math.min(cap, n); k++) {
          const prev = dp[n - k];
          const c = bestLast[k];
          if (!prev || !c) continue;
          const cost = Math.max(prev.cost, c.last);
          if (!seq || cost < seq.cost - 1e-12 || (Math.abs(cost - seq.cost) <= 1e-12 && prev.bytes.length + 1 < seq.bytes.length)) {
            seq = { cost, bytes: [...prev.bytes, c.byte] };
          }
        }
        if (!seq || seq.cost > maxDeviation + 1e-12) continue;
        const perByte = Math.max(...seq.bytes.map((b) => frameRuns(b, stopBits).length / 2));
        const totalUs = (seq.bytes.length * (9 + stopBits) * 1e6) / baudRate;
        const key = [Math.floor(seq.cost * 100 + 1e-9), perByte, worstRateError, totalUs];
        if (!best || lexLess(key, best.key)) {
          best = {
            key,
            plan: {
              pulses: n, baudRate, stopBits, bytes: Uint8Array.from(seq.bytes), pulsesPerByte: perByte,
              chipRates, worstDeviation: seq.cost,
            },
          };
        }
      }
    }
  }
  if (!best) {
    throw new RangeError(`no baud rate within ${(tolerance * 100).toFixed(1)} % on ${chips.join(', ')} draws ${n} pulses `
      + `with every phase within ${(maxDeviation * 100).toFixed(0)} % of ${target} µs`);
  }
  const p = best.plan;
  const m = measurePulses(uartWaveform(p.bytes, p.baudRate, p.stopBits));
  return {
    ...p,
    lowUs: m.lowUs,
    highUs: m.highUs,
    totalUs: (p.bytes.length * (9 + p.stopBits) * 1e6) / p.baudRate,
    edges: m.edges,
    bitUs: 1e6 / p.baudRate,
    frameBits: 9 + p.stopBits,
  };
}

function lexLess(a: readonly number[], b: readonly number[]): boolean {
  for (let i = 0; i < Math.min(a.length, b.length); i++) {
    if (a[i]! < b[i]! - 1e-9) return true;
    if (a[i]! > b[i]! + 1e-9) return false;
  }
  return false;
}

// ---------------------------------------------------------------------------------------------
// The power-cycle and write sequence

/** The subset of WebSerial's SerialOutputSignals this module sets. */
export interface OutputSignals {
  dataTerminalReady?: boolean;
  requestToSend?: boolean;
  break?: boolean;
}

export type PowerLine = 'rts' | 'dtr';

/**
 * How the switch reacts to the modem line. USB-serial chips drive RTS#/DTR# active low:
 * `setSignals({ requestToSend: true })` asserts RTS, which puts the RTS# pin at 0 V;
 * `false` puts it at VCCIO. With the P-MOSFET high-side switch of docs/bind-wiring.md the
 * satellite is powered while the line is asserted ('asserted', the default); an NPN-inverted
 * switch or a regulator whose enable is active high powers it while deasserted.
 */
export type PowerPolarity = 'asserted' | 'deasserted';

/** The setSignals() argument that switches the satellite on or off. */
export function powerSignals(powerLine: PowerLine, on: boolean, polarity: PowerPolarity = 'asserted'): OutputSignals {
  const asserted = polarity === 'asserted' ? on : !on;
  return powerLine === 'rts' ? { requestToSend: asserted } : { dataTerminalReady: asserted };
}

interface StepBase {
  /** When to start the step, ms from the start of the sequence. */
  readonly atMs: number;
  /** The same time relative to power-on (t0); negative before it. */
  readonly sincePowerOnMs: number;
  readonly note: string;
}
export type BindStep =
  | (StepBase & { readonly action: 'open'; readonly baudRate: number; readonly stopBits: StopBits; readonly dataBits: 8; readonly parity: 'none'; readonly flowControl: 'none' })
  | (StepBase & { readonly action: 'power-off'; readonly signals: OutputSignals })
  | (StepBase & { readonly action: 'power-on'; readonly signals: OutputSignals })
  | (StepBase & { readonly action: 'write'; readonly bytes: Uint8Array; readonly durationUs: number })
  | (StepBase & { readonly action: 'reopen'; readonly baudRate: number; readonly signals: OutputSignals });

export interface TimelineOptions {
  /** Which modem line switches the satellite's 3.3 V. */
  powerLine: PowerLine;
  /** Default 'asserted' (P-MOSFET gate on the active-low pin). */
  polarity?: PowerPolarity;
  /**
   * Power off this long before power-on, ms (default 500, as PX4; at least 200). The satellite
   * must really reset; the gate hold-up of the recommended switch (1 MΩ · 100 nF) keeps it on
   * for ~50–170 ms after the line drops, so 500 ms leaves ≥ 330 ms really off.
   */
  offMs?: number;
  /** From power-on to the write, ms (default 60, as Betaflight; 20–~195 allowed). */
  settleMs?: number;
  /** From the end of the pulses to the reopen at `liveBaudRate`, ms (default 20). */
  reopenAfterMs?: number;
  /** Rate for watching the bind take (default 115200, spec §7.1). */
  liveBaudRate?: number;
  /**
   * Hold TX low (break) while the satellite is off, released at power-on. Only for the bare
   * series-resistor wiring, where an idle-high TX would feed the unpowered satellite through
   * its DATA pin's clamp diode; the diode wiring needs nothing.
   */
  holdTxLowWhileOff?: boolean;
  /** The pulses (default planPulses(n)). */
  plan?: PulsePlan;
}

/**
 * The steps a driver runs, in order, each no earlier than its `atMs` (and after the previous
 * one finished): open at the bind rate, power off, power on (t0), write the pulses t0 + settle,
 * then close and reopen at 115200 with the power line re-asserted at once.
 */
export function bindTimeline(n: number, options: TimelineOptions): BindStep[] {
  checkPulses(n);
  const polarity = options.polarity ?? 'asserted';
  const offMs = options.offMs ?? 500;
  const settleMs = options.settleMs ?? BIND_WINDOW.recommendedMs;
  const reopenAfterMs = options.reopenAfterMs ?? 20;
  const liveBaudRate = options.liveBaudRate ?? 115_200;
  const plan = options.plan ?? planPulses(n);
  if (options.powerLine !== 'rts' && options.powerLine !== 'dtr') throw new RangeError(`power line must be 'rts' or 'dtr', not ${String(options.powerLine)}`);
  if (plan.pulses !== n) throw new RangeError(`the plan is for ${plan.pulses} pulses, not ${n}`);
  if (!(offMs >= 200)) throw new RangeError(`power must stay off ≥ 200 ms, not ${offMs}`);
  const pulsesMs = plan.totalUs / 1000;
  if (!(settleMs >= 0) || settleMs + pulsesMs > BIND_WINDOW.latestMs) {
    throw new RangeError(`pulses must start after power-on and end within ${BIND_WINDOW.latestMs} ms; settle ${settleMs} ms + ${pulsesMs.toFixed(2)} ms does not`);
  }
  if (!(reopenAfterMs >= 0)) throw new RangeError(`reopenAfterMs must be ≥ 0, not ${reopenAfterMs}`);

  const line = options.powerLine === 'rts' ? 'RTS' : 'DTR';
  const holdBreak = options.holdTxLowWhileOff === true;
  const off = { ...powerSignals(options.powerLine, false, polarity), ...(holdBreak ? { break: true } : {}) };
  const on = { ...powerSignals(options.powerLine, true, polarity), ...(holdBreak ? { break: false } : {}) };
  const t0 = offMs;
  const writeAt = t0 + settleMs;
  const reopenAt = writeAt + Math.ceil(pulsesMs) + reopenAfterMs;
  const selected = bindMode(n);
  const pinLevel = (powered: boolean) => ((polarity === 'asserted') === powered ? 'low (asserted)' : 'high (deasserted)');
  return [
    {
      atMs: 0, sincePowerOnMs: -t0, action: 'open', baudRate: plan.baudRate, stopBits: plan.stopBits,
      dataBits: 8, parity: 'none', flowControl: 'none',
      note: `Close the port if it is open, then open it at ${plan.baudRate} baud 8${plan.stopBits === 1 ? 'N1' : 'N2'}. `
        + 'Opening asserts DTR and RTS (the OS does it on Linux and macOS, Chromium on Windows), which may switch the satellite on for a moment; the next step switches it off.',
    },
    {
      atMs: 0, sincePowerOnMs: -t0, action: 'power-off', signals: off,
      note: `setSignals(${JSON.stringify(off)}): ${line}# pin ${pinLevel(false)}, satellite off for ${offMs} ms so it really resets`
        + (holdBreak ? '; break holds TX low so it cannot feed the unpowered satellite.' : '.'),
    },
    {
      atMs: t0, sincePowerOnMs: 0, action: 'power-on', signals: on,
      note: `t0. setSignals(${JSON.stringify(on)}): ${line}# pin ${pinLevel(true)}, satellite powered. Time the next step from when this promise resolves.`,
    },
    {
      atMs: writeAt, sincePowerOnMs: settleMs, action: 'write', bytes: plan.bytes, durationUs: plan.totalUs,
      note: `One write() of ${plan.bytes.length} byte${plan.bytes.length === 1 ? '' : 's'} (one USB packet): ${n} low pulses of ${fmt(plan.lowUs[0]!)} µs, `
        + `${pulsesMs.toFixed(2)} ms on the wire, ending ${(settleMs + pulsesMs).toFixed(1)} ms after power-on (window ${BIND_WINDOW.earliestMs}–${BIND_WINDOW.latestMs} ms). ${selected.description}`,
    },
    {
      atMs: reopenAt, sincePowerOnMs: reopenAt - t0, action: 'reopen', baudRate: liveBaudRate, signals: on,
      note: `await writer.close() (drains the bytes), close(), open at ${liveBaudRate} 8N1 and at once setSignals(${JSON.stringify(on)}). `
        + `close() drops DTR and RTS (HUPCL on Linux and macOS, most Windows drivers): the switch's gate hold-up must bridge the gap, or the bind is cancelled. `
        + 'The satellite blinks while it waits for the transmitter; frames appear once the bind takes.',
    },
  ];
}

const fmt = (us: number) => (Math.round(us * 10) / 10).toString();

// ---------------------------------------------------------------------------------------------
// Checking a plan

export interface ValidateOptions {
  /** Accepted phase widths, µs (default BIND_PULSE_MIN_US–BIND_PULSE_MAX_US, 90–150). */
  minUs?: number;
  maxUs?: number;
  /** Also check at these chips' real rates (default: the chips the plan was made for). */
  chips?: readonly UsbSerialChip[];
  /** Check the write's place in this timeline against the window. */
  timeline?: readonly BindStep[];
  /** Window, ms after power-on (default BIND_WINDOW: 20–200). */
  earliestMs?: number;
  latestMs?: number;
}

export interface PlanCheck {
  readonly ok: boolean;
  readonly problems: string[];
  /** At the requested rate. */
  readonly edges: number;
  readonly lowUs: number[];
  readonly highUs: number[];
}

/**
 * Simulates the plan's bytes on the line, at the requested rate and at each chip's real rate,
 * and checks: exactly `n` falling edges; every low phase and every high phase between pulses
 * within [minUs, maxUs]; and, with a timeline, that the pulses start ≥ earliestMs after
 * power-on and end ≤ latestMs after it, with the plan's bytes, before the reopen.
 */
export function validatePlan(plan: PulsePlan, n: number, options: ValidateOptions = {}): PlanCheck {
  const problems: string[] = [];
  const minUs = options.minUs ?? BIND_PULSE_MIN_US;
  const maxUs = options.maxUs ?? BIND_PULSE_MAX_US;
  const chips = options.chips ?? plan.chipRates.map((c) => c.chip);
  if (!Number.isInteger(n) || n < MIN_BIND_PULSES || n > MAX_BIND_PULSES) problems.push(`${String(n)} is not a bind pulse count (3–10)`);

  const rates: { label: string; baud: number }[] = [{ label: `${plan.baudRate} baud`, baud: plan.baudRate }];
  for (const chip of chips) rates.push({ label: `${chip} (${fmt(chipBaudRate(chip, plan.baudRate))} baud)`, baud: chipBaudRate(chip, plan.baudRate) });

  let nominal: PulseMeasurement | undefined;
  for (const { label, baud } of rates) {
    const m = measurePulses(uartWaveform(plan.bytes, baud, plan.stopBits));
    nominal ??= m;
    if (m.edges !== n) problems.push(`${label}: ${m.edges} falling edges, not ${n}`);
    m.lowUs.forEach((w, i) => {
      if (w < minUs || w > maxUs) problems.push(`${label}: low ${i + 1} is ${fmt(w)} µs, outside ${minUs}–${maxUs}`);
    });
    m.highUs.forEach((w, i) => {
      if (w < minUs || w > maxUs) problems.push(`${label}: high after pulse ${i + 1} is ${fmt(w)} µs, outside ${minUs}–${maxUs}`);
    });
  }

  if (options.timeline) {
    const earliest = options.earliestMs ?? BIND_WINDOW.earliestMs;
    const latest = options.latestMs ?? BIND_WINDOW.latestMs;
    const steps = options.timeline;
    const on = steps.findIndex((s) => s.action === 'power-on');
    const write = steps.findIndex((s) => s.action === 'write');
    const off = steps.findIndex((s) => s.action === 'power-off');
    const reopen = steps.findIndex((s) => s.action === 'reopen');
    if (on < 0 || write < 0) problems.push('timeline: no power-on or no write');
    else {
      const onStep = steps[on]!;
      const writeStep = steps[write]!;
      if (write < on) problems.push('timeline: the write comes before power-on');
      if (off < 0 || off > on) problems.push('timeline: no power-off before power-on');
      if (off >= 0 && off < on && onStep.atMs - steps[off]!.atMs < 200) problems.push(`timeline: power off only ${onStep.atMs - steps[off]!.atMs} ms`);
      const startMs = writeStep.atMs - onStep.atMs;
      const endMs = startMs + plan.totalUs / 1000;
      if (startMs < earliest) problems.push(`timeline: pulses start ${startMs} ms after power-on, before ${earliest} ms`);
      if (endMs > latest) problems.push(`timeline: pulses end ${endMs.toFixed(2)} ms after power-on, after ${latest} ms`);
      if (writeStep.action === 'write' && !sameBytes(writeStep.bytes, plan.bytes)) problems.push('timeline: the write is not the plan\'s bytes');
      if (reopen >= 0 && steps[reopen]!.atMs < writeStep.atMs + plan.totalUs / 1000) problems.push('timeline: reopen before the pulses are out');
      const open = steps.findIndex((s) => s.action === 'open');
      const openStep = steps[open];
      if (!openStep || open > off || (openStep.action === 'open' && (openStep.baudRate !== plan.baudRate || openStep.stopBits !== plan.stopBits))) {
        problems.push(`timeline: the port is not opened at ${plan.baudRate} 8N${plan.stopBits} before power-off`);
      }
    }
  }
  return { ok: problems.length === 0, problems, edges: nominal?.edges ?? 0, lowUs: nominal?.lowUs ?? [], highUs: nominal?.highUs ?? [] };
}

function sameBytes(a: Uint8Array, b: Uint8Array): boolean {
  if (a.length !== b.length) return false;
  for (let i = 0; i < a.length; i++) if (a[i] !== b[i]) return false;
  return true;
}
