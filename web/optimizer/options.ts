// Checks of the optimiser requests' options (gait, seed, foot lock, fit tolerance, simulated length), and
// the rule that only a left-out option takes its default (`optional`), shared by the page API (web/api) and
// the generator worker, so both reject a bad value the same way.
import { describeValue } from '../motion/describe';
import { checkPathPoints, GroundPath, relativeToStart, type GroundPoint } from './path';
import type { Gait } from './pathFollower';

export const MAX_SIMULATED_SECONDS = 600;

/** An optional option's value: `fallback` only when it is left out (undefined); null or anything else is checked as given. */
export function optional(value: unknown, fallback: unknown): unknown {
  return value === undefined ? fallback : value;
}

export function checkGait(gait: unknown): Gait {
  if (gait !== 'walk' && gait !== 'run') throw new TypeError(`gait must be "walk" or "run", got ${describeValue(gait)}`);
  return gait;
}

export function checkSeed(seed: unknown): number {
  if (typeof seed !== 'number' || !Number.isInteger(seed) || seed < 0 || seed > 0xffffffff) throw new RangeError(`seed must be an integer from 0 to 4294967295, got ${describeValue(seed)}`);
  return seed;
}

export function checkFootLock(value: unknown): boolean {
  if (value !== undefined && typeof value !== 'boolean') throw new TypeError(`footLock must be true or false, got ${describeValue(value)}`);
  return value ?? true;
}

export function checkFitSigma(value: unknown, name = 'fitSigma'): number {
  if (typeof value !== 'number' || !(value >= 0.02 && value <= 2)) throw new RangeError(`${name} must be a number from 0.02 to 2 m, got ${describeValue(value)}`);
  return value;
}

export function checkSeconds(seconds: unknown): number {
  if (typeof seconds !== 'number' || !(seconds > 0 && seconds <= MAX_SIMULATED_SECONDS)) throw new RangeError(`seconds must be a number above 0 and at most ${MAX_SIMULATED_SECONDS}, got ${describeValue(seconds)}`);
  return seconds;
}

/**
 * What every path follower's worker checks alike (each checks its own option beside it): the points, gait,
 * seed and foot lock; and the ground path it follows near the origin (smoothed when `stroke`: hand-drawn),
 * to be moved back to `origin`, where the path starts.
 */
export function checkFollowRequest(p: { points: unknown; gait: unknown; seed: unknown; footLock?: unknown; stroke?: boolean }): {
  gait: Gait;
  seed: number;
  lock: boolean;
  origin: GroundPoint;
  ground: GroundPath;
} {
  const points = checkPathPoints(p.points);
  const gait = checkGait(p.gait);
  const seed = checkSeed(p.seed);
  const lock = checkFootLock(p.footLock);
  const { origin, local } = relativeToStart(points);
  return { gait, seed, lock, origin, ground: p.stroke ? GroundPath.fromStroke(local) : GroundPath.fromPoints(local) };
}
