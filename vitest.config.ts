import { defineConfig } from 'vitest/config';

export default defineConfig({
  test: {
    include: ['tests/**/*.test.ts'],
    // The slow tier runs apart: npm run test:slow (vitest.slow.config.ts).
    exclude: ['tests/slow/**', '**/node_modules/**'],
    // The package and browser tests pack, install and launch things: give them room.
    testTimeout: 60_000,
    hookTimeout: 120_000,
  },
});
