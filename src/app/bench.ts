/**
 * Measurement hooks for the page benchmark (only with ?bench in the URL): for each batch with
 * new bytes that reaches the screen, the time from the bytes' arrival in the worker to the
 * animation frame that drew them, in ms; the last such frame (when, and the source clock it
 * showed), so a seek can be timed to the frame that drew its new position; and when the
 * worker's reset and first batch after it arrived, to split that time between the worker and
 * the page. Read by bench/page.bench.ts through window.__satscopeBench.
 */
import type { FromWorker } from '../worker/protocol.js';
import { onFrame } from './frame-loop.js';
import { allLives, current } from './store.js';

interface BenchHooks {
  latencies: number[];
  /** When (performance.now()) the worker's last reset of every source arrived (a capture opened, a seek), and the first batch after it. */
  resetAtMs: number;
  firstBatchAtMs: number;
  /** The last animation frame that drew a new batch: its time (performance.now()) and the selected remote's clock, µs. */
  painted: { atMs: number; clockUs: number };
  lives: typeof allLives;
}

declare global {
  interface Window {
    __satscopeBench?: BenchHooks;
  }
}

export function startBenchHooks(worker: Worker): void {
  const bench: BenchHooks = { latencies: [], resetAtMs: 0, firstBatchAtMs: 0, painted: { atMs: 0, clockUs: Number.NaN }, lives: allLives };
  window.__satscopeBench = bench;
  // After the store's own listener: splits a seek into the worker's part and the page's.
  worker.addEventListener('message', (event: MessageEvent<FromWorker>) => {
    const m = event.data;
    if (m.type === 'reset' && m.source === undefined) bench.resetAtMs = performance.now();
    else if (m.type === 'batches' && bench.firstBatchAtMs < bench.resetAtMs) bench.firstBatchAtMs = performance.now();
  });
  let version = -1;
  let shown = current();
  /** The arrival time of the newest bytes already sampled: a batch without new bytes is no sample. */
  let sampledArrivalMs = 0;
  // Registered after the views, so it runs after they drew in the same frame.
  onFrame((nowMs) => {
    const live = current();
    if (live === shown && live.version === version) return;
    shown = live;
    version = live.version;
    bench.painted = { atMs: nowMs, clockUs: live.nowUs() };
    // Only a batch that brought new bytes is a latency sample. While a remote is silent (a
    // dropout) the worker still sends batches (the link state, the graph's empty buckets) that
    // carry the last bytes' arrival: their age is how long the silence lasted, not a delay.
    if (live.lastArrivedMs > 0 && live.lastArrivedMs !== sampledArrivalMs) {
      sampledArrivalMs = live.lastArrivedMs;
      bench.latencies.push(performance.timeOrigin + nowMs - live.lastArrivedMs);
    }
  });
}
