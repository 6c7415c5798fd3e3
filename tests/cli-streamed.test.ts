/**
 * `satscope info`, `report` and `doctor` read a file a window at a time (src/cli/streamed-file.ts)
 * and say exactly what they said reading it whole: every command and output form, byte for byte,
 * on every kind of file (the fixtures' raw dumps, the PX4 Saleae exports, simulated .sscap
 * recordings and CSVs), with SATSCOPE_READ_WHOLE=1 giving the whole reading. Files that must be
 * read whole (a damaged .sscap, times the time rule steps over) are, and say the same.
 * Runs dist/cli/main.js: needs `npm run build:lib` first (`npm test` does it).
 */
import { spawnSync } from 'node:child_process';
import { existsSync, mkdtempSync, readdirSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { openStreamed } from '../src/cli/streamed-file.js';
import { CLI, CLI_TIMEOUT_MS } from './built-cli.js';
import { writeSamples } from './streamed-files.js';

let dir = '';
let samples: string[] = [];
const fixtures = resolve(import.meta.dirname, 'fixtures');
const px4 = resolve(import.meta.dirname, '../../shared/captures/px4');

beforeAll(() => {
  dir = mkdtempSync(join(tmpdir(), 'satscope-streamed-'));
  samples = writeSamples(dir);
  // Damaged: a byte of a record flipped (salvaged), and a recording cut inside a record.
  const one = readFileSync(join(dir, 'one.sscap'));
  const flipped = Uint8Array.from(one);
  const mid = Math.floor(one.length / 2);
  flipped[mid] = (flipped[mid] ?? 0) ^ 0xff;
  writeFileSync(join(dir, 'flipped.sscap'), flipped);
  writeFileSync(join(dir, 'cut.sscap'), one.subarray(0, one.length - 7));
});

afterAll(() => {
  if (dir !== '') rmSync(dir, { recursive: true, force: true });
});

/** stdout, stderr and the exit code of `satscope ...args`, read streamed or whole. */
function run(whole: boolean, ...args: string[]): string {
  const env = { ...process.env, SATSCOPE_READ_WHOLE: whole ? '1' : '0' };
  const r = spawnSync(process.execPath, [CLI, ...args], { encoding: 'utf8', timeout: CLI_TIMEOUT_MS, env, cwd: dir });
  return `${r.stdout}\n--- stderr\n${r.stderr}\n--- exit ${r.status}`;
}

/** Each command, each form (the text forms print what the JSON holds: one of each is enough for doctor and info). */
const COMMANDS = [['info'], ['info', '--port', '1', '--json'], ['report'], ['report', '--json'], ['doctor', '--json']];

/** A few dozen runs of the CLI, on a busy machine. */
const RUNS_MS = 300_000;

describe('a streamed file says what the whole file says', () => {
  it('streams every sample, and reads the damaged ones whole', () => {
    for (const f of samples) expect(openStreamed(f), f).not.toBeNull();
    for (const name of ['flipped.sscap', 'cut.sscap']) expect(openStreamed(join(dir, name)), name).toBeNull();
  });

  it(
    'on simulated recordings and exports, every command and form',
    () => {
      for (const f of [...samples, join(dir, 'flipped.sscap'), join(dir, 'cut.sscap')])
        for (const cmd of COMMANDS) expect(run(false, ...cmd, f), `${cmd.join(' ')} ${f}`).toBe(run(true, ...cmd, f));
    },
    RUNS_MS,
  );

  it(
    'on the raw fixtures',
    () => {
      const files = readdirSync(fixtures).filter((f) => f.endsWith('.bin'));
      expect(files.length).toBeGreaterThan(5);
      for (const f of files.slice(0, 6))
        for (const cmd of [['info', '--json'], ['report', '--json'], ['doctor']])
          expect(run(false, ...cmd, join(fixtures, f)), `${cmd} ${f}`).toBe(run(true, ...cmd, join(fixtures, f)));
    },
    RUNS_MS,
  );

  it.skipIf(!existsSync(px4))(
    'on the real PX4 captures',
    () => {
      for (const f of readdirSync(px4)) {
        const path = join(px4, f);
        expect(openStreamed(path), f).not.toBeNull();
        for (const cmd of [['info'], ['report', '--json'], ['report'], ['doctor', '--json']])
          expect(run(false, ...cmd, path), `${cmd} ${f}`).toBe(run(true, ...cmd, path));
      }
    },
    RUNS_MS,
  );
});
