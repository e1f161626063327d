// Checks of the optimiser requests' options (gait, seed, foot lock, fit tolerance, simulated length),
// shared by the page API (web/api) and the generator worker, so both reject a bad value the same way.
import type { Gait } from './pathFollower';

export const MAX_SIMULATED_SECONDS = 600;

export function checkGait(gait: unknown): Gait {
  if (gait !== 'walk' && gait !== 'run') throw new TypeError(`gait must be "walk" or "run", got ${JSON.stringify(gait)}`);
  return gait;
}

export function checkSeed(seed: unknown): number {
  if (typeof seed !== 'number' || !Number.isInteger(seed) || seed < 0 || seed > 0xffffffff) throw new RangeError(`seed must be an integer from 0 to 4294967295, got ${String(seed)}`);
  return seed;
}

export function checkFootLock(value: unknown): boolean {
  if (value !== undefined && typeof value !== 'boolean') throw new TypeError(`footLock must be true or false, got ${String(value)}`);
  return value ?? true;
}

export function checkFitSigma(value: unknown, name = 'fitSigma'): number {
  if (typeof value !== 'number' || !(value >= 0.02 && value <= 2)) throw new RangeError(`${name} must be a number from 0.02 to 2 m, got ${String(value)}`);
  return value;
}

export function checkSeconds(seconds: unknown): number {
  if (typeof seconds !== 'number' || !(seconds > 0 && seconds <= MAX_SIMULATED_SECONDS)) throw new RangeError(`seconds must be a number above 0 and at most ${MAX_SIMULATED_SECONDS}, got ${String(seconds)}`);
  return seconds;
}
