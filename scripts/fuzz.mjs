#!/usr/bin/env node
/**
 * Fuzzing the built decoder (dist/): random bytes and simulator streams of every preset with
 * bits flipped, stretches lost, stray and repeated bytes, under every option combination and
 * every way of timing the bytes. For each input it checks that the decoder
 * - never throws,
 * - never hangs (each input runs in a worker thread under a watchdog),
 * - accounts for every byte (framed or discarded, none left pending after end()),
 * - gives the same frames and counters whether the bytes come whole or in random chunks,
 * - gives the same frames (every field), counters and events with its fast path off
 *   (`fastPath: false`, the general path only) as with it on.
 *
 * `npm run fuzz` runs 1,000,000 inputs on every core; `npm test` runs a short run through
 * `runFuzz` (tests/decoder.fuzz.test.ts). A failure prints the input's number and seed, enough
 * to replay it: `node scripts/fuzz.mjs --from N --count 1`.
 */
import { availableParallelism } from 'node:os';
import { isMainThread, parentPort, Worker, workerData } from 'node:worker_threads';
import { fileURLToPath } from 'node:url';

const DIST = new URL('../dist/', import.meta.url);

const RESOLUTIONS = ['auto', 1024, 2048];
const REMOTES = ['auto', 'internal', 'external'];
const HEADER_MODES = ['auto', 'fades', 'rssi'];
const TIMINGS = ['none', 'chunk', 'per-byte'];

/** A small deterministic generator (mulberry32): the input number is the seed. */
function rng(seed) {
  let a = seed >>> 0;
  return () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

/** The input numbered `n`: bytes, decoder options and how to time them. */
function makeInput(n, pool) {
  const r = rng(n * 2654435761);
  const pick = (xs) => xs[Math.floor(r() * xs.length)];
  const options = { resolution: pick(RESOLUTIONS), remote: pick(REMOTES), headerMode: pick(HEADER_MODES) };
  const timing = pick(TIMINGS);
  let bytes;
  if (r() < 0.15) {
    bytes = new Uint8Array(Math.floor(r() * 600));
    // Random bytes, sometimes from a small alphabet (headers and fillers repeat in real streams).
    const alphabet = r() < 0.5 ? null : [0x00, 0xff, 0xb2, 0x01, 0x12, 0xa2, 0x80, pick([0x3e, 0x55, 0xc0])];
    for (let i = 0; i < bytes.length; i++) bytes[i] = alphabet ? pick(alphabet) : Math.floor(r() * 256);
  } else {
    const clean = pick(pool);
    const start = Math.floor(r() * Math.max(1, clean.length - 480));
    const b = Array.from(clean.subarray(start, start + 160 + Math.floor(r() * 480)));
    const edits = 1 + Math.floor(r() * 4);
    for (let e = 0; e < edits && b.length > 0; e++) {
      const at = Math.floor(r() * b.length);
      const kind = r();
      if (kind < 0.3) b[at] ^= 1 << Math.floor(r() * 8);
      else if (kind < 0.55) b.splice(at, 1 + Math.floor(r() * 40));
      else if (kind < 0.75) b.splice(at, 0, ...Array.from({ length: 1 + Math.floor(r() * 40) }, () => Math.floor(r() * 256)));
      else if (kind < 0.9) b.splice(at, 0, ...b.slice(Math.max(0, at - 1 - Math.floor(r() * 40)), at));
      else b.length = at;
    }
    bytes = Uint8Array.from(b);
  }
  const splits = Array.from({ length: 16 }, () => 1 + Math.floor(r() * 64));
  return { bytes, options, timing, splits };
}

function decode(SpektrumDecoder, input, chunked, fastPath = true) {
  const { bytes, options, timing, splits } = input;
  const events = [];
  const d = new SpektrumDecoder({ ...options, fastPath, onEvent: (e) => events.push(JSON.stringify(e)) });
  const out = [];
  // What chunking may change (frame times follow the chunks' times), for the fast/general comparison.
  const more = [];
  const drain = () => {
    for (let f = d.next(); f; f = d.next()) {
      out.push(
        `${f.offset}|${f.remote}|${f.system}|${f.resolution}|${f.fades}|${f.fadesDelta}|${f.rssi}|${f.ids.subarray(0, f.count)}|${f.positions.subarray(0, f.count)}|${f.vtx?.raw ?? ''}`,
      );
      more.push(`${f.index}|${f.timeUs}|${f.words}|${f.bytes}|${JSON.stringify(d.stats)}`);
    }
  };
  let k = 0;
  for (let i = 0; i < bytes.length; ) {
    const end = chunked ? Math.min(bytes.length, i + splits[k++ % splits.length]) : bytes.length;
    const part = bytes.subarray(i, end);
    const time = timing === 'chunk' ? end * 87 : timing === 'per-byte' ? Float64Array.from(part, (_, j) => (i + j) * 87) : undefined;
    d.push(part, time);
    drain();
    i = end;
  }
  d.end();
  drain();
  return { frames: out, more, events, stats: { ...d.stats } };
}

/** Checks one input; returns a failure message or null. */
function check(SpektrumDecoder, input) {
  let whole;
  let chunked;
  let general;
  try {
    whole = decode(SpektrumDecoder, input, false);
    chunked = decode(SpektrumDecoder, input, true);
    general = decode(SpektrumDecoder, input, false, false);
  } catch (e) {
    return `threw ${e instanceof Error ? e.stack : String(e)}`;
  }
  const s = whole.stats;
  if (s.pendingBytes !== 0 || s.frameBytes + s.discardedBytes !== s.bytes) return `bytes not accounted for: ${JSON.stringify(s)}`;
  if (whole.frames.length !== chunked.frames.length || whole.frames.some((f, i) => f !== chunked.frames[i])) {
    const i = whole.frames.findIndex((f, j) => f !== chunked.frames[j]);
    return `chunking changed frame ${i}: ${whole.frames[i]} vs ${chunked.frames[i]}`;
  }
  if (JSON.stringify(s) !== JSON.stringify(chunked.stats))
    return `chunking changed the counters: ${JSON.stringify(s)} vs ${JSON.stringify(chunked.stats)}`;
  for (const k of ['frames', 'more', 'events']) {
    const i = Math.max(whole[k].length, general[k].length) === 0 ? -1 : whole[k].findIndex((x, j) => x !== general[k][j]);
    if (whole[k].length !== general[k].length || i >= 0)
      return `the fast path changed ${k} at ${i < 0 ? whole[k].length : i}: ${whole[k][i]} vs general ${general[k][i]}`;
  }
  if (JSON.stringify(s) !== JSON.stringify(general.stats))
    return `the fast path changed the counters: ${JSON.stringify(s)} vs general ${JSON.stringify(general.stats)}`;
  return null;
}

async function workerMain() {
  const { SpektrumDecoder } = await import(new URL('decoder/index.js', DIST).href);
  const { simulate, preset, PRESET_NAMES } = await import(new URL('simulator/index.js', DIST).href);
  const pool = [];
  for (const name of PRESET_NAMES) for (let seed = 1; seed <= 3; seed++) pool.push(simulate({ ...preset(name), seed }, 400_000).bytes);
  const { from, count, step, progress } = workerData;
  const at = new Int32Array(progress);
  const failures = [];
  for (let n = from; n < from + count; n += step) {
    Atomics.store(at, 0, n);
    const message = check(SpektrumDecoder, makeInput(n, pool));
    if (message !== null) {
      failures.push({ n, message });
      if (failures.length >= 5) break;
    }
    if ((n - from) % (step * 2000) === 0) parentPort.postMessage({ type: 'tick' });
  }
  parentPort.postMessage({ type: 'done', failures });
}

/**
 * Runs inputs `from` … `from + count - 1` on `workers` threads; rejects with the input that hung
 * (no progress for `hangMs`), resolves with the failures (at most five a thread).
 */
export function runFuzz({ from = 0, count = 1_000_000, workers = Math.max(1, availableParallelism()), hangMs = 10_000 } = {}) {
  const file = fileURLToPath(import.meta.url);
  return Promise.all(
    Array.from(
      { length: workers },
      (_, w) =>
        new Promise((resolve, reject) => {
          const progress = new SharedArrayBuffer(4);
          const at = new Int32Array(progress);
          const worker = new Worker(file, { workerData: { from: from + w, count: count - w, step: workers, progress } });
          let last = -1;
          let still = 0;
          const timer = setInterval(() => {
            const n = Atomics.load(at, 0);
            if (n !== last) {
              last = n;
              still = 0;
              return;
            }
            still += 500;
            if (still >= hangMs) {
              clearInterval(timer);
              void worker.terminate();
              reject(new Error(`input ${n} made no progress for ${hangMs} ms (replay: node scripts/fuzz.mjs --from ${n} --count 1)`));
            }
          }, 500);
          worker.on('message', (m) => {
            if (m.type !== 'done') return;
            clearInterval(timer);
            resolve(m.failures);
            void worker.terminate();
          });
          worker.on('error', (e) => {
            clearInterval(timer);
            reject(e);
          });
        }),
    ),
  ).then((all) => all.flat());
}

if (!isMainThread) {
  await workerMain();
} else if (process.argv[1] === fileURLToPath(import.meta.url)) {
  const arg = (name, fallback) => {
    const i = process.argv.indexOf(name);
    return i < 0 ? fallback : Number(process.argv[i + 1]);
  };
  const count = arg('--count', 1_000_000);
  const from = arg('--from', 0);
  const started = performance.now();
  try {
    const failures = await runFuzz({ from, count, workers: Math.min(count, Math.max(1, availableParallelism())) });
    const s = ((performance.now() - started) / 1000).toFixed(1);
    if (failures.length > 0) {
      for (const f of failures) console.error(`input ${f.n}: ${f.message}`);
      console.error(`${failures.length} failing inputs in ${count} (${s} s)`);
      process.exitCode = 1;
    } else {
      console.log(
        `${count} inputs from ${from}, every option and timing: 0 throws, 0 hangs, every byte accounted for, same frames however chunked, same frames, counters and events with the fast path off (${s} s)`,
      );
    }
  } catch (e) {
    console.error(String(e instanceof Error ? e.message : e));
    process.exitCode = 1;
  }
}
