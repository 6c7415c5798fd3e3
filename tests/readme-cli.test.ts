/**
 * The command line exactly as the README shows it: every `npx satscope ...` line of its
 * "Command line" and "Health report" blocks, run through npx in the repository (where a fresh
 * clone's `npm ci` has built the command: package.json's `prepare`), on files of the names the
 * README uses. Needs `npm run build:lib` first (`npm test` does it, and so does `npm ci`).
 */
import { spawnSync } from 'node:child_process';
import { copyFileSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { CaptureWriter } from '../src/capture/writer.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { concatBytes } from './bytes.js';
import { usbChunks } from './feeds.js';

const root = resolve(import.meta.dirname, '..');
const readme = readFileSync(join(root, 'README.md'), 'utf8');
const pkg = JSON.parse(readFileSync(join(root, 'package.json'), 'utf8')) as { scripts: Record<string, string> };
let dir = '';

/** The `npx satscope ...` lines of the README's sh blocks, comments cut off. */
function readmeCommands(): string[] {
  const lines: string[] = [];
  for (const block of readme.matchAll(/```sh\n([\s\S]*?)```/g))
    for (const line of block[1]!.split('\n')) if (line.startsWith('npx satscope ')) lines.push(line.replace(/\s+#.*$/, '').trim());
  return lines;
}

beforeAll(() => {
  dir = mkdtempSync(join(tmpdir(), 'satscope-readme-'));
  const sim = simulate({ ...preset('dropouts-failsafe'), seed: 5 }, 3_000_000);
  const writer = new CaptureWriter({ baudRate: 115200, source: 'test' });
  const parts = [writer.header()];
  for (const c of usbChunks(sim.bytes, sim.timesUs)) parts.push(writer.data(c.bytes, c.timeUs));
  writeFileSync(join(dir, 'capture.sscap'), concatBytes(parts));
  copyFileSync(join(root, 'tests/fixtures/dsmx-11ms-2048-external.bin'), join(dir, 'dump.bin'));
  const csv = ['Time [s],Value,Parity Error,Framing Error'];
  for (let i = 0; i < sim.bytes.length; i++)
    csv.push(`${(sim.timesUs[i]! / 1e6).toFixed(9)},0x${sim.bytes[i]!.toString(16).padStart(2, '0')},,`);
  writeFileSync(join(dir, 'saleae-export.csv'), csv.join('\n'));
});

afterAll(() => {
  if (dir) rmSync(dir, { recursive: true, force: true });
});

describe("the README's command lines", () => {
  it('are built by npm ci on a fresh clone (prepare builds the library)', () => {
    expect(pkg.scripts.prepare).toBe('npm run build:lib');
  });

  const commands = readmeCommands();
  it('are all found', () => {
    expect(commands.length).toBeGreaterThanOrEqual(6);
  });

  for (const command of commands)
    it(`run as written: ${command}`, () => {
      // The README's file names, in the scratch folder; `--out` there too; `> file` is the shell's.
      const args = command
        .replace(/\s*>\s*\S+$/, '')
        .split(/\s+/)
        .slice(2)
        .map((a) => (/\.(sscap|bin|csv|html)$/.test(a) ? join(dir, a) : a));
      const r = spawnSync('npx', ['--no-install', 'satscope', ...args], { cwd: root, encoding: 'utf8', timeout: 60_000 });
      const expected = args[0] === 'doctor' ? [0, 1] : [0]; // doctor: exit 1 on a problem
      expect(expected, `${command}\n${r.stderr}`).toContain(r.status);
      expect(r.stdout.length + (args.includes('--out') ? 1 : 0)).toBeGreaterThan(0);
      expect(r.stderr).not.toMatch(/not found|internal error/i);
    });
});
