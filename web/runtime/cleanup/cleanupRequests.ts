// The `denoise` request (motion clean-up, cleanup.ts) in the model workers: `map` and `lowpass` in the generator's
// worker (the MAP filter runs on its session), `manifold` in the latent ERD's (it holds the autoencoder). Both check
// the motion and options again (the page checks them first) and report progress.
import type { GeneratorInfo } from '../../model/generatorInfo';
import { validateMotion } from '../../motion/validate';
import type { Motion } from '../../motion/types';
import { checkCleanupMotion, checkCleanupOptions, cleanUpOnCanonical, lowpassCleanup, type CanonicalCleaned, type CanonicalInput, type CleanupOptions, type CleanupResult } from './cleanup';

export interface DenoiseParams {
  motion: Motion;
  options: CleanupOptions;
}

/** What a worker can clean with: its canonical cleaner for the methods it serves, and the generator's info for the IK. */
export interface DenoiseBackend {
  methods: readonly CleanupOptions['method'][];
  info: () => Promise<GeneratorInfo>;
  cleaner: (options: CleanupOptions, progress: (fraction: number) => void) => (input: CanonicalInput) => Promise<CanonicalCleaned>;
}

export async function serveDenoise(p: DenoiseParams, backend: DenoiseBackend, progress: (fraction: number) => void, signal?: AbortSignal): Promise<CleanupResult> {
  const motion = validateMotion(p.motion);
  const options = checkCleanupOptions(p.options);
  checkCleanupMotion(motion);
  if (!backend.methods.includes(options.method)) throw new Error(`method ${options.method} is not served by this worker`);
  if (options.method === 'lowpass') {
    progress(1);
    return lowpassCleanup(motion, options);
  }
  const result = await cleanUpOnCanonical(await backend.info(), motion, options.method, backend.cleaner(options, progress), signal);
  progress(1);
  return result;
}
