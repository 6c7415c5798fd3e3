import { defineConfig } from 'vitest/config';

export default defineConfig({
  test: {
    include: ['tests/**/*.test.ts'],
    // The package and browser tests pack, install and launch things: give them room.
    testTimeout: 60_000,
    hookTimeout: 120_000,
  },
});
