/**
 * What the worker takes from where it runs: a way to post to the page and a clock with timers.
 * The entry (worker.ts) passes the browser's; tests pass a fake `post` and a fake clock, so
 * every part of the worker is built and driven in Node.
 */
import type { FromWorker } from './protocol.js';

/** Wall time and timers. */
export interface Clock {
  /** Milliseconds, monotonic (performance.now()). */
  now(): number;
  /** Runs `fn` once after `ms`. */
  after(ms: number, fn: () => void): unknown;
  /** Runs `fn` every `ms`. */
  every(ms: number, fn: () => void): unknown;
  /** Cancels what `after` or `every` returned (undefined: nothing). */
  cancel(handle: unknown): void;
}

/** The browser's clock: performance.now() and the timer functions. */
export const BROWSER_CLOCK: Clock = {
  now: () => performance.now(),
  after: (ms, fn) => setTimeout(fn, ms),
  every: (ms, fn) => setInterval(fn, ms),
  // clearTimeout and clearInterval share one pool of ids (HTML, Node alike): either clears both.
  cancel: (handle) => clearTimeout(handle as ReturnType<typeof setTimeout> | undefined),
};

export interface Host {
  /** Sends a message to the page, transferring `transfer`. */
  post(message: FromWorker, transfer?: Transferable[]): void;
  readonly clock: Clock;
  /** performance.timeOrigin: `clock.now()` plus this is wall time in ms since the epoch. */
  readonly timeOriginMs: number;
}

/** Tells the user something, through the page. */
export function notice(host: Host, level: 'info' | 'warning' | 'error', title: string, detail: string): void {
  host.post({ type: 'notice', level, title, detail });
}

/** The host's clock in µs: the live sources' clock. */
export function nowUs(host: Host): number {
  return host.clock.now() * 1000;
}
