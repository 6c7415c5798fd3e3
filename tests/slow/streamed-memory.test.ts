/**
 * `satscope info`, `report` and `doctor` read a file a piece at a time: what they hold does not
 * grow with the file's bytes. Each command runs on a small and on a big file of each kind (a raw
 * dump, an .sscap recording, a Saleae CSV), in a child whose JavaScript heap is held to 64 MB,
 * and its peak resident memory is measured, streamed and read whole (SATSCOPE_READ_WHOLE=1):
 * from the small file to the big one, the streamed reading grows by less than half what the whole
 * one does. (Both grow by what the results hold, which follows the capture's span, not its bytes:
 * the series' bins and the doctor's per-second line windows, about 35 MB for the 7 hours of the
 * big .sscap; the whole reading grows by the file's bytes and its columns besides, twice the file
 * and more.) Runs dist/cli/main.js: needs `npm run build:lib` first.
 */
import { spawnSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { CLI } from '../built-cli.js';
import { writeBig } from '../streamed-files.js';

const MB = 1 << 20;
const SMALL = 8 * MB;
const BIG = 72 * MB;
/** The most the streamed reading's peak memory may grow from the small file to the big one, as a share of what the whole reading's grows by. */
const GROWTH_MAX = 0.5;

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
function peak(command: string, file: string, whole: boolean): number {
  const rssFile = join(dir, 'rss');
  const r = spawnSync(process.execPath, ['--max-old-space-size=64', '--import', hook, CLI, command, file], {
    encoding: 'utf8',
    timeout: 300_000,
    env: { ...process.env, RSS_FILE: rssFile, SATSCOPE_READ_WHOLE: whole ? '1' : '0' },
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
    for (const command of ['info', 'report', 'doctor']) {
      const streamed = peak(command, big, false) - peak(command, small, false);
      const whole = peak(command, big, true) - peak(command, small, true);
      const said = `${command}: ${(streamed / MB).toFixed(1)} MB more streamed, ${(whole / MB).toFixed(1)} MB more whole`;
      expect(streamed / whole, said).toBeLessThan(GROWTH_MAX);
    }
    rmSync(small);
    rmSync(big);
  });
});
