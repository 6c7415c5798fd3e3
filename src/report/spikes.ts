/**
 * The glitch rule (a "spike": a channel value that jumps and comes back, see
 * `SPIKE_MIN_JUMP_PERCENT` for its shape and why), once, for every surface: the health report's
 * tally (report-port.ts) judges its candidates with `isSpike`, and the page's channel traces
 * mark what `SpikeFinder` finds frame by frame, so the report and the page name the same glitches.
 */
import { CHANNEL_COUNT, channelResolution, servoToMicros, servoToPercent } from '../decoder/spec.js';
import type { DecodedFrame } from '../decoder/types.js';
import { SPIKE_MIN_JUMP_PERCENT, SPIKE_RETURN_PERCENT, SPIKE_WINDOW_FRAMES, SPIKE_WINDOW_US } from './report-thresholds.js';

/**
 * Whether B, between a channel's consecutive appearances A and C (% travel `pA`, `pB`, `pC`;
 * A's and C's times, NaN without timing, and frame indexes), is a spike: it left A and C by at
 * least SPIKE_MIN_JUMP_PERCENT, on the same side of both, C came back within
 * SPIKE_RETURN_PERCENT of A, and C came inside the window after A (in frames without timing).
 */
export function isSpike(pA: number, pB: number, pC: number, atA: number, atC: number, indexA: number, indexC: number): boolean {
  const up = pB - pA;
  const down = pB - pC;
  // Written so that NaN (an appearance not there yet) is no spike.
  if (!(Math.abs(up) >= SPIKE_MIN_JUMP_PERCENT && Math.abs(down) >= SPIKE_MIN_JUMP_PERCENT)) return false;
  if (Math.sign(up) !== Math.sign(down) || Math.abs(pC - pA) > SPIKE_RETURN_PERCENT) return false;
  return Number.isFinite(atA) && Number.isFinite(atC) ? atC - atA <= SPIKE_WINDOW_US : indexC - indexA <= SPIKE_WINDOW_FRAMES;
}

/** A spike found: the channel, and its B (the wrong value) with what came before and after it. */
export interface FoundSpike {
  channel: number;
  /** B's frame time (µs, NaN without timing) and frame index. */
  timeUs: number;
  frameIndex: number;
  beforeUs: number;
  spikeUs: number;
  afterUs: number;
  /** B − A, % travel. */
  jumpPercent: number;
}

// Each channel's last two appearances A and B, at `id × STRIDE`: % travel, µs, time, frame index.
const P_A = 0;
const US_A = 1;
const T_A = 2;
const I_A = 3;
const P_B = 4;
const US_B = 5;
const T_B = 6;
const I_B = 7;
const STRIDE = 8;

/**
 * Finds spikes frame by frame, as the frames come (live or in replay), keeping each channel's
 * last two appearances; each new one is C. Nothing is allocated per frame: a spike is handed to
 * the callback in one reused object, valid during the call.
 */
export class SpikeFinder {
  readonly #ch = new Float64Array(CHANNEL_COUNT * STRIDE).fill(Number.NaN);
  readonly #found: FoundSpike = { channel: 0, timeUs: 0, frameIndex: 0, beforeUs: 0, spikeUs: 0, afterUs: 0, jumpPercent: 0 };

  /** Reads one frame's channels; `onSpike` is called for each B this frame's values show was a spike. */
  frame(f: DecodedFrame, onSpike: (s: Readonly<FoundSpike>) => void): void {
    const ch = this.#ch;
    const t = f.timeUs;
    for (let i = 0; i < f.count; i++) {
      const id = f.ids[i];
      const pos = f.positions[i];
      if (id === undefined || pos === undefined) break;
      const res = channelResolution(id, f.resolution);
      const p = servoToPercent(pos, res);
      const u = servoToMicros(pos, res);
      const o = id * STRIDE;
      const pA = ch[o + P_A] as number;
      const pB = ch[o + P_B] as number;
      // NaN before two appearances: no spike.
      if (isSpike(pA, pB, p, ch[o + T_A] as number, t, ch[o + I_A] as number, f.index)) {
        const s = this.#found;
        s.channel = id;
        s.timeUs = ch[o + T_B] as number;
        s.frameIndex = ch[o + I_B] as number;
        s.beforeUs = ch[o + US_A] as number;
        s.spikeUs = ch[o + US_B] as number;
        s.afterUs = u;
        s.jumpPercent = pB - pA;
        onSpike(s);
      }
      ch.copyWithin(o + P_A, o + P_B, o + STRIDE);
      ch[o + P_B] = p;
      ch[o + US_B] = u;
      ch[o + T_B] = t;
      ch[o + I_B] = f.index;
    }
  }

  /** Forgets every appearance (a new stream, a seek). */
  reset(): void {
    this.#ch.fill(Number.NaN);
  }
}
