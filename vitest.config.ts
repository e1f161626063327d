// Unit tests (tests/unit) run from the repo root; vite.config.ts roots the app at web/, so vitest
// needs its own config (vitest prefers this file over vite.config.ts).
import { fileURLToPath } from 'node:url';
import { defineConfig } from 'vitest/config';

export default defineConfig({
  root: fileURLToPath(new URL('.', import.meta.url)),
  test: {
    include: ['tests/unit/**/*.test.ts'],
    testTimeout: 20000,
  },
});
