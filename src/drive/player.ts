/**
 * The drive player: a scenario's steps on one clock, as the writes a serial port makes. Each
 * step's receiver is the simulator (the one encoder SatScope has), so what is sent is what the
 * simulator's ground truth says was sent. A write is the bytes that leave together: one frame
 * (whole or cut short), or a burst of noise in the silence between frames.
 */
import { BYTE_TIME_US, CHANNEL_COUNT } from '../decoder/spec.js';
import { Simulator } from '../simulator/simulator.js';
import type { TruthFrame } from '../simulator/truth.js';
import { scenarioDurationUs, type DriveScenario } from './scenario.js';

/** Bytes that leave the port together. */
export interface DriveWrite {
  /** When the first byte is due, µs on the player's clock (0: the scenario's start). */
  atUs: number;
  bytes: Uint8Array;
  /** The frame the bytes are (its ground truth: channels, header, damage), or null for noise bytes. */
  frame: TruthFrame | null;
  /** The step the write belongs to (index into the scenario's steps). */
  step: number;
}

/** Where a step runs on the player's clock. */
export interface DriveStepTime {
  index: number;
  note: string;
  startUs: number;
  endUs: number;
}

/** Bytes closer together than this belong to one write: a frame's bytes leave back to back. */
const SAME_WRITE_US = 3 * BYTE_TIME_US;

/**
 * Plays a drive scenario from its start: `writesUntil(t)` hands out the writes due before `t`,
 * in order, once each. Live channel values (`setChannel`) and the throttle ceiling apply to
 * every step from the next frame on.
 */
export class DrivePlayer {
  readonly scenario: DriveScenario;
  readonly durationUs: number;
  readonly steps: readonly DriveStepTime[];
  readonly #held = new Float64Array(CHANNEL_COUNT).fill(Number.NaN);
  #ceiling: number | null;
  #index = 0;
  #sim: Simulator | null = null;
  #untilUs = 0;
  /** Where the step before left its frame schedule (its next slot), so a step that follows it keeps the frames apart. */
  #resumeUs = Number.NaN;

  /** `throttleCeilingPercent`: the most travel channel 0 (throttle) may reach, whatever a step or the user asks (default none). */
  constructor(scenario: DriveScenario, options: { throttleCeilingPercent?: number } = {}) {
    this.scenario = scenario;
    this.durationUs = scenarioDurationUs(scenario);
    let t = 0;
    this.steps = scenario.steps.map((s, index) => {
      const st = { index, note: s.note, startUs: t, endUs: t + s.durationUs };
      t += s.durationUs;
      return st;
    });
    const c = options.throttleCeilingPercent;
    if (c !== undefined && !Number.isFinite(c)) throw new RangeError(`throttleCeilingPercent must be a finite number, got ${c}`);
    this.#ceiling = c ?? null;
  }

  /** The step running at `tUs` (the last one after the end). */
  stepAt(tUs: number): DriveStepTime {
    for (const s of this.steps) if (tUs < s.endUs) return s;
    return this.steps[this.steps.length - 1] as DriveStepTime;
  }

  /** Whether every write has been handed out. */
  get done(): boolean {
    return this.#index >= this.steps.length;
  }

  /** Holds channel `id` at `percent` travel from the next frame on (a slider, a gamepad); null gives it back to the scenario. */
  setChannel(id: number, percent: number | null): void {
    this.#sim?.setChannel(id, percent);
    this.#held[id] = percent ?? Number.NaN;
  }

  /**
   * The writes due before `untilUs` not handed out yet, in time order. A frame whose slot is
   * before `untilUs` is handed out whole, its last bytes a little after.
   */
  writesUntil(untilUs: number): DriveWrite[] {
    const out: DriveWrite[] = [];
    while (this.#index < this.steps.length) {
      const st = this.steps[this.#index] as DriveStepTime;
      const receiver = this.scenario.steps[st.index]?.receiver;
      const to = Math.min(untilUs, st.endUs);
      if (receiver !== undefined && to > this.#untilUs) {
        const sim = this.#simulator(st);
        const chunk = sim.generate(to);
        cut(chunk.bytes, chunk.timesUs, chunk.truth?.frames ?? [], st.index, out);
      }
      this.#untilUs = Math.max(this.#untilUs, to);
      if (untilUs < st.endUs) break;
      this.#index++;
      this.#resumeUs = this.#sim?.nextSlotUs ?? Number.NaN;
      this.#sim = null;
    }
    return out;
  }

  #simulator(st: DriveStepTime): Simulator {
    if (this.#sim !== null) return this.#sim;
    const rx = this.scenario.steps[st.index]?.receiver;
    if (rx === undefined) throw new Error('a silent step has no receiver');
    // The first frame where the step before's next one was due (its last frame a period back),
    // else 1 ms into the step.
    const startUs = Number.isNaN(this.#resumeUs) ? st.startUs + 1000 : this.#resumeUs;
    const sim = new Simulator({ ...rx, timing: { ...rx.timing, startUs } }, { truth: true });
    for (let id = 0; id < CHANNEL_COUNT; id++) {
      const held = this.#held[id] ?? Number.NaN;
      if (!Number.isNaN(held)) sim.setChannel(id, held);
    }
    if (this.#ceiling !== null) sim.setCeiling(0, this.#ceiling);
    this.#sim = sim;
    return sim;
  }
}

/** Splits `bytes` (with their times) into writes at silences, each frame's write given its truth. */
function cut(bytes: Uint8Array, times: Float64Array, frames: readonly TruthFrame[], step: number, out: DriveWrite[]): void {
  let f = 0;
  let start = 0;
  for (let i = 1; i <= bytes.length; i++) {
    if (i < bytes.length && (times[i] as number) - (times[i - 1] as number) < SAME_WRITE_US) continue;
    const atUs = times[start] as number;
    while (f < frames.length && (frames[f] as TruthFrame).timeUs < atUs) f++;
    const frame = f < frames.length && (frames[f] as TruthFrame).timeUs === atUs ? (frames[f] as TruthFrame) : null;
    out.push({ atUs, bytes: bytes.slice(start, i), frame, step });
    start = i;
  }
}
