/**
 * What a Spektrum satellite expects to enter bind mode (spec Rev G §7.2): within 200 ms of
 * power-up, N falling pulses (3–10) on its DATA line; N picks the mode. The pulse widths and the
 * window are what firmware that binds uses, since the spec gives only the count.
 */
import { SYSTEM_DSM2_11MS_2048, SYSTEM_DSM2_22MS_1024, SYSTEM_DSMX_11MS_2048, SYSTEM_DSMX_22MS_2048 } from '../decoder/spec.js';

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
  ]
    .filter(Boolean)
    .join('; ');
  return {
    pulses,
    remote,
    protocol,
    periodMs,
    recommended,
    systemByte,
    description:
      `${pulses} pulses: ${remote} remote, ${protocol} ${periodMs} ms (${also})` +
      (remote === 'internal' ? '. Only one remote in a system may be internal.' : '.'),
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

/**
 * @throws RangeError unless `n` is a bind pulse count (an integer 3–10). Not exported from the
 * package: the planner and the timeline share it so both refuse the same counts.
 */
export function checkPulses(n: number): void {
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
