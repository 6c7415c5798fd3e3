/**
 * The slow tier's run of the decoder fuzzer (tests/fuzz-run.ts): the 200,000 inputs after the
 * main tier's 10,000 (`npm run fuzz` runs a million).
 */
import { describe, it } from 'vitest';
import { fuzz } from '../fuzz-run.js';

describe('fuzzing the built decoder', () => {
  it('survives 200,000 more random and damaged inputs under every option: no throw, no hang, same frames however chunked', async () => {
    await fuzz(200_000, 10_000);
  }, 600_000);
});
