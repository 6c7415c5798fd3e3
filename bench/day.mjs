#!/usr/bin/env node
/**
 * Day-long captures (npm run bench:day): `satscope info` and `satscope report` on captures of
 * two remotes at 11 ms (a DSMX internal remote on port 0, an external one on port 1, recorded
 * as a USB adapter delivers them: whatever arrived in each 16 ms window, one record each) of 1
 * minute, 1 hour and 24 hours, each timed in a child process with its peak memory, so that cost
 * growth can be read against the file size. Measurement only: the files live in os.tmpdir()
 * (never in the repository) and are kept there for the next run (`--fresh` makes them again).
 *
 * Options: --only 1m,1h (durations to run; 7d, a week of 3 GB, only when named), --fresh,
 * --keep-html, --make-only (make the captures, run no command: for bench/replay.mjs and the page).
 */
import { spawnSync } from 'node:child_process';
import { closeSync, existsSync, openSync, renameSync, rmSync, statSync, writeSync } from 'node:fs';
import { cpus, loadavg, tmpdir } from 'node:os';
import { join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { CaptureWriter } from '../dist/capture/index.js';
import { Simulator, preset } from '../dist/simulator/index.js';

const VERSION = 1; // bump when the generated stream changes, so old files are not reused
const DURATIONS = { '1m': 60e6, '1h': 3600e6, '24h': 24 * 3600e6, '7d': 7 * 24 * 3600e6 };
/** Made and run unless `--only` says otherwise: the week (3 GB) only when asked for. */
const DEFAULT = ['1m', '1h', '24h'];
const USB_WINDOW_US = 16_000;
const BLOCK_US = 1_000_000;
const cli = fileURLToPath(new URL('../dist/cli/main.js', import.meta.url));

const args = process.argv.slice(2);
const only = args.includes('--only') ? args[args.indexOf('--only') + 1].split(',') : DEFAULT;
const fresh = args.includes('--fresh');
/** Only make the captures (for bench/replay.mjs and the page bench), run no command. */
const makeOnly = args.includes('--make-only');

/** Writes the capture of `durationUs` to `path` (through a temporary file: a cut-off run leaves no half file). */
function makeCapture(path, durationUs) {
  const writer = new CaptureWriter({
    source: 'simulator',
    baudRate: 115200,
    note: 'bench/day.mjs',
    ports: [{ name: 'internal DSMX 11 ms' }, { name: 'external DSMX 11 ms' }],
  });
  const sims = [
    new Simulator({ ...preset('dsmx-11ms-2048-internal'), seed: 11 }),
    new Simulator({ ...preset('dsmx-11ms-2048-external'), seed: 12 }),
  ];
  const part = `${path}.part`;
  const fd = openSync(part, 'w');
  const out = new Uint8Array(8 << 20);
  let used = 0;
  const put = (record) => {
    if (used + record.length > out.length) {
      writeSync(fd, out, 0, used);
      used = 0;
    }
    out.set(record, used);
    used += record.length;
  };
  put(writer.header());
  const start = sims[0].scenario.timing.startUs;
  for (let t = start; t < start + durationUs; t += BLOCK_US) {
    const until = Math.min(t + BLOCK_US, start + durationUs);
    // Each port's bytes of this second, cut where a 16 ms USB window closes; then both ports'
    // records merged in time order (the recorder's one clock).
    const records = [];
    for (const [port, sim] of sims.entries()) {
      const { bytes, timesUs } = sim.generate(until);
      let from = 0;
      for (let i = 0; i <= bytes.length; i++) {
        const deadline = Math.floor((timesUs[from] ?? 0) / USB_WINDOW_US) * USB_WINDOW_US + USB_WINDOW_US;
        if (i === bytes.length || timesUs[i] >= deadline) {
          if (i > from) records.push({ port, time: deadline, bytes: bytes.subarray(from, i) });
          from = i;
        }
      }
    }
    records.sort((a, b) => a.time - b.time || a.port - b.port);
    for (const r of records) put(writer.data(r.bytes, r.time, r.port));
  }
  writeSync(fd, out, 0, used);
  closeSync(fd);
  renameSync(part, path);
}

/** Runs the CLI under /usr/bin/time -v: wall and CPU seconds, peak resident memory. */
function measure(argv) {
  const r = spawnSync('/usr/bin/time', ['-v', process.execPath, cli, ...argv], { encoding: 'utf8', maxBuffer: 1 << 30 });
  const field = (name) => r.stderr.match(new RegExp(`${name}: (.*)`))?.[1];
  const [m, s] = (field('Elapsed \\(wall clock\\) time \\(h:mm:ss or m:ss\\)') ?? '0:0').split(':').slice(-2).map(Number);
  return {
    status: r.status,
    wallS: m * 60 + s,
    cpuS: Number(field('User time \\(seconds\\)')) + Number(field('System time \\(seconds\\)')),
    peakMB: Number(field('Maximum resident set size \\(kbytes\\)')) / 1024,
    stdout: r.stdout,
    stderr: r.stderr.split('\n\tCommand being timed')[0],
  };
}

const load = () =>
  loadavg()
    .map((x) => x.toFixed(2))
    .join(' ');
console.log(`satscope on day-long captures: node ${process.version}, ${cpus().length} CPUs, load average ${load()}`);
// What node itself takes, to read the peak memory figures against.
const idle = measure(['--version']);
console.log(`node + satscope --version alone: ${idle.wallS.toFixed(2)} s, peak ${idle.peakMB.toFixed(0)} MB\n`);
console.log(
  `${'capture'.padEnd(8)} ${'file MB'.padStart(8)} ${'command'.padEnd(8)} ${'wall s'.padStart(7)} ${'cpu s'.padStart(7)} ${'peak MB'.padStart(8)} ${'peak/file'.padStart(9)} ${'s per file GB'.padStart(13)} ${'cpu s per GB'.padStart(12)}`,
);
const rows = [];
for (const name of only) {
  const durationUs = DURATIONS[name];
  if (durationUs === undefined) throw new Error(`unknown duration ${name}: one of ${Object.keys(DURATIONS).join(', ')}`);
  const path = join(tmpdir(), `satscope-bench-day-v${VERSION}-${name}.sscap`);
  if (fresh || !existsSync(path)) {
    const t0 = performance.now();
    makeCapture(path, durationUs);
    console.log(`(made ${path} in ${((performance.now() - t0) / 1000).toFixed(1)} s)`);
  }
  const fileMB = statSync(path).size / 2 ** 20;
  if (makeOnly) continue;
  const html = join(tmpdir(), `satscope-bench-day-${name}.html`);
  for (const [command, argv] of [
    ['info', ['info', path]],
    ['report', ['report', path, '--out', html]],
  ]) {
    const r = measure(argv);
    if (r.status !== 0) console.log(`  ${command} exited with ${r.status}: ${r.stderr.trim().split('\n').slice(-3).join(' / ')}`);
    rows.push({ name, command, fileMB, ...r });
    console.log(
      `${name.padEnd(8)} ${fileMB.toFixed(1).padStart(8)} ${command.padEnd(8)} ${r.wallS.toFixed(2).padStart(7)} ${r.cpuS.toFixed(2).padStart(7)} ${r.peakMB.toFixed(0).padStart(8)} ${(r.peakMB / fileMB).toFixed(2).padStart(9)} ${(r.wallS / (fileMB / 1024)).toFixed(1).padStart(13)} ${(r.cpuS / (fileMB / 1024)).toFixed(1).padStart(12)}`,
    );
  }
  if (!args.includes('--keep-html')) rmSync(html, { force: true });
}
console.log(`\nload average after: ${load()}`);
console.log(
  'Targets (issue 12): info and report under 5 s with peak memory under 3× the file size on the 24-hour capture; cost linear in the file size (s per file GB flat).',
);
