/**
 * The slow tier's run of the decoder fuzzer (scripts/fuzz.mjs), the 200,000 inputs after the
 * main tier's 10,000 (`npm run fuzz` runs a million):
 * random and damaged streams under every option and timing never make the built decoder throw
 * or hang, every byte is accounted for, and chunking never changes the frames.
 */
import { execFile } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { promisify } from 'node:util';
import { describe, expect, it } from 'vitest';

const run = promisify(execFile);
const script = fileURLToPath(new URL('../../scripts/fuzz.mjs', import.meta.url));

describe('fuzzing the built decoder', () => {
  it('survives 200,000 more random and damaged inputs under every option: no throw, no hang, same frames however chunked', async () => {
    const { stdout } = await run(process.execPath, [script, '--count', '200000', '--from', '10000']);
    expect(stdout).toMatch(/^200000 inputs from 10000, every option and timing: 0 throws, 0 hangs/);
  }, 600_000);
});
