/**
 * The adapter's TX line, bit by bit: a UART frame is a start bit (low), 8 data bits LSB first
 * and 1 or 2 stop bits (high), and the line idles high between frames. A page cannot bit-bang
 * the bind pulses, but the low stretches of well-chosen frames are pulses; this model says
 * exactly which, and how wide, for the planner and for checking a plan.
 */

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
 * Runs of equal bits in a byte's frame, in bits: [low, high, low, high, …], always starting low
 * (the start bit) and ending high (the stop bits). Not exported from the package.
 */
export function frameRuns(byte: number, stopBits: StopBits): number[] {
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
    // Whole runs times the bit time, so durations are whole multiples of it; runs alternate
    // low, high, … from the start bit.
    const runs = frameRuns(b, stopBits);
    for (let r = 0; r < runs.length; r++) put(r % 2 === 0 ? 0 : 1, runs[r]! * bitUs);
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
