import { defineConfig } from 'vitest/config';

// The page benchmark: not part of `npm test` (it runs for minutes and measures, never asserts).
export default defineConfig({
  test: { include: ['bench/**/*.bench.ts'], testTimeout: 120 * 60_000, hookTimeout: 120_000 },
});
