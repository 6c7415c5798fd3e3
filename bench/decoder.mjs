#!/usr/bin/env node
/**
 * Decoder benchmark (npm run bench): throughput over a 1-hour simulated DSMX 11 ms capture
 * (327k frames, 5.2 MB), fed whole, in 64-byte chunks with chunk times (what WebSerial hands
 * over) and with per-byte times; median of several runs, MB/s and frames/s. Then bytes
 * allocated per frame in steady state, measured in a child process with a young generation
 * large enough that no garbage collection runs during the measurement.
 * Target (issue #2): ≥ 100 MB/s on our 2-core machines.
 */
import { execFileSync } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { SpektrumDecoder } from '../dist/decoder/index.js';
import { Simulator, preset } from '../dist/simulator/index.js';

const HOUR_US = 3600e6;
const RUNS = Number(process.env.BENCH_RUNS ?? 7);

function hourOfFrames() {
  const sim = new Simulator({ ...preset('dsmx-11ms-2048-internal'), seed: 1 });
  return sim.generate(sim.scenario.timing.startUs + HOUR_US);
}

function decodeAll(bytes, times, mode, chunk = 64) {
  const d = new SpektrumDecoder();
  let frames = 0;
  if (mode === 'whole') {
    d.push(bytes);
    while (d.next()) frames++;
  } else {
    for (let i = 0; i < bytes.length; i += chunk) {
      const end = Math.min(bytes.length, i + chunk);
      d.push(bytes.subarray(i, end), mode === 'per-byte' ? times.subarray(i, end) : times[end - 1]);
      while (d.next()) frames++;
    }
  }
  d.end();
  while (d.next()) frames++;
  return frames;
}

const median = (xs) => [...xs].sort((a, b) => a - b)[xs.length >> 1];

if (process.argv[2] === '--alloc') {
  // Child: decode the hour once so the JIT has settled, then measure heap growth over the whole
  // hour again with no garbage collection in between. The chunk views and their times are made
  // up front so that the measured loop allocates nothing itself.
  const { bytes, timesUs } = hourOfFrames();
  const chunk = 64;
  const views = [];
  const times = [];
  for (let i = 0; i < bytes.length; i += chunk) { views.push(bytes.subarray(i, i + chunk)); times.push(timesUs[Math.min(i + chunk, bytes.length) - 1]); }
  const run = (d) => { let n = 0; for (let k = 0; k < views.length; k++) { d.push(views[k], times[k]); for (let f = d.next(); f; f = d.next()) n++; } return n; };
  run(new SpektrumDecoder());
  const d = new SpektrumDecoder();
  d.push(views[0], times[0]);
  globalThis.gc();
  let gcs = 0;
  const { PerformanceObserver } = await import('node:perf_hooks');
  const obs = new PerformanceObserver((list) => { gcs += list.getEntries().length; });
  obs.observe({ entryTypes: ['gc'] });
  const before = process.memoryUsage().heapUsed;
  const frames = run(d);
  const after = process.memoryUsage().heapUsed;
  await new Promise((r) => setTimeout(r, 10));
  obs.disconnect();
  process.stdout.write(JSON.stringify({ frames, pushes: views.length, bytes: after - before, gcs }));
  process.exit(0);
}

const { bytes, timesUs } = hourOfFrames();
console.log(`1-hour DSMX 11 ms capture: ${(bytes.length / 1e6).toFixed(2)} MB, ${RUNS} runs each, median`);
for (const mode of ['whole', 'chunk', 'per-byte']) {
  const ms = [];
  let frames = 0;
  for (let w = 0; w < 3; w++) decodeAll(bytes, timesUs, mode); // warm-up: let the JIT settle
  for (let r = 0; r < RUNS; r++) {
    const t0 = performance.now();
    frames = decodeAll(bytes, timesUs, mode);
    ms.push(performance.now() - t0);
  }
  const m = median(ms);
  const label = { whole: 'whole buffer, no times', chunk: '64-byte chunks, chunk times', 'per-byte': '64-byte chunks, per-byte times' }[mode];
  console.log(`  ${label.padEnd(32)} ${(bytes.length / 1e6 / (m / 1000)).toFixed(0).padStart(5)} MB/s  ${(frames / (m / 1000) / 1e6).toFixed(2)} M frames/s  (${m.toFixed(1)} ms, min ${Math.min(...ms).toFixed(1)}, max ${Math.max(...ms).toFixed(1)}; ${frames} frames)`);
}
const self = fileURLToPath(import.meta.url);
const alloc = JSON.parse(execFileSync(process.execPath, ['--expose-gc', '--max-semi-space-size=1024', self, '--alloc'], { encoding: 'utf8' }));
console.log(`  heap growth in steady state: ${(alloc.bytes / alloc.frames).toFixed(2)} bytes/frame = ${(alloc.bytes / alloc.pushes).toFixed(1)} bytes/push over ${alloc.frames} frames in ${alloc.pushes} pushes (${alloc.gcs} GCs during the run)`);
