/**
 * Measurement hooks for the page benchmark (only with ?bench in the URL): for each batch that
 * reaches the screen, the time from the bytes' arrival in the worker to the animation frame
 * that drew them, in ms. Read by bench/page.bench.ts through window.__satscopeBench.
 */
import { onFrame } from './frame-loop.js';
import { allLives, current } from './store.js';

declare global {
  interface Window {
    __satscopeBench?: { latencies: number[]; lives: typeof allLives };
  }
}

export function startBenchHooks(): void {
  const bench = { latencies: [] as number[], lives: allLives };
  window.__satscopeBench = bench;
  let version = -1;
  // Registered after the views, so it runs after they drew in the same frame.
  onFrame((nowMs) => {
    const live = current();
    if (live.version === version) return;
    version = live.version;
    if (live.lastArrivedMs > 0) bench.latencies.push(performance.timeOrigin + nowMs - live.lastArrivedMs);
  });
}
