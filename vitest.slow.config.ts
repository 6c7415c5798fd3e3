import { defineConfig } from 'vitest/config';

/** The slow tier (`npm run test:slow`, which `.ci/run` runs after the README's test command): the long fuzz. */
export default defineConfig({
  test: {
    include: ['tests/slow/**/*.test.ts'],
    testTimeout: 600_000,
  },
});
