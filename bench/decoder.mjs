#!/usr/bin/env node
/**
 * Decoder benchmark (npm run bench). bench/README.md says how to read it.
 *
 * Every figure is min / median / max over rounds that interleave all cases (A, B, C, A, B, C…),
 * so that a neighbour's load on a shared machine falls on every case alike. Each round also runs
 * a plain JavaScript loop over the same bytes (frames aligned, no search, per-slot validation)
 * and each SatScope figure is given as a ratio to that loop in the same round: that ratio
 * carries from machine to machine far better than MB/s.
 *
 * Then the heap growth per frame in steady state, measured in a child process with a young
 * generation large enough that no garbage collection runs during the measurement.
 *
 * Environment: BENCH_ROUNDS (default 15), BENCH_WARMUP (default 3), BENCH_ONLY (a substring of
 * the case names to run, with their baselines).
 */
import { execFileSync } from 'node:child_process';
import { cpus, loadavg } from 'node:os';
import { fileURLToPath } from 'node:url';
import { SpektrumDecoder } from '../dist/decoder/index.js';
import { Simulator, preset } from '../dist/simulator/index.js';

const HOUR_US = 3600e6;
const ROUNDS = Number(process.env.BENCH_ROUNDS ?? 15);
const WARMUP = Number(process.env.BENCH_WARMUP ?? 3);
const CHUNK = 64;
/** Measured runs of the heap-growth child; the least is printed (a late (de)optimisation allocates once, in one run). */
const RUNS = 5;
const FRAME_SIZE = 16;

/** The streams: about 5.2 MB each (an hour at 11 ms, two at 22 ms). */
const STREAMS = {
  2048: { preset: 'dsmx-11ms-2048-internal', hours: 1, resolution: 2048, label: 'DSMX 11 ms 2048, internal remote, 1 h' },
  1024: { preset: 'dsm2-22ms-1024-internal', hours: 2, resolution: 1024, label: 'DSM2 22 ms 1024, internal remote, 2 h' },
  external: { preset: 'dsmx-11ms-2048-external', hours: 1, resolution: 2048, label: 'DSMX 11 ms 2048, external remote, 1 h' },
  // No stream at all: what a line held high (or runs of empty slots) and line noise cost to rule out.
  filler: { fill: () => new Uint8Array(5_200_000).fill(0xff), resolution: 2048, label: '0xFF filler, 5.2 MB' },
  noise: { fill: () => randomBytes(5_200_000), resolution: 2048, label: 'random bytes, 5.2 MB' },
};

/** `length` bytes from a fixed-seed xorshift: the same noise every run. */
function randomBytes(length) {
  const out = new Uint8Array(length);
  let x = 0x9e3779b9;
  for (let i = 0; i < length; i++) {
    x ^= x << 13;
    x ^= x >>> 17;
    x ^= x << 5;
    out[i] = x & 0xff;
  }
  return out;
}

function makeStream(key) {
  const s = STREAMS[key];
  let bytes = s.fill?.();
  let timesUs = null;
  if (bytes === undefined) {
    const sim = new Simulator({ ...preset(s.preset), seed: 1 });
    ({ bytes, timesUs } = sim.generate(sim.scenario.timing.startUs + s.hours * HOUR_US));
  }
  // What a serial port hands over: 64-byte views with the time of each one's last byte. Made up
  // front so that the timed loops allocate nothing of their own.
  const views = [];
  const byteTimes = [];
  const chunkTimes = new Float64Array(Math.ceil(bytes.length / CHUNK));
  for (let i = 0, k = 0; i < bytes.length; i += CHUNK, k++) {
    const end = Math.min(bytes.length, i + CHUNK);
    views.push(bytes.subarray(i, end));
    // A stream without times (filler, noise) is timed at line rate: 86.8 µs a byte.
    byteTimes.push(timesUs ? timesUs.subarray(i, end) : Float64Array.from({ length: end - i }, (_, j) => (i + j) * 86.8));
    chunkTimes[k] = timesUs ? timesUs[end - 1] : (end - 1) * 86.8;
  }
  return { ...s, key, bytes, timesUs, views, byteTimes, chunkTimes };
}

// ---- the cases ------------------------------------------------------------------------------

/**
 * The baseline: what a decoder that already knows the alignment must at least do. Aligned
 * 16-byte frames (no search, no header model), each of the seven slots validated (empty, a
 * channel ID in range or X-Plus, no ID twice) and its ID and position written out.
 */
function baseline(bytes, resolution) {
  const ids = new Uint8Array(7);
  const positions = new Uint16Array(7);
  let frames = 0;
  let invalid = 0;
  let sum = 0;
  const end = bytes.length - (bytes.length % FRAME_SIZE);
  for (let o = 0; o < end; o += FRAME_SIZE) {
    let seen = 0;
    let count = 0;
    let ok = true;
    for (let i = 0; i < 7; i++) {
      const word = (bytes[o + 2 + 2 * i] << 8) | bytes[o + 3 + 2 * i];
      if (word === 0xffff) continue;
      let id;
      let position;
      if (resolution === 2048) {
        id = (word >> 11) & 0x0f;
        if (id === 12) {
          id = 12 + ((word >> 9) & 3) + ((word & 0x8000) !== 0 ? 4 : 0);
          position = (word & 0x1ff) << 2;
        } else if (id > 11) {
          ok = false;
          break;
        } else {
          position = word & 0x7ff;
        }
      } else {
        id = word >> 10;
        if (id > 11) {
          ok = false;
          break;
        }
        position = word & 0x3ff;
      }
      const bit = 1 << id;
      if ((seen & bit) !== 0) {
        ok = false;
        break;
      }
      seen |= bit;
      ids[count] = id;
      positions[count] = position;
      count++;
    }
    if (!ok) {
      invalid++;
      continue;
    }
    frames++;
    sum += positions[0] + ids[count - 1];
  }
  if (sum < 0) throw new Error('unreachable: keeps the loop from being optimised away');
  return frames + invalid; // every aligned 16 bytes, like the decoder's frame count on a clean stream
}

function drain(d) {
  let n = 0;
  for (let f = d.next(); f; f = d.next()) n++;
  return n;
}

function whole(s) {
  const d = new SpektrumDecoder();
  d.push(s.bytes);
  const frames = drain(d);
  d.end();
  return frames + drain(d);
}

function chunkTimes(s, options = undefined) {
  const d = new SpektrumDecoder(options);
  const { views, chunkTimes: times } = s;
  let frames = 0;
  for (let k = 0; k < views.length; k++) {
    d.push(views[k], times[k]);
    frames += drain(d);
  }
  d.end();
  return frames + drain(d);
}

function perByteTimes(s) {
  const d = new SpektrumDecoder();
  const { views, byteTimes } = s;
  let frames = 0;
  for (let k = 0; k < views.length; k++) {
    d.push(views[k], byteTimes[k]);
    frames += drain(d);
  }
  d.end();
  return frames + drain(d);
}

// ---- the heap-growth child ------------------------------------------------------------------

if (process.argv[2] === '--alloc') {
  // Decode the stream twice so the JIT has settled. Then, five times, on a decoder that has
  // already locked (its first 1000 chunks fed beforehand: acquiring allocates once, about
  // 26 kB, none of it per frame), measure heap growth over the rest of the stream with no
  // garbage collection in between. A late optimisation or deoptimisation allocates on the heap
  // too, once: the least of the three is the decoder's own.
  const mode = process.argv[3];
  const s = makeStream(process.argv[4] ?? '2048');
  const SETTLE = 1000;
  // push() called straight from the loop, as a live reader or a replay does: whether a double
  // time gets boxed depends on what the JIT inlines into the caller.
  const { views, chunkTimes: times, byteTimes } = s;
  const run = {
    chunk: (d, from, to) => {
      let n = 0;
      for (let k = from; k < to; k++) {
        d.push(views[k], times[k]);
        n += drain(d);
      }
      return n;
    },
    'per-byte': (d, from, to) => {
      let n = 0;
      for (let k = from; k < to; k++) {
        d.push(views[k], byteTimes[k]);
        n += drain(d);
      }
      return n;
    },
    none: (d, from, to) => {
      let n = 0;
      for (let k = from; k < to; k++) {
        d.push(views[k]);
        n += drain(d);
      }
      return n;
    },
  }[mode];
  run(new SpektrumDecoder(), 0, s.views.length);
  run(new SpektrumDecoder(), 0, s.views.length);
  const { PerformanceObserver } = await import('node:perf_hooks');
  let gcs = 0;
  const obs = new PerformanceObserver((list) => {
    gcs += list.getEntries().length;
  });
  obs.observe({ entryTypes: ['gc'] });
  const runs = [];
  for (let r = 0; r < RUNS; r++) {
    const d = new SpektrumDecoder();
    run(d, 0, SETTLE);
    globalThis.gc();
    await new Promise((done) => setTimeout(done, 10));
    const gcsBefore = gcs;
    const before = process.memoryUsage().heapUsed;
    const frames = run(d, SETTLE, s.views.length);
    const after = process.memoryUsage().heapUsed;
    // The same measurement around no work: what measuring costs (memoryUsage's own object…).
    const emptyBefore = process.memoryUsage().heapUsed;
    run(d, 0, 0);
    const emptyAfter = process.memoryUsage().heapUsed;
    await new Promise((done) => setTimeout(done, 10));
    runs.push({ frames, pushes: s.views.length - SETTLE, bytes: after - before - (emptyAfter - emptyBefore), gcs: gcs - gcsBefore });
  }
  obs.disconnect();
  const all = runs.map((x) => x.bytes);
  runs.sort((x, y) => x.bytes - y.bytes);
  process.stdout.write(JSON.stringify({ ...runs[0], all }));
  process.exit(0);
}

// ---- the run --------------------------------------------------------------------------------

const only = process.env.BENCH_ONLY ?? '';
const streams = Object.fromEntries(Object.keys(STREAMS).map((k) => [k, makeStream(k)]));
/**
 * Each case: name, the stream, the function, the baseline it is compared with (null for a
 * baseline), and `vs`: the decoder case it is also compared with (other streams and timings
 * against the 2048 chunk-times case, which carry the targets' "within 25 %").
 */
const CHUNK_CASE = '64-byte chunks, chunk times';
const CASES = [
  { name: 'baseline JS loop, 2048 internal', stream: '2048', run: (s) => baseline(s.bytes, s.resolution), base: null },
  { name: 'whole buffer, no times', stream: '2048', run: whole, base: 'baseline JS loop, 2048 internal' },
  { name: CHUNK_CASE, stream: '2048', run: chunkTimes, base: 'baseline JS loop, 2048 internal' },
  { name: '64-byte chunks, per-byte times', stream: '2048', run: perByteTimes, base: 'baseline JS loop, 2048 internal', vs: CHUNK_CASE },
  { name: 'baseline JS loop, 1024 internal', stream: '1024', run: (s) => baseline(s.bytes, s.resolution), base: null },
  {
    name: '1024 mode, 64-byte chunks, chunk times',
    stream: '1024',
    run: chunkTimes,
    base: 'baseline JS loop, 1024 internal',
    vs: CHUNK_CASE,
  },
  { name: 'baseline JS loop, 2048 external', stream: 'external', run: (s) => baseline(s.bytes, s.resolution), base: null },
  {
    name: 'external remote, 64-byte chunks, chunk times',
    stream: 'external',
    run: chunkTimes,
    base: 'baseline JS loop, 2048 external',
    vs: CHUNK_CASE,
  },
  { name: 'no stream: 0xFF filler, 64-byte chunks', stream: 'filler', run: chunkTimes, base: null, vs: CHUNK_CASE },
  { name: 'no stream: random bytes, 64-byte chunks', stream: 'noise', run: chunkTimes, base: null, vs: CHUNK_CASE },
].filter(
  (c, _i, all) => only === '' || c.name.includes(only) || all.some((x) => (x.base === c.name || x.vs === c.name) && x.name.includes(only)),
);
// (A baseline, or the case others are compared with, stays in whenever a case compared with it does.)

const load = () =>
  loadavg()
    .map((x) => x.toFixed(2))
    .join(' ');
console.log(`SatScope decoder benchmark: node ${process.version}, ${cpus().length} CPUs, load average ${load()} (1, 5, 15 min)`);
for (const s of Object.values(streams))
  console.log(
    `  stream ${s.key.padEnd(8)} ${s.label}: ${(s.bytes.length / 1e6).toFixed(2)} MB, ${s.views.length} chunks of ${CHUNK} bytes`,
  );
console.log(`${ROUNDS} rounds interleaving ${CASES.length} cases after ${WARMUP} warm-up rounds; min / median / max`);

const ms = new Map(CASES.map((c) => [c.name, []]));
/** CPU time (user + system) of the same runs: what the run itself cost, whatever else ran on the cores. */
const cpuMs = new Map(CASES.map((c) => [c.name, []]));
const frames = new Map();
for (let r = 0; r < WARMUP + ROUNDS; r++) {
  for (const c of CASES) {
    const s = streams[c.stream];
    const cpu0 = process.cpuUsage();
    const t0 = performance.now();
    const n = c.run(s);
    const t = performance.now() - t0;
    const cpu = process.cpuUsage(cpu0);
    if (r >= WARMUP) {
      ms.get(c.name).push(t);
      cpuMs.get(c.name).push((cpu.user + cpu.system) / 1000);
    }
    if (frames.has(c.name) && frames.get(c.name) !== n) throw new Error(`${c.name}: ${n} frames, before ${frames.get(c.name)}`);
    frames.set(c.name, n);
  }
}

const sorted = (xs) => [...xs].sort((a, b) => a - b);
const stats = (xs) => {
  const v = sorted(xs);
  return [v[0], v[v.length >> 1], v[v.length - 1]];
};
const fmt = (v, digits) => v.map((x) => x.toFixed(digits).padStart(digits === 0 ? 5 : 5)).join(' /');
/** Per round: `other`'s time over this case's time (1.0: as fast; 0.5: half as fast); min / median / max. */
const ratioTo = (c, other) =>
  other !== undefined && other !== null && ms.has(other) ? fmt(stats(ms.get(c.name).map((t, i) => ms.get(other)[i] / t)), 2) : '';
console.log(
  `\n${'case'.padEnd(46)} ${'MB/s min / median / max'.padEnd(24)} ${'× baseline (same round)'.padEnd(24)} ${'× 2048 chunk times'.padEnd(24)} ${'CPU MB/s'.padEnd(9)} frames`,
);
for (const c of CASES) {
  const s = streams[c.stream];
  const mb = s.bytes.length / 1e6;
  const [lo, mid, hi] = stats(ms.get(c.name).map((t) => mb / (t / 1000)));
  const cpu = stats(cpuMs.get(c.name).map((t) => mb / (t / 1000)))[1];
  console.log(
    `${c.name.padEnd(46)} ${fmt([lo, mid, hi], 0).padEnd(24)} ${ratioTo(c, c.base).padEnd(24)} ${ratioTo(c, c.vs).padEnd(24)} ${cpu.toFixed(0).padStart(8)}  ${frames.get(c.name)}`,
  );
}
console.log(`load average after: ${load()}`);

const self = fileURLToPath(import.meta.url);
console.log(`\nheap growth in steady state (no GC during the run; locked decoder, the least of ${RUNS} runs after 2 warm-up runs):`);
for (const [mode, stream] of [
  ['chunk', '2048'],
  ['per-byte', '2048'],
  ['none', '2048'],
  ['chunk', '1024'],
  ['chunk', 'external'],
]) {
  if (only !== '' && !['heap', stream, mode].some((w) => only.includes(w))) continue;
  const alloc = JSON.parse(
    execFileSync(process.execPath, ['--expose-gc', '--max-semi-space-size=1024', self, '--alloc', mode, stream], { encoding: 'utf8' }),
  );
  const what = { chunk: '64-byte chunks, chunk times', 'per-byte': '64-byte chunks, per-byte times', none: '64-byte chunks, no times' }[
    mode
  ];
  console.log(
    `  ${`${stream}, ${what}`.padEnd(44)} ${(alloc.bytes / alloc.frames).toFixed(2).padStart(6)} bytes/frame = ${(alloc.bytes / alloc.pushes).toFixed(2).padStart(6)} bytes/push over ${alloc.frames} frames in ${alloc.pushes} pushes (${alloc.gcs} GCs; bytes in ${RUNS} runs: ${alloc.all.join(', ')})`,
  );
}
