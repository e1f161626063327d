import { readdirSync, readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { defineConfig, type Plugin } from 'vite';

const here = fileURLToPath(new URL('.', import.meta.url));
const pkg = JSON.parse(readFileSync(new URL('./package.json', import.meta.url), 'utf8')) as { version: string };

// Cross-origin isolation (SharedArrayBuffer → onnxruntime-web threads). The page also works without it:
// code must check `crossOriginIsolated` before relying on threads.
const isolationHeaders = {
  'Cross-Origin-Opener-Policy': 'same-origin',
  'Cross-Origin-Embedder-Policy': 'require-corp',
};

/** examples/*.html go into the build as they are: they load ../motion-playground.js like any other site would. */
function examples(): Plugin {
  return {
    name: 'motion-playground-examples',
    apply: 'build',
    generateBundle() {
      for (const name of readdirSync(`${here}examples`).filter((f) => f.endsWith('.html'))) {
        this.emitFile({ type: 'asset', fileName: `examples/${name}`, source: readFileSync(`${here}examples/${name}`, 'utf8') });
      }
    },
  };
}

export default defineConfig({
  plugins: [examples()],
  root: `${here}web`,
  publicDir: `${here}public`,
  base: './',
  define: {
    __APP_VERSION__: JSON.stringify(pkg.version),
  },
  server: {
    headers: isolationHeaders,
    fs: { allow: [here] },
  },
  preview: {
    headers: isolationHeaders,
  },
  worker: {
    format: 'es',
  },
  optimizeDeps: {
    // onnxruntime-web ships its own wasm/worker files and resolves them relative to its module URL;
    // pre-bundling breaks those paths.
    exclude: ['onnxruntime-web'],
  },
  build: {
    outDir: `${here}dist`,
    emptyOutDir: true,
    target: 'es2022',
    sourcemap: true,
    chunkSizeWarningLimit: 2048, // three.js alone is ~600 kB minified
    rollupOptions: {
      // The page, and the <motion-playground> element as one ES module at the top of the folder (the page
      // imports it too), with its workers, wasm and models beside it under relative URLs.
      input: { index: `${here}web/index.html`, 'motion-playground': `${here}web/motion-playground.ts` },
      preserveEntrySignatures: 'exports-only',
      output: {
        entryFileNames: (chunk) => (chunk.name === 'motion-playground' ? 'motion-playground.js' : 'assets/[name]-[hash].js'),
      },
    },
  },
});
