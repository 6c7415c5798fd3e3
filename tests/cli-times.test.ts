/**
 * Absurd times in a file never kill, hang or flood the command line: for random bad times (NaN,
 * infinities, 1e18, far back, far forward, any double) in an .sscap or a Saleae CSV, and for
 * random raw bytes, `info`, `decode`, `report` and `doctor` each end with a clear result (exit 0
 * or 1, never a stack trace) in bounded time and memory, and say what they stepped over.
 * Runs dist/cli/main.js: needs `npm run build:lib` first (`npm test` does it).
 */
import { spawnSync } from 'node:child_process';
import { closeSync, mkdtempSync, openSync, rmSync, writeFileSync, writeSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';
import fc from 'fast-check';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { CaptureWriter } from '../src/capture/writer.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { CLI } from './built-cli.js';
import { concatBytes } from './bytes.js';
import { usbChunks } from './feeds.js';

let dir = '';
const sim = simulate(preset('dsmx-11ms-2048-internal'), 2_000_000);
const CHUNKS = usbChunks(sim.bytes, sim.timesUs);

/** Each run of a command must end within this, and stay under this peak memory. */
const RUN_MS = 15_000;
const PEAK_KB = 200 * 1024;

beforeAll(() => {
  dir = mkdtempSync(join(tmpdir(), 'satscope-times-'));
  // The CLI, reporting its peak resident memory on stderr as it exits (as cli-stream.test.ts does).
  writeFileSync(
    join(dir, 'peak.mjs'),
    `import { writeSync } from 'node:fs';\n` +
      `process.on('exit', () => writeSync(2, '\\npeak-rss-kb ' + process.resourceUsage().maxRSS + '\\n'));\n` +
      `await import(${JSON.stringify(pathToFileURL(CLI).href)});\n`,
  );
});

afterAll(() => rmSync(dir, { recursive: true, force: true }));

/** `satscope ...args` with its peak memory (kB) and how long it took. */
function run(...args: string[]) {
  const started = performance.now();
  const r = spawnSync(process.execPath, [join(dir, 'peak.mjs'), ...args], { encoding: 'utf8', timeout: RUN_MS });
  const err = String(r.stderr ?? '');
  return {
    code: r.status,
    ms: performance.now() - started,
    peakKb: Number(/peak-rss-kb (\d+)/.exec(err)?.[1] ?? Number.NaN),
    err: err.replace(/\s*peak-rss-kb \d+\s*$/, ''),
    out: String(r.stdout ?? ''),
  };
}

const COMMANDS = [['info'], ['decode'], ['report', '--json'], ['doctor', '--json']] as const;

/** Every command on `file`: each ends, within time and memory, with a clear result; their stderr, per command. */
function everyCommand(file: string, framesExpected: boolean): Map<string, string> {
  const errs = new Map<string, string>();
  for (const command of COMMANDS) {
    const r = run(...command, file);
    const what = `${command.join(' ')} ${file}: exit ${r.code}, ${r.ms.toFixed(0)} ms, ${(r.peakKb / 1024).toFixed(0)} MB\n${r.err.slice(0, 2000)}`;
    expect(r.code, what).not.toBeNull();
    expect([0, 1], what).toContain(r.code);
    if (framesExpected && command[0] !== 'doctor') expect(r.code, what).toBe(0);
    expect(r.err, what).not.toMatch(/\n\s+at |RangeError|TypeError|internal error/);
    expect(r.peakKb, what).toBeLessThan(PEAK_KB);
    errs.set(command[0], r.err);
  }
  return errs;
}

/**
 * A time no clock gives: not a number, infinite, or over 10^12 µs (11.6 days) from the capture's
 * few seconds either way. (Any double was drawn once, and 0 for the first chunk is no damage: a
 * stream may start there. Seed -1687542541 drew it.)
 */
const absurd = fc.oneof(
  fc.constantFrom(Number.NaN, Number.POSITIVE_INFINITY, Number.NEGATIVE_INFINITY, 1e18, -1e18, 1e13, -1e13, 2 ** 53, Number.MAX_VALUE),
  fc.double({ min: 1e12, noNaN: true }),
  fc.double({ max: -1e12, noNaN: true }),
);

/** Some chunk indices with the times they get instead of their own. */
const damage = (n: number) => fc.array(fc.tuple(fc.nat(n - 1), absurd), { minLength: 1, maxLength: 12 });

/** The simulated stream as an .sscap, chunk `k` timed `bad.get(k)` where given (written into the record when the writer refuses it). */
function sscap(bad: Map<number, number>): Uint8Array {
  const w = new CaptureWriter({ source: 'test' });
  const parts = [w.header()];
  CHUNKS.forEach((c, k) => {
    const t = bad.get(k);
    const record = w.data(c.bytes, t === undefined || !Number.isFinite(t) ? c.timeUs : t);
    if (t !== undefined && !Number.isFinite(t)) setRecordTime(record, t);
    parts.push(record);
  });
  return concatBytes(parts);
}

/** A whole data record with its time set to `timeUs` and its CRC-32 made again. */
function setRecordTime(record: Uint8Array, timeUs: number): void {
  const view = new DataView(record.buffer, record.byteOffset, record.byteLength);
  view.setFloat64(8, timeUs, true);
  const end = record.length - 4;
  let crc = 0xffffffff;
  for (let i = 2; i < end; i++) {
    crc ^= record[i]!;
    for (let b = 0; b < 8; b++) crc = (crc >>> 1) ^ (0xedb88320 & -(crc & 1));
  }
  view.setUint32(end, (crc ^ 0xffffffff) >>> 0, true);
}

describe('absurd times on every command', () => {
  it('in an .sscap: every command ends with the stream read, and says what it stepped over', () => {
    fc.assert(
      fc.property(damage(CHUNKS.length), (bad) => {
        const file = join(dir, 'bad.sscap');
        writeFileSync(file, sscap(new Map(bad)));
        const errs = everyCommand(file, true);
        expect(errs.get('info')).toMatch(/chunk times? jump out of line|the clock steps|bad-time/);
      }),
      { numRuns: 3 },
    );
  }, 120_000);

  it('in a Saleae CSV: every command ends with the stream read, and says what it stepped over', () => {
    const rows = Array.from(sim.bytes.subarray(0, 6000), (b, i) => [
      (sim.timesUs[i]! / 1e6).toFixed(9),
      `0x${b.toString(16).padStart(2, '0')}`,
    ]);
    fc.assert(
      fc.property(damage(rows.length), (bad) => {
        const times = new Map(bad);
        const text = rows.map(([t, v], i) => `${times.has(i) ? String(times.get(i)! / 1e6) : t},${v},,`).join('\n');
        const file = join(dir, 'bad.csv');
        writeFileSync(file, `Time [s],Value,Parity Error,Framing Error\n${text}\n`);
        const errs = everyCommand(file, true);
        // Any time out of line, a number or not ("NaN", "Infinity"), is stepped over, its byte kept.
        expect(errs.get('info')).toMatch(/byte times jump out of line|the clock steps/);
      }),
      { numRuns: 3 },
    );
  }, 120_000);

  it('in random raw bytes: every command ends with a clear result', () => {
    fc.assert(
      fc.property(fc.uint8Array({ minLength: 1, maxLength: 20_000 }), (bytes) => {
        const file = join(dir, 'random.bin');
        writeFileSync(file, bytes);
        everyCommand(file, false);
      }),
      { numRuns: 2 },
    );
  }, 120_000);
});

describe('a file of 2 GiB or more', () => {
  it('decodes as it is read: a stream at its start comes out at once, in little memory', () => {
    // Sparse: 20 s of a stream (more output than head takes, so the command learns it stopped
    // reading), then a hole to 2.2 GB that costs no disk.
    const file = join(dir, 'huge.bin');
    const fd = openSync(file, 'w');
    try {
      writeSync(fd, simulate(preset('dsmx-11ms-2048-internal'), 20_000_000).bytes);
      writeSync(fd, new Uint8Array(1), 0, 1, 2_200_000_000 - 1);
    } finally {
      closeSync(fd);
    }
    const child = spawnSync('sh', ['-c', `"${process.execPath}" "${join(dir, 'peak.mjs')}" decode "${file}" | head -n 3`], {
      encoding: 'utf8',
      timeout: RUN_MS,
    });
    expect(child.status).toBe(0);
    expect(child.stdout.trim().split('\n')).toHaveLength(3);
    expect(child.stdout).toMatch(/^\{"t": null, "remote": "internal"/);
    expect(child.stderr).not.toMatch(/internal error|RangeError|\n\s+at /);
    const peak = Number(/peak-rss-kb (\d+)/.exec(child.stderr)?.[1]);
    expect(peak).toBeLessThan(PEAK_KB);
  });
});
