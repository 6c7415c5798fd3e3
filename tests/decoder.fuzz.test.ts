/**
 * A short run of the decoder fuzzer (scripts/fuzz.mjs; `npm run fuzz` runs a million inputs):
 * random and damaged streams under every option and timing never make the built decoder throw
 * or hang, every byte is accounted for, and chunking never changes the frames.
 */
import { execFile } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { promisify } from 'node:util';
import { describe, expect, it } from 'vitest';

const run = promisify(execFile);
const script = fileURLToPath(new URL('../scripts/fuzz.mjs', import.meta.url));

describe('fuzzing the built decoder', () => {
  it('survives 40,000 random and damaged inputs under every option: no throw, no hang, same frames however chunked', async () => {
    const { stdout } = await run(process.execPath, [script, '--count', '40000', '--from', '0']);
    expect(stdout).toMatch(/^40000 inputs from 0, every option and timing: 0 throws, 0 hangs/);
  }, 120_000);
});
