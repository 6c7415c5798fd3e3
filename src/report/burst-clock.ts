/**
 * The rhythm of a line: when bursts of bytes (or read errors) start, and the period they keep,
 * for naming a stream by its timing (the doctor's line rules).
 */

/** `BurstClock.checkpoint()`. */
export interface BurstClockCheckpoint {
  readonly starts: Float64Array;
  readonly count: number;
  readonly next: number;
  readonly last: number;
}

/**
 * Burst timing from per-byte (or per-error) times: a burst starts after a quiet gap of
 * `gapUs`; the period is the median interval between burst starts when at least 70 % of the
 * intervals lie within 10 % of it. Keeps the last 64 burst starts.
 */
export class BurstClock {
  readonly #starts = new Float64Array(64);
  #count = 0;
  #next = 0;
  #last = -Infinity;
  constructor(readonly gapUs = 600) {}

  event(t: number): void {
    if (!Number.isFinite(t)) return;
    if (t - this.#last > this.gapUs) {
      this.#starts[this.#next] = t;
      this.#next = (this.#next + 1) & 63;
      if (this.#count < 64) this.#count++;
    }
    if (t > this.#last) this.#last = t;
  }

  /** The burst starts kept and the last event, as copies. */
  checkpoint(): BurstClockCheckpoint {
    return { starts: this.#starts.slice(), count: this.#count, next: this.#next, last: this.#last };
  }

  /** Back to where `checkpoint()` was taken; `gapUs` stays this clock's own. */
  restore(cp: BurstClockCheckpoint): void {
    this.#starts.set(cp.starts);
    this.#count = cp.count;
    this.#next = cp.next;
    this.#last = cp.last;
  }

  /** Forget everything (e.g. when the port reopens). */
  reset(): void {
    this.#count = 0;
    this.#next = 0;
    this.#last = -Infinity;
  }

  /** The burst period in µs over starts after `sinceUs`, or NaN. */
  periodUs(sinceUs = -Infinity): number {
    const starts: number[] = [];
    for (let i = 0; i < this.#count; i++) {
      const t = this.#starts[(this.#next - this.#count + i + 64) & 63] ?? NaN;
      if (t >= sinceUs) starts.push(t);
    }
    if (starts.length < 6) return NaN;
    const iv: number[] = [];
    for (let i = 1; i < starts.length; i++) iv.push((starts[i] ?? NaN) - (starts[i - 1] ?? NaN));
    iv.sort((a, b) => a - b);
    const median = iv[iv.length >> 1] ?? NaN;
    const close = iv.filter((x) => Math.abs(x - median) <= 0.1 * median).length;
    return close >= 0.7 * iv.length ? median : NaN;
  }
}
