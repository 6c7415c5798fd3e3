/**
 * A short run of the decoder fuzzer (tests/fuzz-run.ts); tests/slow/ runs 200,000 more, `npm run
 * fuzz` a million.
 */
import { describe, it } from 'vitest';
import { fuzz } from './fuzz-run.js';

describe('fuzzing the built decoder', () => {
  it('survives 10,000 random and damaged inputs under every option: no throw, no hang, same frames however chunked', async () => {
    await fuzz(10_000, 0);
  }, 120_000);
});
