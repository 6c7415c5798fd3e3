import { defineConfig } from 'vitest/config';

export default defineConfig({
  test: {
    include: ['tests/**/*.test.ts'],
    // The slow tier runs apart: npm run test:slow (vitest.slow.config.ts).
    exclude: ['tests/slow/**', '**/node_modules/**'],
    // The package and browser tests pack, install and launch things: give them room.
    testTimeout: 60_000,
    // Vitest runs one file at a time where the machine has two cores (its default is one fewer
    // than the cores); the browser tests mostly wait on the page, so two at once take 6 min
    // where one takes 8 (bench/README.md has no row for it: the figure is the suite's wall time).
    maxWorkers: 2,
    // The Drive browser tests (tests/e2e/drive*) time a writer against a clock: `npm test` runs
    // them after the rest, with nothing beside them (package.json), so they measure the page, not
    // the neighbouring test file's load.
    hookTimeout: 120_000,
  },
});
