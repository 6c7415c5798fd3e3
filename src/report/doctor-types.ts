/**
 * What the doctor says and how it is set up: finding codes, severities, confidence, evidence,
 * the probe that would confirm a finding, the options and what a port gives it to read.
 */
import type { LinkMonitor } from '../decoder/link.js';
import type { SpektrumDecoder } from '../decoder/decoder.js';
import type { StackSetting } from './doctor-stacks.js';

/** Stable codes, for programs and tests; titles are for people. */
export type DoctorCode =
  // Nothing arrives
  | 'nothing-arrives'
  // Bytes, but not a satellite stream
  | 'no-satellite'
  | 'inverted-line'
  | 'srxl-v1'
  | 'srxl2'
  | 'ibus'
  | 'sbus'
  | 'crsf'
  | 'fport'
  | 'ghst'
  | 'wrong-speed'
  | 'noise'
  | 'unknown-stream'
  | 'overrun'
  // The adapter went away
  | 'adapter-away'
  // A satellite the flight controller will read wrong
  | 'fc-settings'
  | 'alignment-unproven'
  | 'bind-mode'
  | 'system-byte-contradicted'
  | 'xplus-channels'
  | 'vtx-frames'
  | 'autopilot-detection'
  // The link is weak
  | 'weak-link'
  | 'weakest-remote'
  | 'fades-together'
  // The setup is wrong
  | 'forced-option'
  | 'internal-count'
  | 'resolution-mismatch'
  | 'rebind'
  | 'receiver-restart'
  | 'delivery-stall'
  | 'rssi-receiver';

/** How much a finding matters: a problem to fix, a warning to check, or information. */
export type Severity = 'problem' | 'warning' | 'info';
/** How sure: 'certain' (the bytes prove it), 'likely' (the numbers fit it and nothing else known), 'possible' (one of several explanations). */
export type Confidence = 'possible' | 'likely' | 'certain';

/** One number from the stream, as a sentence, with when it was seen (µs, the caller's clock) if it has a time. */
export interface Evidence {
  text: string;
  timeUs: number | null;
}

/** A short listen at another line setting that would confirm a finding (the worker may offer it). */
export interface ConfirmProbe {
  baudRate: number;
  parity: 'none' | 'even' | 'odd';
  stopBits: 1 | 2;
  /** How long to listen, µs. */
  listenUs: number;
  /** Why, and what the adapter must be able to do. */
  note: string;
}

/** One thing the doctor found: what, on which ports, how bad, how sure, the evidence, and what to do. */
export interface DoctorFinding {
  code: DoctorCode;
  /** The ports it is about, in increasing order (several for a finding about the whole system). */
  ports: number[];
  severity: Severity;
  confidence: Confidence;
  /** A plain title, e.g. "This is FlySky IBUS, not a Spektrum satellite". */
  title: string;
  evidence: Evidence[];
  /** What to do, most likely first. */
  todo: string[];
  /** Flight-stack settings, where there are some ("copy settings"). */
  settings: StackSetting[];
  confirm: ConfirmProbe | null;
  /** When the finding appeared (it has held at every `findings()` call since), µs. */
  sinceUs: number;
}

/** How a `Doctor` reads its sources: their timing, how far back it remembers, and where its clock starts. */
export interface DoctorOptions {
  /**
   * How byte and error times were taken: 'per-byte' (a logic analyser, the line model), where
   * the gaps between bursts are the sender's; or 'per-chunk' (WebSerial, .sscap), where they
   * are the USB adapter's batching and are not used; or 'none' (a raw file): the times given
   * are only the bytes' places in the stream at 115200, which the line findings' windows run on,
   * and no sentence states a time, a duration or a rate. Default 'per-chunk'.
   */
  timing?: 'per-byte' | 'per-chunk' | 'none';
  /** How far back link findings (holds, failsafes, fades, restarts, rebinds) look, µs. Default 60 s; a whole capture: Infinity. */
  memoryUs?: number;
  /**
   * Time zero for the times written in the evidence sentences ("at 12.3 s"), µs on the
   * caller's clock: the session's start, or a capture's first time. Default 0. `Evidence.timeUs`
   * stays on the caller's clock.
   */
  originUs?: number;
}

/** What a port's source gives the doctor to read. */
export interface DoctorPortSource {
  decoder: SpektrumDecoder;
  link: LinkMonitor;
  /** A short name for titles ("A", "Port 1"). Default "Port N". */
  label?: string;
}

/** How a rule hands a finding to `findings()` (which dates it: `sinceUs` defaults to now). */
export type AddFinding = (f: Omit<DoctorFinding, 'sinceUs'> & { sinceUs?: number }) => void;

/** What the rules read from the doctor itself. */
export interface RuleContext {
  /** A time in a sentence, from the session's origin, as the report writes it ("0:12.3"). */
  at(us: number): string;
  /** `word` and the time (" since 0:12.3"), or nothing when the time is not a recorded one. */
  when(word: string, us: number): string;
  /** Per-byte times (a logic analyser): bursts and gaps are the sender's. */
  precise: boolean;
  /** Times are recorded ones (not only the bytes' places in an untimed file): times, durations and rates may be stated. */
  timed: boolean;
  /** How far back link findings look, µs. */
  memoryUs: number;
}
