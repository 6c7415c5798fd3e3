/**
 * A replay's growing overview, sent to the page as a long capture is read (replay-session.ts):
 * how often, and never one that reads less far than the last.
 */
import type { Host } from '../host.js';
import type { Overview } from '../protocol.js';

/**
 * The growing overview is sent at most this often, and no more often than a quarter of the time
 * the reading has taken so far: the page draws the whole of it each time, so a long capture's
 * few dozen seconds of reading cost it a handful of draws, not one a second.
 */
const OVERVIEW_EVERY_MS = 1000;

/**
 * A capture's growing overview sent to the page, as often as OVERVIEW_EVERY_MS says; never one
 * read less far than the last, and nothing after the complete one. The first with anything read
 * goes as soon as it is offered, however soon after one with nothing read.
 */
export class OverviewSender {
  readonly #host: Host;
  readonly #startMs: number;
  #lastMs = Number.NEGATIVE_INFINITY;
  #sentUntilUs = Number.NEGATIVE_INFINITY;
  complete = false;

  constructor(host: Host) {
    this.#host = host;
    this.#startMs = host.clock.now();
  }

  /** Whether an overview would be sent now (so that one is worth making). */
  due(): boolean {
    const nowMs = this.#host.clock.now();
    return !this.complete && nowMs - this.#lastMs >= Math.max(OVERVIEW_EVERY_MS, (nowMs - this.#startMs) / 4);
  }

  offer(overview: Overview): void {
    if (this.complete || !(overview.complete || overview.readUntilUs > this.#sentUntilUs)) return;
    // One with nothing read yet (the span alone, hatched) does not hold back the first that has.
    if (overview.t.length > 0) this.#lastMs = this.#host.clock.now();
    this.#sentUntilUs = overview.readUntilUs;
    this.complete = overview.complete;
    postOverview(this.#host, overview);
  }
}

function postOverview(host: Host, overview: Overview): void {
  host.post({ type: 'overview', overview }, [overview.t.buffer, overview.fadeRate.buffer, overview.lost.buffer]);
}
