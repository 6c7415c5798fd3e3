/**
 * Drive scenarios: what SatScope sends a flight controller, as a timeline of steps. Each step
 * is a simulated receiver (the simulator's own `Scenario`: system, remote, channels, X-Plus,
 * fades, dropouts, VTX, line damage, stick motion) for a while, or silence. A switch of frame
 * period or a rebind to another format is two steps. Scenarios are plain JSON, so a user can
 * write one and share it; `parseDriveScenario` checks one and says what is wrong.
 */
import { resolveScenario, type Scenario } from '../simulator/scenario.js';

/** One step of a drive scenario. */
export interface DriveStep {
  /** What the step does, in a few words (the page shows it while the step runs). */
  note: string;
  /** How long the step lasts, µs. */
  durationUs: number;
  /** The receiver the step plays; absent: the line is silent (the receiver off or unplugged). */
  receiver?: Scenario;
}

/** A timeline of steps that drives a flight controller. */
export interface DriveScenario {
  /** A short identifier (letters, digits, dashes). */
  name: string;
  /** What the scenario checks, in a sentence. */
  title: string;
  steps: DriveStep[];
}

/** The most steps a scenario may have, and the longest it may run: a day. */
const MAX_STEPS = 1000;
const MAX_TOTAL_US = 24 * 3600e6;

/** The whole length of a scenario, µs. */
export function scenarioDurationUs(s: DriveScenario): number {
  let total = 0;
  for (const step of s.steps) total += step.durationUs;
  return total;
}

/**
 * Checks a scenario given as JSON text or as a parsed value, and returns it (receivers
 * checked by the simulator's own rules). Throws `TypeError` with the step and field at fault.
 */
export function parseDriveScenario(input: string | unknown): DriveScenario {
  let value: unknown = input;
  if (typeof input === 'string') {
    try {
      value = JSON.parse(input);
    } catch (e) {
      throw new TypeError(`a drive scenario is JSON: ${(e as Error).message}`);
    }
  }
  if (typeof value !== 'object' || value === null || Array.isArray(value))
    throw new TypeError('a drive scenario is an object with name, title and steps');
  const v = value as Record<string, unknown>;
  if (typeof v.name !== 'string' || !/^[a-z0-9][a-z0-9-]{0,63}$/i.test(v.name)) {
    throw new TypeError('name must be 1–64 letters, digits or dashes');
  }
  const name = v.name;
  if (typeof v.title !== 'string' || v.title.length === 0) throw new TypeError(`${name}: title must be a sentence`);
  if (!Array.isArray(v.steps) || v.steps.length === 0 || v.steps.length > MAX_STEPS) {
    throw new TypeError(`${name}: steps must be a list of 1–${MAX_STEPS} steps`);
  }
  let total = 0;
  const steps = v.steps.map((raw: unknown, i): DriveStep => {
    const at = `${name}: step ${i + 1}`;
    if (typeof raw !== 'object' || raw === null) throw new TypeError(`${at} is not an object`);
    const st = raw as Record<string, unknown>;
    if (typeof st.note !== 'string') throw new TypeError(`${at}: note must be text`);
    const d = st.durationUs;
    if (typeof d !== 'number' || !Number.isFinite(d) || d <= 0) throw new TypeError(`${at}: durationUs must be a number of µs above 0`);
    total += d;
    if (st.receiver === undefined) return { note: st.note, durationUs: d };
    try {
      resolveScenario(st.receiver as Scenario);
    } catch (e) {
      throw new TypeError(`${at}: ${(e as Error).message}`);
    }
    return { note: st.note, durationUs: d, receiver: st.receiver as Scenario };
  });
  if (total > MAX_TOTAL_US) throw new TypeError(`${name}: the steps last over a day`);
  return { name, title: v.title, steps };
}
