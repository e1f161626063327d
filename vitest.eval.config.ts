// Model evaluations that write reports (npm run evaluate:cleanup): run by vitest for its TypeScript, but not tests.
import { fileURLToPath } from 'node:url';
import { defineConfig } from 'vitest/config';

export default defineConfig({
  root: fileURLToPath(new URL('.', import.meta.url)),
  test: { include: ['tests/eval/**/*.eval.ts'], testTimeout: 3_600_000 },
});
