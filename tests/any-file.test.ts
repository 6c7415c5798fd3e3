/**
 * Any file, every command: random bytes, a picture, text, filler, other receivers' protocols,
 * truncated and bit-flipped captures and captures with absurd times, each through `decode`,
 * `info`, `report --json` and `doctor --json` as a user runs them. Each run ends in time with a
 * clear result (exit 0 or 1, a message, never a stack trace), in memory that does not grow with
 * the span of the times, and a file without a Spektrum stream is never called healthy: `info`
 * and `doctor` exit 1, `decode` prints no frame, the report's status is not "good".
 * Needs `npm run build:lib` first (`npm test` does it).
 */
import { spawn } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { CaptureWriter } from '../src/capture/writer.js';
import { crsfStream, ibusStream, sbusStream, srxl2Stream } from '../src/simulator/protocols.js';
import { preset } from '../src/simulator/presets.js';
import { Prng } from '../src/simulator/prng.js';
import { simulate } from '../src/simulator/simulator.js';
import { concatBytes } from './bytes.js';
import { CLI } from './built-cli.js';
import { usbChunks } from './feeds.js';

const root = resolve(import.meta.dirname, '..');
const SECOND = 1_000_000;
/** A run's ceiling: far above what any of these small files needs, far below a runaway. */
const RUN_TIMEOUT_MS = 30_000;
const MAX_RSS_KB = 400_000;

interface Case {
  name: string;
  bytes: Uint8Array | string;
  /** Whether the file holds a Spektrum stream (then info finds frames). */
  spektrum: boolean;
}

function randomBytes(seed: number, length: number): Uint8Array {
  const rng = new Prng(seed);
  return Uint8Array.from({ length }, () => Math.floor(rng.next() * 256));
}

function csvOf(bytes: Uint8Array, timesUs: Float64Array, time = (us: number) => (us / 1e6).toFixed(9)): string {
  const rows = ['Time [s],Value,Parity Error,Framing Error'];
  for (let i = 0; i < bytes.length; i++) rows.push(`${time(timesUs[i]!)},0x${bytes[i]!.toString(16).padStart(2, '0')},,`);
  return rows.join('\n');
}

/** A recording of `sim` with the chunk times `at(i, t)` gives (one of them absurd, say). */
function sscap(sim: { bytes: Uint8Array; timesUs: Float64Array }, at = (_i: number, t: number) => t): Uint8Array {
  const w = new CaptureWriter({ baudRate: 115200, source: 'test' });
  return concatBytes([w.header(), ...usbChunks(sim.bytes, sim.timesUs).map((c, i) => w.data(c.bytes, at(i, c.timeUs)))]);
}

function cases(): Case[] {
  const sim = simulate({ ...preset('dropouts-failsafe'), seed: 11 }, 3 * SECOND);
  const good = sscap(sim);
  const flipped = good.slice();
  const rng = new Prng(7);
  for (let k = 0; k < 40; k++) flipped[Math.floor(rng.next() * flipped.length)]! ^= 1 << Math.floor(rng.next() * 8);
  const other = { durationUs: 2 * SECOND };
  return [
    { name: 'random-1k.bin', bytes: randomBytes(1, 1024), spektrum: false },
    { name: 'random-20k.bin', bytes: randomBytes(2, 20_000), spektrum: false },
    { name: 'random.sscap', bytes: randomBytes(3, 5000), spektrum: false },
    { name: 'picture.png', bytes: readFileSync(join(root, 'public/icon-512.png')), spektrum: false },
    { name: 'readme.csv', bytes: readFileSync(join(root, 'README.md')), spektrum: false },
    { name: 'ff.bin', bytes: new Uint8Array(16_000).fill(0xff), spektrum: false },
    { name: 'ff64.bin', bytes: new Uint8Array(64).fill(0xff), spektrum: false },
    { name: 'zero.bin', bytes: new Uint8Array(16_000), spektrum: false },
    { name: 'alternating.bin', bytes: Uint8Array.from({ length: 16_000 }, (_, i) => (i & 1 ? 0xaa : 0x55)), spektrum: false },
    { name: 'sbus.bin', bytes: sbusStream(other).bytes, spektrum: false },
    { name: 'crsf.csv', bytes: csvOf(crsfStream(other).bytes, crsfStream(other).timesUs), spektrum: false },
    { name: 'ibus.bin', bytes: ibusStream(other).bytes, spektrum: false },
    { name: 'srxl2.csv', bytes: csvOf(srxl2Stream(other).bytes, srxl2Stream(other).timesUs), spektrum: false },
    { name: 'empty.bin', bytes: new Uint8Array(0), spektrum: false },
    { name: 'good.sscap', bytes: good, spektrum: true },
    { name: 'truncated.sscap', bytes: good.subarray(0, Math.floor(good.length * 0.6)), spektrum: true },
    { name: 'flipped.sscap', bytes: flipped, spektrum: true },
    { name: 'time-1e18.sscap', bytes: sscap(sim, (i, t) => (i === 40 ? 1e18 : t)), spektrum: true },
    { name: 'time-1e13.sscap', bytes: sscap(sim, (i, t) => (i === 40 ? 1e13 : t)), spektrum: true },
    {
      name: 'row-minus-inf.csv',
      bytes: csvOf(sim.bytes, sim.timesUs, (us) => (us === sim.timesUs[300] ? '-Infinity' : (us / 1e6).toFixed(9))),
      spektrum: true,
    },
    { name: 'time-nan-tenth.sscap', bytes: sscap(sim, (i, t) => (i % 10 === 9 ? NaN : t)), spektrum: true },
    { name: 'time-backwards.sscap', bytes: sscap(sim, (i, t) => (i === 40 ? t - 5 * SECOND : t)), spektrum: true },
    {
      name: 'row-1e18.csv',
      bytes: csvOf(
        sim.bytes,
        sim.timesUs.map((t, i) => (i === 300 ? 1e24 : t)),
      ),
      spektrum: true,
    },
  ];
}

interface Run {
  code: number | null;
  out: string;
  err: string;
  rssKb: number;
}

/** `satscope ...args` under GNU time (its peak memory), asynchronously, so two run at once. */
function satscope(args: string[]): Promise<Run> {
  const rssFile = join(dir, `rss-${Math.random().toString(36).slice(2)}`);
  return new Promise((done) => {
    // In a process group of its own, so that a run over time is stopped whole (GNU time and the
    // command), not only its first process.
    const child = spawn('/usr/bin/time', ['-f', '%M', '-o', rssFile, process.execPath, CLI, ...args], { detached: true });
    let killed = false;
    const timer = setTimeout(() => {
      killed = true;
      process.kill(-child.pid!, 'SIGKILL');
    }, RUN_TIMEOUT_MS);
    let out = '';
    let err = '';
    child.stdout.on('data', (d: Buffer) => {
      if (out.length < 1e6) out += d.toString();
    });
    child.stderr.on('data', (d: Buffer) => {
      if (err.length < 1e5) err += d.toString();
    });
    child.on('close', (code) => {
      clearTimeout(timer);
      let rssKb = Number.NaN;
      try {
        rssKb = Number(readFileSync(rssFile, 'utf8').trim().split('\n').at(-1));
      } catch {}
      done({ code: killed ? null : code, out, err, rssKb });
    });
  });
}

let dir = '';
const runs = new Map<string, Run>();
const COMMANDS: [string, string[]][] = [
  ['decode', ['decode']],
  ['info', ['info']],
  ['report', ['report', '--json']],
  ['doctor', ['doctor', '--json']],
];
const all = cases();

beforeAll(async () => {
  dir = mkdtempSync(join(tmpdir(), 'satscope-any-'));
  const jobs: (() => Promise<void>)[] = [];
  for (const c of all) {
    const file = join(dir, c.name);
    writeFileSync(file, c.bytes);
    for (const [command, args] of COMMANDS)
      jobs.push(async () => {
        runs.set(`${c.name} ${command}`, await satscope([...args, file]));
      });
  }
  // Two at a time: the machines have two cores.
  const next = async (): Promise<void> => {
    for (let job = jobs.shift(); job; job = jobs.shift()) await job();
  };
  await Promise.all([next(), next()]);
}, 600_000);

afterAll(() => {
  if (dir) rmSync(dir, { recursive: true, force: true });
});

describe('any file through every command', () => {
  it('counts no missed frame for chunks whose time is unknown or out of line', () => {
    const missed = (name: string) => /Gaps\s+(\d+) missed/.exec(runs.get(`${name} info`)!.out)?.[1];
    const good = missed('good.sscap');
    expect(good).toBeDefined();
    for (const name of ['time-nan-tenth.sscap', 'time-1e18.sscap', 'time-1e13.sscap', 'time-backwards.sscap'])
      expect(missed(name), name).toBe(good);
  });

  for (const c of all)
    for (const [command] of COMMANDS)
      it(`${c.name}: ${command} ends with a clear result`, () => {
        const r = runs.get(`${c.name} ${command}`)!;
        expect(r.code, `${command} ${c.name} exit (null: killed after ${RUN_TIMEOUT_MS} ms)\n${r.err}`).not.toBeNull();
        expect([0, 1], `${command} ${c.name}\n${r.err}`).toContain(r.code);
        expect(r.err).not.toMatch(/\n\s+at |RangeError|TypeError|internal error|heap out of memory/i);
        expect(r.rssKb, `${command} ${c.name} peak memory`).toBeLessThan(MAX_RSS_KB);
        if (r.code === 1) expect(`${r.out}${r.err}`, 'a message').not.toBe('');
        // A bad time is quoted where the file says it ("says NaN"); no figure is ever one.
        expect(r.out.replace(/(says|time \\?") ?-?(NaN|Infinity)\b/g, ''), 'a figure that is not a number').not.toMatch(
          /\bNaN\b|\bInfinity\b/,
        );
        if (c.spektrum) {
          if (command === 'info' || command === 'decode') expect(r.code, r.err).toBe(0);
          return;
        }
        // No Spektrum stream: never healthy, never a frame.
        if (command === 'decode') expect(r.out).toBe('');
        if (command === 'info') expect(r.code).toBe(1);
        if (command === 'doctor') {
          expect(r.code, r.out).toBe(1);
          // A file that is no capture at all is refused with a message; any other gets findings.
          if (r.out === '') expect(r.err).toMatch(/^satscope doctor: .+: /);
          else expect((JSON.parse(r.out) as { findings: unknown[] }).findings.length).toBeGreaterThan(0);
        }
        if (command === 'report' && r.out !== '') expect((JSON.parse(r.out) as { status: string }).status).not.toBe('good');
      });
});
