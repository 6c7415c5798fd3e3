/**
 * Measurement hooks for the page benchmark (only with ?bench in the URL): for each batch that
 * reaches the screen, the time from the bytes' arrival in the worker to the animation frame
 * that drew them, in ms; and the last such frame (when, and the source clock it showed), so a
 * seek can be timed to the frame that drew its new position. Read by bench/page.bench.ts
 * through window.__satscopeBench.
 */
import { onFrame } from './frame-loop.js';
import { allLives, current } from './store.js';

interface BenchHooks {
  latencies: number[];
  /** The last animation frame that drew a new batch: its time (performance.now()) and the selected remote's clock, µs. */
  painted: { atMs: number; clockUs: number };
  lives: typeof allLives;
}

declare global {
  interface Window {
    __satscopeBench?: BenchHooks;
  }
}

export function startBenchHooks(): void {
  const bench: BenchHooks = { latencies: [], painted: { atMs: 0, clockUs: Number.NaN }, lives: allLives };
  window.__satscopeBench = bench;
  let version = -1;
  let shown = current();
  // Registered after the views, so it runs after they drew in the same frame.
  onFrame((nowMs) => {
    const live = current();
    if (live === shown && live.version === version) return;
    shown = live;
    version = live.version;
    bench.painted = { atMs: nowMs, clockUs: live.nowUs() };
    if (live.lastArrivedMs > 0) bench.latencies.push(performance.timeOrigin + nowMs - live.lastArrivedMs);
  });
}
