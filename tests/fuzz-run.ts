/**
 * Runs the decoder fuzzer (scripts/fuzz.mjs) on the built decoder for `count` inputs from
 * `from`: random and damaged streams under every option and timing never make it throw or
 * hang, every byte is accounted for, and chunking never changes the frames.
 */
import { execFile } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { promisify } from 'node:util';
import { expect } from 'vitest';

const run = promisify(execFile);
const script = fileURLToPath(new URL('../scripts/fuzz.mjs', import.meta.url));

export async function fuzz(count: number, from: number): Promise<void> {
  const { stdout } = await run(process.execPath, [script, '--count', String(count), '--from', String(from)]);
  expect(stdout).toMatch(new RegExp(`^${count} inputs from ${from}, every option and timing: 0 throws, 0 hangs`));
}
