/**
 * The batcher: hands the page what changed in every source, in one message, at most every
 * MIN_BATCH_MS however fast bytes come (a display frame is 16.7 ms at 60 Hz), never leaving the
 * last change unsent, and every IDLE_TICK_MS while live sources are quiet, so hold, failsafe and
 * ages advance.
 */
import type { Clock, Host } from './host.js';
import type { Batch } from './protocol.js';
import type { SourceRegistry } from './registry.js';

/** Batches at most this often. */
export const MIN_BATCH_MS = 8;
/** While live sources are quiet, still tick this often. */
export const IDLE_TICK_MS = 50;

export class Batcher {
  readonly #clock: Clock;
  #lastBatchMs = -Infinity;
  #flushTimer: unknown;
  #idleTimer: unknown;

  /**
   * @param afterFlush after each flush (what depends on every source's batch: the shared
   *   resolution, the list of sources, the doctor)
   */
  constructor(
    readonly host: Host,
    readonly registry: SourceRegistry,
    readonly afterFlush: () => void,
  ) {
    this.#clock = host.clock;
  }

  /** Sends every source's batch now, each judged at its own link time. */
  flush(): void {
    this.#clock.cancel(this.#flushTimer);
    this.#flushTimer = undefined;
    this.#lastBatchMs = this.#clock.now();
    const batches: { source: number; batch: Batch }[] = [];
    const transfer: ArrayBuffer[] = [];
    for (const s of this.registry.list()) {
      const out = s.engine.batch(this.registry.linkNowUs(s.id));
      if (out === null) continue;
      batches.push({ source: s.id, batch: out.batch });
      transfer.push(...out.transfer);
    }
    if (batches.length > 0) this.host.post({ type: 'batches', batches }, transfer);
    this.afterFlush();
  }

  /** Something changed: flush now if the last batch is old enough, else once it is. */
  schedule(): void {
    if (this.#flushTimer !== undefined) return;
    const wait = MIN_BATCH_MS - (this.#clock.now() - this.#lastBatchMs);
    if (wait <= 0) this.flush();
    else this.#flushTimer = this.#clock.after(wait, () => this.flush());
  }

  /** Live sources run: tick while they are quiet. */
  startTicks(): void {
    if (this.#idleTimer === undefined) this.#idleTimer = this.#clock.every(IDLE_TICK_MS, () => this.schedule());
  }

  /** No source left: no timer runs. */
  stop(): void {
    this.#clock.cancel(this.#idleTimer);
    this.#idleTimer = undefined;
    this.#clock.cancel(this.#flushTimer);
    this.#flushTimer = undefined;
  }
}
