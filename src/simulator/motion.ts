/**
 * Stick motion: where each channel is at a given time, from the scenario's motions (held, a
 * sine, a random walk, steps), on the link's position scale. A channel can be held where a
 * user puts it (`override`, a slider or a gamepad when driving a flight controller) and kept
 * under a ceiling (`ceiling`, the throttle limit no scenario may exceed).
 */
import { MASK_1024_SXPOS, MASK_2048_SXPOS } from '../decoder/spec.js';
import type { Prng } from './prng.js';
import type { ChannelMotion } from './scenario.js';

/** The channels' motions (by channel ID 0–19) and the state of their random walks. */
export class StickMotion {
  private readonly motion: readonly ChannelMotion[];
  private readonly rng: Prng;
  private readonly walk = new Float64Array(20);
  private readonly walkIds: number[] = [];
  /** % travel a channel is held at instead of its motion (NaN: none). */
  private readonly overrides = new Float64Array(20).fill(Number.NaN);
  /** The most % travel a channel may reach (Infinity: none). */
  private readonly ceilings = new Float64Array(20).fill(Number.POSITIVE_INFINITY);

  /** `rng` drives the random walks (the simulator's motion stream). */
  constructor(motion: readonly ChannelMotion[], rng: Prng) {
    this.motion = motion;
    this.rng = rng;
    motion.forEach((m, id) => {
      if (m.kind === 'walk') {
        this.walkIds.push(id);
        this.walk[id] = m.start ?? 0;
      }
    });
  }

  /** Holds channel `id` at `percent` travel instead of its motion; null gives it back its motion. */
  override(id: number, percent: number | null): void {
    this.overrides[id] = percent ?? Number.NaN;
  }

  /** Keeps channel `id` at or below `percent` travel whatever moves it; null lifts the ceiling. */
  ceiling(id: number, percent: number | null): void {
    this.ceilings[id] = percent ?? Number.POSITIVE_INFINITY;
  }

  /** Position of channel `id` on the link's scale (0–1023 or 0–2047), ±100 % = 341/1707 in 2048. */
  position(id: number, tau: number, resolution: number): number {
    const held = this.overrides[id] ?? Number.NaN;
    const wanted = Number.isNaN(held) ? this.percent(id, tau) : held;
    const top = this.ceilings[id] ?? Number.POSITIVE_INFINITY;
    const p = wanted > top ? top : wanted;
    const max = resolution === 2048 ? MASK_2048_SXPOS : MASK_1024_SXPOS;
    const v = Math.round(resolution / 2 + (p * resolution) / 300);
    return v < 0 ? 0 : v > max ? max : v;
  }

  /** One frame slot on: each random walk takes a step (reflected at its bounds). */
  advance(): void {
    const motion = this.motion;
    for (const id of this.walkIds) {
      const m = motion[id]!;
      if (m.kind !== 'walk') continue;
      const lo = m.min ?? -100;
      const hi = m.max ?? 100;
      let x = this.walk[id]! + m.step * (2 * this.rng.next() - 1);
      if (x > hi) x = 2 * hi - x;
      if (x < lo) x = 2 * lo - x;
      this.walk[id] = x < lo ? lo : x > hi ? hi : x;
    }
  }

  /** Percent travel of channel `id` at time `tau` (µs since the first slot). */
  private percent(id: number, tau: number): number {
    const m = this.motion[id]!;
    switch (m.kind) {
      case 'fixed':
        return m.percent;
      case 'sine':
        return (m.centre ?? 0) + m.amplitude * Math.sin((2 * Math.PI * tau) / m.periodUs + (m.phase ?? 0));
      case 'walk':
        return this.walk[id]!;
      case 'steps':
        return m.levels[Math.floor(tau / m.holdUs) % m.levels.length]!;
    }
  }
}
