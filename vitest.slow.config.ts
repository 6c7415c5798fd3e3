import { defineConfig } from 'vitest/config';

/**
 * The slow tier (`npm run test:slow`, which `.ci/run` runs after the README's test command): the
 * long fuzz, and the page in every size and theme (screenshots to look at, axe-core in light).
 */
export default defineConfig({
  test: {
    include: ['tests/slow/**/*.test.ts'],
    testTimeout: 600_000,
    // Starting the page's server and Chromium on a busy machine.
    hookTimeout: 120_000,
    maxWorkers: 2,
  },
});
