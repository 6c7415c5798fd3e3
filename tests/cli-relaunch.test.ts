/**
 * The satscope executable runs its command in a Node started with the command's options
 * (src/cli/relaunch.ts: Node's hang at exit), and is stopped, and ends, as the command would be.
 * Runs dist/cli/main.js: needs `npm run build:lib` first (`npm test` does it). Linux (/proc).
 */
import { spawn, spawnSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { COMMAND_NODE_FLAGS } from '../src/cli/relaunch.js';
import { preset, simulate } from '../src/simulator/index.js';
import { CLI, CLI_TIMEOUT_MS, satscope } from './built-cli.js';

let dir = '';
let file = '';

beforeAll(() => {
  dir = mkdtempSync(join(tmpdir(), 'satscope-relaunch-'));
  // Twenty minutes of frames: about 30 MB of JSON lines, far more than a pipe holds.
  const minute = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 5 }, 60_000_000);
  const bytes = new Uint8Array(20 * minute.bytes.length);
  for (let t = 0; t < 20; t++) bytes.set(minute.bytes, t * minute.bytes.length);
  file = join(dir, 'long.bin');
  writeFileSync(file, bytes);
});

afterAll(() => rmSync(dir, { recursive: true, force: true }));

/** The children of process `pid`. */
function childrenOf(pid: number): number[] {
  return readFileSync(`/proc/${pid}/task/${pid}/children`, 'utf8').trim().split(/\s+/).filter(Boolean).map(Number);
}

/** The command line of process `pid`, word by word. */
function commandLine(pid: number): string[] {
  return readFileSync(`/proc/${pid}/cmdline`, 'utf8').split('\0').filter(Boolean);
}

/** Whether process `pid` is still running (not gone, not a zombie). */
function running(pid: number): boolean {
  if (!existsSync(`/proc/${pid}`)) return false;
  return !/\) [ZX] /.test(readFileSync(`/proc/${pid}/stat`, 'utf8'));
}

describe.skipIf(!existsSync(`/proc/${process.pid}/task/${process.pid}/children`))('the satscope executable', () => {
  it('runs the command in a Node started with the command options, and a SIGTERM stops both', async () => {
    const satscope = spawn(process.execPath, [CLI, 'decode', file], { stdio: ['ignore', 'pipe', 'pipe'] });
    // Nobody reads: the command waits on the full pipe, still running.
    satscope.stdout.pause();
    const ended = new Promise<{ code: number | null; signal: string | null }>((r) =>
      satscope.on('exit', (code, signal) => r({ code, signal })),
    );
    let children: number[] = [];
    for (let i = 0; i < 100 && children.length === 0; i++) {
      await new Promise((r) => setTimeout(r, 50));
      children = childrenOf(satscope.pid!);
    }
    expect(children).toHaveLength(1);
    const childPid = children[0]!;
    const command = commandLine(childPid);
    expect(command.slice(1, 1 + COMMAND_NODE_FLAGS.length)).toEqual(COMMAND_NODE_FLAGS);
    expect(command.slice(-3)).toEqual([CLI, 'decode', file]);
    expect(running(childPid)).toBe(true);
    // What the command wrote, to its end: once satscope has ended, Node reads its pipe on.
    let lines = 0;
    satscope.stdout.on('data', (chunk: Buffer) => {
      for (let i = chunk.indexOf(10); i >= 0; i = chunk.indexOf(10, i + 1)) lines++;
    });
    const closed = new Promise((r) => satscope.stdout.on('close', r));
    satscope.kill('SIGTERM');
    expect(await ended).toEqual({ code: null, signal: 'SIGTERM' });
    await closed;
    // Its pipe closes as it exits: a moment before it is gone.
    for (let i = 0; i < 40 && running(childPid); i++) await new Promise((r) => setTimeout(r, 50));
    expect(running(childPid)).toBe(false);
    // Stopped where the pipe held it: not one of the twenty minutes' hundred thousand frames more.
    expect(lines).toBeLessThan(2_000);
  });

  it('ends with the exit code of the command, 0 when the reader stops early (| head)', () => {
    const r = spawnSync('sh', ['-c', `("${process.execPath}" "${CLI}" decode "${file}"; echo "exit $?" >&2) | head -n 2`], {
      encoding: 'utf8',
      timeout: CLI_TIMEOUT_MS,
    });
    expect(
      r.stdout
        .split('\n')
        .slice(0, 2)
        .every((l) => l.startsWith('{"t": null, "remote": "internal"')),
    ).toBe(true);
    expect(r.stderr).toBe('exit 0\n');
    const missing = satscope('info', join(dir, 'no-such.bin'));
    expect(missing.code).toBe(2);
    expect(missing.err).toMatch(/^satscope: .*no-such\.bin/);
  });
});
