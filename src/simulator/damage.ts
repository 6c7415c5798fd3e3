/**
 * Line damage to a frame on its way to the wire: bytes that never reach it (a truncated frame,
 * or a stream that starts mid-frame) and a flipped bit, drawn from the scenario's damage rates.
 * Noise bytes between frames are the simulator's own (they need the slot's timing).
 */
import { FRAME_SIZE } from '../decoder/spec.js';
import type { Prng } from './prng.js';
import type { DamageOptions } from './scenario.js';
import type { FrameDamage } from './truth.js';

/** Damages the simulator's frames one by one; allocates nothing per frame when truth is off. */
export class LineDamage {
  /** Per byte of the last frame damaged: 1 when the line dropped it. */
  readonly removed = new Uint8Array(FRAME_SIZE);
  /** How many bytes the line dropped from the last frame. */
  removedCount = 0;
  private readonly options: Required<DamageOptions>;
  private readonly rng: Prng;
  private readonly truthOn: boolean;

  /** `rng`: the simulator's damage stream; `truth`: whether to say what the damage was. */
  constructor(options: Required<DamageOptions>, rng: Prng, truth: boolean) {
    this.options = options;
    this.rng = rng;
    this.truthOn = truth;
  }

  /**
   * Damages frame `f` in place (a flipped bit) or marks the bytes the line drops (`removed`,
   * `removedCount`); `first`: the stream's first frame, which may start mid-frame. Returns the
   * damage for the ground truth: null when there was none or truth is off.
   */
  apply(f: Uint8Array, first: boolean): FrameDamage | null {
    const d = this.options;
    const removed = this.removed;
    removed.fill(0);
    let damage: FrameDamage | null = null;
    let nRemoved = 0;
    if (first && d.startMidFrame > 0) {
      for (let i = 0; i < d.startMidFrame; i++) removed[i] = 1;
      nRemoved = d.startMidFrame;
    } else if (this.rng.chance(d.truncateRate)) {
      const want = 1 + this.rng.int(d.truncateMaxBytes);
      while (nRemoved < want) {
        const i = this.rng.int(FRAME_SIZE);
        if (!removed[i]) {
          removed[i] = 1;
          nRemoved++;
        }
      }
    } else if (this.rng.chance(d.bitFlipRate)) {
      const byte = this.rng.int(FRAME_SIZE);
      const bit = this.rng.int(8);
      f[byte] = f[byte]! ^ (1 << bit);
      if (this.truthOn) damage = { kind: 'bit-flip', byte, bit };
    }
    if (nRemoved > 0 && this.truthOn) {
      const list: number[] = [];
      for (let i = 0; i < FRAME_SIZE; i++) if (removed[i]) list.push(i);
      damage = { kind: 'truncated', removed: list };
    }
    this.removedCount = nRemoved;
    return damage;
  }
}
