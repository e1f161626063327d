// Test helpers for the model cores run on the shipped ONNX files with onnxruntime-web's Node build
// (the same wasm runtime the browser workers use).
import { readFileSync } from 'node:fs';
import * as ort from 'onnxruntime-web';
import { REPO_ROOT } from './corpus';

export { ort };

/** A single-threaded session on public/models/<file>. */
export function shippedSession(file: string): Promise<ort.InferenceSession> {
  ort.env.wasm.numThreads = 1;
  return ort.InferenceSession.create(readFileSync(`${REPO_ROOT}public/models/${file}`));
}

export function maxAbsDiff(a: ArrayLike<number>, b: ArrayLike<number>): number {
  if (a.length !== b.length) return Infinity;
  let worst = 0;
  for (let i = 0; i < a.length; i++) worst = Math.max(worst, Math.abs(a[i] - b[i]));
  return worst;
}

/** The bytes of a typed array, for bit-exact comparisons. */
export const bytes = (a: Float32Array | Uint8Array): number[] => Array.from(new Uint8Array(a.buffer, a.byteOffset, a.byteLength));
