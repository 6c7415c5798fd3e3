/**
 * Checking a bind plan bit by bit before it is sent: its bytes on the line model at the
 * requested rate and at each chip's real rate, and its place in the power-cycle timeline.
 */
import { type UsbSerialChip, chipBaudRate } from './chips.js';
import { BIND_PULSE_MAX_US, BIND_PULSE_MIN_US, BIND_WINDOW, MAX_BIND_PULSES, MIN_BIND_PULSES } from './modes.js';
import { type PulsePlan, fmtUs } from './plan.js';
import type { BindStep } from './timeline.js';
import { type PulseMeasurement, measurePulses, uartWaveform } from './uart.js';

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
  for (const chip of chips)
    rates.push({ label: `${chip} (${fmtUs(chipBaudRate(chip, plan.baudRate))} baud)`, baud: chipBaudRate(chip, plan.baudRate) });

  let nominal: PulseMeasurement | undefined;
  for (const { label, baud } of rates) {
    const m = measurePulses(uartWaveform(plan.bytes, baud, plan.stopBits));
    nominal ??= m;
    if (m.edges !== n) problems.push(`${label}: ${m.edges} falling edges, not ${n}`);
    m.lowUs.forEach((w, i) => {
      if (w < minUs || w > maxUs) problems.push(`${label}: low ${i + 1} is ${fmtUs(w)} µs, outside ${minUs}–${maxUs}`);
    });
    m.highUs.forEach((w, i) => {
      if (w < minUs || w > maxUs) problems.push(`${label}: high after pulse ${i + 1} is ${fmtUs(w)} µs, outside ${minUs}–${maxUs}`);
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
      if (off >= 0 && off < on && onStep.atMs - steps[off]!.atMs < 200)
        problems.push(`timeline: power off only ${onStep.atMs - steps[off]!.atMs} ms`);
      const startMs = writeStep.atMs - onStep.atMs;
      const endMs = startMs + plan.totalUs / 1000;
      if (startMs < earliest) problems.push(`timeline: pulses start ${startMs} ms after power-on, before ${earliest} ms`);
      if (endMs > latest) problems.push(`timeline: pulses end ${endMs.toFixed(2)} ms after power-on, after ${latest} ms`);
      if (writeStep.action === 'write' && !sameBytes(writeStep.bytes, plan.bytes))
        problems.push("timeline: the write is not the plan's bytes");
      if (reopen >= 0 && steps[reopen]!.atMs < writeStep.atMs + plan.totalUs / 1000)
        problems.push('timeline: reopen before the pulses are out');
      const open = steps.findIndex((s) => s.action === 'open');
      const openStep = steps[open];
      if (
        !openStep ||
        open > off ||
        (openStep.action === 'open' && (openStep.baudRate !== plan.baudRate || openStep.stopBits !== plan.stopBits))
      ) {
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
