/**
 * `satscope info`, `report` and `doctor` read a file a piece at a time: what they hold does not
 * grow with the file. Each command runs on a small and on a big file of each kind (a raw dump,
 * an .sscap recording, a Saleae CSV), in a child whose JavaScript heap is held to 64 MB (a file
 * held whole in the heap's objects fails there), and its peak resident memory is measured: from
 * the small file to the big one it grows by a fraction of what the file grows by (reading it
 * whole, by more than the file). Runs dist/cli/main.js: needs `npm run build:lib` first.
 */
import { spawnSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, statSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { CLI } from '../built-cli.js';
import { writeBig } from '../streamed-files.js';

const MB = 1 << 20;
const SMALL = 8 * MB;
const BIG = 72 * MB;
/** The most a command's peak memory may grow from the small file to the big one, as a share of what the file grew by. */
const GROWTH_MAX = 0.25;

let dir = '';
let hook = '';

beforeAll(() => {
  dir = mkdtempSync(join(tmpdir(), 'satscope-memory-'));
  // Writes the process's peak resident memory (KB) where RSS_FILE says, as it exits.
  hook = join(dir, 'rss-hook.mjs');
  writeFileSync(
    hook,
    "import { writeFileSync } from 'node:fs';\nprocess.on('exit', () => writeFileSync(process.env.RSS_FILE, String(process.resourceUsage().maxRSS)));\n",
  );
});

afterAll(() => {
  if (dir !== '') rmSync(dir, { recursive: true, force: true });
});

/** Peak resident memory (bytes) of `satscope command file`, which must succeed, its heap held to 64 MB. */
function peak(command: string, file: string): number {
  const rssFile = join(dir, 'rss');
  const r = spawnSync(process.execPath, ['--max-old-space-size=64', '--import', hook, CLI, command, file], {
    encoding: 'utf8',
    timeout: 300_000,
    env: { ...process.env, RSS_FILE: rssFile },
    maxBuffer: 256 * MB,
  });
  expect(r.status, `${command} ${file}: ${r.stderr}`).toBe(0);
  return Number(readFileSync(rssFile, 'utf8')) * 1024;
}

describe.each(['raw', 'sscap', 'csv'] as const)('a %s file', (kind) => {
  it('costs the same memory small or big, in info, report and doctor', () => {
    const ext = kind === 'raw' ? 'bin' : kind;
    const small = join(dir, `small.${ext}`);
    const big = join(dir, `big.${ext}`);
    writeBig(small, kind, SMALL);
    writeBig(big, kind, BIG);
    const grown = statSync(big).size - statSync(small).size;
    for (const command of ['info', 'report', 'doctor']) {
      const growth = peak(command, big) - peak(command, small);
      expect(growth / grown, `${command}: ${(growth / MB).toFixed(1)} MB more for ${(grown / MB).toFixed(0)} MB more file`).toBeLessThan(GROWTH_MAX);
    }
    rmSync(small);
    rmSync(big);
  });
});
