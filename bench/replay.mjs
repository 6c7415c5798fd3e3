#!/usr/bin/env node
/**
 * Opening and seeking a replay in the worker, in Node (npm run bench:day makes the captures:
 * `node bench/day.mjs --only 1m,1h` for the small ones). The worker's dispatcher is bundled from
 * src/ with Rolldown and driven with a fake host whose replay never ticks (its timers for one
 * shot run, so the capture's walk goes on between them), so only the work of `replay-open` and
 * `replay-seek` is timed: to the first overview sent; to the overview complete (every record
 * walked and decoded, the checkpoints made); and a seek, from the nearest checkpoint a minute or
 * more before the target, reading its window of the file. Each file runs in a child of its own
 * (`--expose-gc`): the heap and array buffers the worker holds once the overview is complete
 * are measured after a collection, against the file size.
 *
 * Options: --only 1h,24h (default: 1m,1h,24h, those that exist), --seeks N (default 15),
 * --src DIR (bundle another tree's src/, e.g. a worktree of an older commit, to compare).
 * Measurement only: it asserts nothing.
 */
import { spawnSync } from 'node:child_process';
import { existsSync, openAsBlob, readFileSync, rmSync, statSync } from 'node:fs';
import { loadavg, tmpdir } from 'node:os';
import { join } from 'node:path';
import { fileURLToPath } from 'node:url';

const args = process.argv.slice(2);
const arg = (name, fallback) => (args.includes(name) ? args[args.indexOf(name) + 1] : fallback);

if (args[0] === '--child') {
  await child(args[1], args[2], Number(args[3]));
} else {
  await main();
}

async function main() {
  // Rolldown (Vite's bundler) turns the worker's TypeScript into one module Node can run.
  const { build } = await import('rolldown');
  const bundle = join(tmpdir(), `satscope-bench-replay-${process.pid}`);
  const src = arg('--src', fileURLToPath(new URL('../src', import.meta.url)));
  await build({
    input: {
      dispatcher: join(src, 'worker/dispatcher.ts'),
      decoder: join(src, 'decoder/index.ts'),
      reader: join(src, 'capture/reader.ts'),
    },
    platform: 'node',
    logLevel: 'silent',
    output: { dir: bundle, format: 'esm', entryFileNames: '[name].mjs' },
  });
  const only = arg('--only', '1m,1h,24h').split(',');
  const seeks = Number(arg('--seeks', '15'));
  const load = () =>
    loadavg()
      .map((x) => x.toFixed(2))
      .join(' ');
  console.log(`load before: ${load()}`);
  console.log(
    'file | MB | first overview s | complete s | × bare decode | held MB | held/file | seek ms median (min–max) | × bare decode of 10 min, median (min–max) | seeks',
  );
  for (const d of only) {
    const path = join(tmpdir(), `satscope-bench-day-v1-${d}.sscap`);
    if (!existsSync(path)) {
      console.log(`${d}: ${path} missing (node bench/day.mjs --only ${d})`);
      continue;
    }
    {
      const run = spawnSync(
        process.execPath,
        ['--expose-gc', '--max-old-space-size=8192', fileURLToPath(import.meta.url), '--child', bundle, path, String(seeks)],
        {
          encoding: 'utf8',
          stdio: ['ignore', 'pipe', 'inherit'],
        },
      );
      if (run.status !== 0) {
        console.log(`${d}: child failed (${run.status ?? run.signal})`);
        continue;
      }
      const r = JSON.parse(run.stdout.trim().split('\n').at(-1));
      const mb = (n) => (n / 1e6).toFixed(1);
      const fixed = (x, digits) => (x === null ? '–' : x.toFixed(digits));
      const range = (x, digits) => `${fixed(x.median, digits)} (${fixed(x.min, digits)}–${fixed(x.max, digits)})`;
      console.log(
        `${d} | ${mb(r.fileBytes)} | ${r.firstS.toFixed(2)} | ${r.openS.toFixed(2)} | ${fixed(r.openRatio, 2)} | ${mb(r.heldBytes)} | ${(r.heldBytes / r.fileBytes).toFixed(2)} | ` +
          `${range(r.seekMs, 0)} | ${range(r.seekRatio, 2)} | ${r.seekMs.n}`,
      );
    }
  }
  console.log(`load after: ${load()}`);
  rmSync(bundle, { recursive: true, force: true });
}

/** Held memory: what the heap and the memory outside it (array buffers) hold after a full collection. */
function held() {
  globalThis.gc();
  globalThis.gc();
  const m = process.memoryUsage();
  return m.heapUsed + m.external;
}

function stats(xs) {
  const sorted = [...xs].sort((a, b) => a - b);
  return { median: sorted[Math.floor(sorted.length / 2)], min: sorted[0], max: sorted.at(-1), n: sorted.length };
}

/**
 * The baseline: the library's decoder alone (push, next, no link, series, inspector or doctor)
 * over every chunk of `capture` whose time is in [fromUs, toUs), each port on its own decoder,
 * ms. What any replay must at least do with those bytes.
 */
function bareDecodeMs(SpektrumDecoder, capture, fromUs, toUs) {
  const started = performance.now();
  const decoders = new Map();
  let start = 0;
  let frames = 0;
  for (let i = 0; i < capture.chunkEnds.length; i++) {
    const end = capture.chunkEnds[i];
    const t = capture.chunkTimesUs[i];
    if (t >= fromUs && t < toUs) {
      const port = capture.chunkPorts[i];
      let d = decoders.get(port);
      if (d === undefined) decoders.set(port, (d = new SpektrumDecoder()));
      d.push(capture.bytes.subarray(start, end), t);
      while (d.next() !== undefined) frames++;
    }
    start = end;
  }
  if (frames < 0) throw new Error('unreachable');
  return performance.now() - started;
}

async function child(bundle, path, seeks) {
  const { Dispatcher } = await import(join(bundle, 'dispatcher.mjs'));
  const { SpektrumDecoder } = await import(join(bundle, 'decoder.mjs'));
  const { parseCapture } = await import(join(bundle, 'reader.mjs'));
  // One-shot timers run (the capture's decode goes on in slices); the replay's ticks never do.
  const clock = { now: () => performance.now(), after: (ms, fn) => setTimeout(fn, ms), every: () => 0, cancel: (h) => clearTimeout(h) };
  let status = null;
  let complete = null;
  let firstAt = Number.NaN;
  const host = {
    post: (m) => {
      if (m.type === 'replay' && m.replay !== null) status = m.replay;
      if (m.type === 'overview' && Number.isNaN(firstAt)) firstAt = performance.now();
      if (m.type === 'overview' && m.overview.complete) complete?.();
    },
    clock,
    timeOriginMs: 0,
  };
  // Without a helper (an older tree that has one, as on a one-core machine).
  const worker = new Dispatcher(host, { passHelper: null });
  const base = held();
  const fileBytes = statSync(path).size;
  // The page hands the worker the File, which the worker reads: here a Blob backed by the file.
  const message = { type: 'replay-open', name: path, file: await openAsBlob(path) };
  const done = new Promise((resolve) => {
    complete = resolve;
  });
  const t0 = performance.now();
  await worker.handle(message);
  await done;
  const firstMs = firstAt - t0;
  const openMs = performance.now() - t0;
  message.data = null;
  const heldBytes = held() - base;
  // The bare decode's capture is read after the worker's memory is measured (Node reads no file
  // over 2 GiB at once: a week's capture goes without the ratios).
  const capture = fileBytes < 2 ** 31 ? parseCapture(new Uint8Array(readFileSync(path))) : null;
  const bare = (fromUs, toUs) => (capture === null ? Number.NaN : bareDecodeMs(SpektrumDecoder, capture, fromUs, toUs));
  const openRatio = openMs / bare(-Infinity, Infinity);
  const { startUs, endUs } = status;
  // Seek targets spread over the file in a fixed order (a seeded walk), both ends included.
  const targets = [startUs, endUs];
  let x = 7;
  for (let i = targets.length; i < seeks; i++) {
    x = (x * 48271) % 2147483647;
    targets.push(startUs + (x / 2147483647) * (endUs - startUs));
  }
  const times = [];
  const ratios = [];
  for (const t of targets) {
    const s = performance.now();
    await worker.handle({ type: 'replay-seek', timeUs: t });
    const ms = performance.now() - s;
    times.push(ms);
    // Ten minutes before the target (what a seek fed before checkpoints) through bare decoders, right after.
    ratios.push(ms / Math.max(0.01, bare(t - 600e6, t + 1)));
  }
  if (process.env.BENCH_VERBOSE)
    console.error(times.map((t, i) => `${((targets[i] - startUs) / 60e6).toFixed(1)} min: ${t.toFixed(0)} ms`).join(', '));
  console.log(
    JSON.stringify({
      fileBytes,
      firstS: firstMs / 1000,
      openS: openMs / 1000,
      openRatio,
      heldBytes,
      seekMs: stats(times),
      seekRatio: stats(ratios),
    }),
  );
}
