/**
 * `satscope decode` on a large capture, through a pipe: the output streams with backpressure
 * (memory stays flat however slow the reader is) and a reader that stops early (`| head`) ends
 * it cleanly. Runs dist/cli/main.js: needs `npm run build:lib` first (`npm test` does it).
 */
import { spawn, spawnSync } from 'node:child_process';
import { closeSync, existsSync, mkdtempSync, openSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { CLI as cli, CLI_TIMEOUT_MS, satscopeWith } from './built-cli.js';

let dir = '';
let big = '';
/** Tiles of a simulated minute, back to back: a continuous stream of whole frames. */
const TILES = 120;
let frames = 0;

beforeAll(() => {
  dir = mkdtempSync(join(tmpdir(), 'satscope-stream-'));
  const minute = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 21 }, 60_000_000, { truth: true });
  expect(minute.truth!.frames.every((f) => f.damage === null)).toBe(true);
  expect(minute.bytes.length % 16).toBe(0);
  frames = TILES * minute.truth!.frames.length;
  const bytes = new Uint8Array(TILES * minute.bytes.length); // ≈ 10 MB, ≈ 230 MB of JSON lines
  for (let t = 0; t < TILES; t++) bytes.set(minute.bytes, t * minute.bytes.length);
  big = join(dir, 'big.bin');
  writeFileSync(big, bytes);
  // Runs the CLI and, as it exits, reports its peak resident memory on stderr: in this process,
  // started with the command's Node options (else it would start another Node to run in).
  writeFileSync(
    join(dir, 'peak.mjs'),
    `import { writeSync } from 'node:fs';\n` +
      `process.on('exit', () => writeSync(2, '\\npeak-rss-kb ' + process.resourceUsage().maxRSS + '\\n'));\n` +
      `await import(${JSON.stringify(pathToFileURL(cli).href)});\n`,
  );
});

afterAll(() => rmSync(dir, { recursive: true, force: true }));

const sleep = (ms: number): Promise<void> => new Promise((r) => setTimeout(r, ms));

describe('satscope decode into a pipe', () => {
  it('keeps its memory flat when the reader is slow, and still delivers every frame', async () => {
    const child = spawn(process.execPath, [join(dir, 'peak.mjs'), 'decode', big], {
      stdio: ['ignore', 'pipe', 'pipe'],
    });
    let err = '';
    child.stderr.setEncoding('utf8').on('data', (s: string) => (err += s));
    const exited = new Promise<number | null>((r) => child.on('close', (code) => r(code)));
    // A slow reader: nothing for a second and a half (long enough to decode everything), then
    // a pause after every 4 MB.
    child.stdout.pause();
    await sleep(1500);
    let lines = 0;
    let sincePause = 0;
    for await (const chunk of child.stdout as AsyncIterable<Buffer>) {
      for (let i = chunk.indexOf(10); i >= 0; i = chunk.indexOf(10, i + 1)) lines++;
      sincePause += chunk.length;
      if (sincePause > 4 << 20) {
        sincePause = 0;
        await sleep(20);
      }
    }
    expect(await exited).toBe(0);
    expect(lines).toBe(frames);
    const peak = Number(/peak-rss-kb (\d+)/.exec(err)?.[1]);
    console.log(`satscope decode of ${TILES * 60} s (${frames} frames) into a slow pipe: peak RSS ${(peak / 1024).toFixed(0)} MB`);
    // Holding the output would take the ≈ 230 MB of text plus the file; streaming, the process
    // stays near Node's own footprint.
    expect(peak).toBeLessThan(160 * 1024);
    expect(err.replace(/\s*peak-rss-kb \d+\s*/, '')).toBe('');
  }, 60_000);

  it.skipIf(!existsSync('/dev/full'))('says the output could not be written, with exit code 1, when the disk is full', () => {
    const full = openSync('/dev/full', 'w');
    try {
      for (const command of ['decode', 'info']) {
        const r = satscopeWith({ stdio: ['ignore', full, 'pipe'] }, command, big);
        expect(r.code, command).toBe(1);
        expect(r.err, command).toBe('satscope: cannot write the output: ENOSPC\n');
      }
    } finally {
      closeSync(full);
    }
  });

  it('ends cleanly, with exit code 0 and no message, when the reader stops early (| head)', () => {
    const r = spawnSync(
      'sh',
      [
        '-c',
        `("${process.execPath}" "${join(dir, 'peak.mjs')}" decode "${big}" 2>"${dir}/err"; echo $? >"${dir}/rc") | head -n 3; cat "${dir}/rc" "${dir}/err"`,
      ],
      { encoding: 'utf8', timeout: CLI_TIMEOUT_MS },
    );
    const out = r.stdout.split('\n');
    expect(out.slice(0, 3).every((l) => l.startsWith('{"t": null, "remote": "internal"'))).toBe(true);
    expect(out[3]).toBe('0');
    // Nothing on stderr but the peak memory line: no stack trace, no "EPIPE".
    expect(out.slice(4).join('\n').trim()).toMatch(/^peak-rss-kb \d+$/);
    const peak = Number(/peak-rss-kb (\d+)/.exec(r.stdout)?.[1]);
    expect(peak).toBeLessThan(160 * 1024);
  });
});
