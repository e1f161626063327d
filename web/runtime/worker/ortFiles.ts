// onnxruntime-web's runtime files, handed to it explicitly so Vite serves them in dev and emits them in a
// build. Imported by the model workers (ortWorker.ts) and by the page, which starts fetching the wasm
// as a model starts loading (workerClient.ts), before its worker has even started.
// The .mjs stays a file of its own (not bundled into the worker) because the threaded runtime starts its
// helper workers from the .mjs's own URL.
import ortWasmUrl from 'onnxruntime-web/ort-wasm-simd-threaded.wasm?url';
import ortGlueUrl from 'onnxruntime-web/ort-wasm-simd-threaded.mjs?url';

// Vite gives both as absolute URLs (a built chunk's own URL based, or a root path in dev); the base only
// matters for a root path.
const base = (): string => globalThis.location?.href ?? globalThis.document?.baseURI;

/** The wasm's absolute URL: the same string on the page and in a worker, so both name one shared download. */
export function ortWasmHref(): string {
  return new URL(ortWasmUrl, base()).href;
}

/** The runtime's JavaScript glue, absolute. */
export function ortGlueHref(): string {
  return new URL(ortGlueUrl, base()).href;
}
