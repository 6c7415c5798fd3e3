/**
 * A short run of the decoder fuzzer (scripts/fuzz.mjs; tests/slow/ runs 200,000 more, `npm run
 * fuzz` a million):
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
  it('survives 10,000 random and damaged inputs under every option: no throw, no hang, same frames however chunked', async () => {
    const { stdout } = await run(process.execPath, [script, '--count', '10000', '--from', '0']);
    expect(stdout).toMatch(/^10000 inputs from 0, every option and timing: 0 throws, 0 hangs/);
  }, 120_000);
});
