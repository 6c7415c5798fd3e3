/**
 * Choosing the bytes and the baud rate whose UART frames draw the bind pulses, on every chip
 * the adapter may be. Flight controllers bit-bang the pulses
 * (Betaflight and PX4: low 120 µs, high 120 µs); a page writes bytes instead, so the planner
 * searches rates and bytes whose low and high runs come closest to 120 µs at each chip's real
 * rate (chips.ts), on the line model of uart.ts. check.ts checks a plan bit by bit.
 */
import { BIND_PULSE_MAX_US, BIND_PULSE_MIN_US, BIND_PULSE_TARGET_US, checkPulses } from './modes.js';
import { DEFAULT_CHIPS, tableRates, chipBaudRate, type UsbSerialChip } from './chips.js';
import { frameRuns, measurePulses, uartWaveform, type StopBits } from './uart.js';

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
  for (const rate of tableRates()) set.add(rate);
  // A phase is at least one bit and a frame at most 11: beyond these rates no frame reaches 120 µs.
  const max = Math.ceil((11 * 1e6) / (targetUs * 0.5));
  return [...set].filter((r) => r >= 300 && r <= max).sort((a, b) => a - b);
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
  const maxDeviation =
    options.maxDeviation ?? Math.min(BIND_PULSE_MAX_US / BIND_PULSE_TARGET_US - 1, 1 - BIND_PULSE_MIN_US / BIND_PULSE_TARGET_US);
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
              pulses: n,
              baudRate,
              stopBits,
              bytes: Uint8Array.from(seq.bytes),
              pulsesPerByte: perByte,
              chipRates,
              worstDeviation: seq.cost,
            },
          };
        }
      }
    }
  }
  if (!best) {
    throw new RangeError(
      `no baud rate within ${(tolerance * 100).toFixed(1)} % on ${chips.join(', ')} draws ${n} pulses ` +
        `with every phase within ${(maxDeviation * 100).toFixed(0)} % of ${target} µs`,
    );
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

/** A width in µs to 0.1 µs, for messages. Not exported from the package. */
export const fmtUs = (us: number) => (Math.round(us * 10) / 10).toString();

// ---------------------------------------------------------------------------------------------
// Checking a plan
