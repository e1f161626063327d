// Synthetic capture noise, for trying clean-up (lowpass.ts, footLock.ts) on a clean clip: Gaussian jitter,
// outlier poses (marker swaps, glitches) and feet that slide while planted (inertial-suit drift). Seeded,
// so the same options always give the same noise.
import { footJointsOf } from './contacts';
import { Rng } from './random';
import { quoteInput } from './text';
import type { Motion } from './types';

export interface NoiseOptions {
  /** σ in metres of Gaussian jitter on every joint position, every frame; default 0. */
  jitter?: number;
  /** Share 0..0.5 of frames that become outlier poses; default 0. */
  outliers?: number;
  /** Speed in m/s at which the feet slide horizontally; default 0. */
  drift?: number;
  /** Seed of the random streams, an integer 0..2³²−1; default 0. */
  seed?: number;
}

/** Outlier joints move at least this far (plus 3 × jitter, so they stand clear of the jitter). */
export const OUTLIER_DISTANCE = 0.15;
/** Drift builds up over this many seconds, then resets, as a suit's re-anchoring would. */
export const DRIFT_PERIOD = 2;
/** The reset fades the old offset out over this long instead of snapping the feet back. */
export const DRIFT_RAMP = 0.25;
/** Most a drift direction turns, rad/s: slow, so a slide is a near-straight line. */
const DRIFT_TURN = 0.5;

/** Each option's upper bound and what its message calls it. */
const LIMITS: Record<keyof NoiseOptions, { max: number; what: string }> = {
  jitter: { max: 0.5, what: 'a number of metres from 0 to 0.5' },
  outliers: { max: 0.5, what: 'a share of frames from 0 to 0.5' },
  drift: { max: 5, what: 'a speed in m/s from 0 to 5' },
  seed: { max: 2 ** 32 - 1, what: 'a whole number from 0 to 4294967295' },
};

/** A value as an error message shows it: strings quoted and cut short, anything else as written. */
function shown(value: unknown): string {
  if (typeof value === 'string') return quoteInput(value);
  if (typeof value === 'number' || typeof value === 'bigint' || value === undefined) return String(value);
  try {
    return quoteInput(JSON.stringify(value) ?? String(value)).slice(1, -1);
  } catch {
    return String(value);
  }
}

/** The options with defaults filled in, or an Error naming the first bad option and its value. */
export function checkNoiseOptions(options: unknown): Required<NoiseOptions> {
  if (typeof options !== 'object' || options === null || Array.isArray(options)) {
    throw new Error(`noise: options must be an object, got ${shown(options)}`);
  }
  const result: Required<NoiseOptions> = { jitter: 0, outliers: 0, drift: 0, seed: 0 };
  for (const [key, value] of Object.entries(options)) {
    if (!(key in LIMITS)) throw new Error(`noise: unknown option ${quoteInput(key)} (expected jitter, outliers, drift or seed)`);
    if (value === undefined) continue; // an explicit undefined means the default, as in most TS APIs
    const { max, what } = LIMITS[key as keyof NoiseOptions];
    const ok = typeof value === 'number' && Number.isFinite(value) && value >= 0 && value <= max && (key !== 'seed' || Number.isInteger(value));
    if (!ok) throw new Error(`noise: ${key} must be ${what}, got ${shown(value)}`);
    result[key as keyof NoiseOptions] = value as number;
  }
  return result;
}


/** One stream per kind of noise, so that e.g. turning jitter on does not move which frames are outliers. */
const stream = (seed: number, kind: number) => new Rng((seed ^ Math.imul(kind, 0x9e3779b9)) >>> 0);

/** The ankle and every joint below it, per side; parents come before children, so one pass finds them. */
function footChains(motion: Motion): number[][] {
  const both = footJointsOf(motion);
  if (!both) throw new Error('noise: drift needs the feet, but this skeleton is not a humanoid whose feet can be found');
  return both.map((feet) => {
    const inChain = motion.parents.map(() => false);
    const chain: number[] = [];
    motion.parents.forEach((p, j) => {
      inChain[j] = j === feet.ankle || (p >= 0 && inChain[p]);
      if (inChain[j]) chain.push(j);
    });
    return chain;
  });
}

/**
 * Horizontal (x, z) drift offset per frame for one foot, frames × 2. In each DRIFT_PERIOD the foot moves
 * at `speed` along a direction that turns at a constant slow rate (both drawn anew each period); at the
 * reset, the previous period's offset fades out over DRIFT_RAMP with a smoothstep, so the largest offset
 * is about speed × DRIFT_PERIOD.
 */
function driftOffsets(frames: number, fps: number, speed: number, rng: Rng): Float64Array {
  const periods = Math.ceil(frames / fps / DRIFT_PERIOD) + 1;
  const heading: number[] = [], turn: number[] = [];
  for (let k = 0; k < periods; k++) {
    heading.push(2 * Math.PI * rng.uniform());
    turn.push(DRIFT_TURN * (2 * rng.uniform() - 1));
  }
  // Closed-form ∫₀^τ speed·(cos, sin)(θ + ωs) ds, so the path does not depend on the frame rate.
  const along = (k: number, tau: number): [number, number] => {
    const th = heading[k], w = turn[k];
    if (Math.abs(w) < 1e-9) return [speed * tau * Math.cos(th), speed * tau * Math.sin(th)];
    return [(speed * (Math.sin(th + w * tau) - Math.sin(th))) / w, (speed * (Math.cos(th) - Math.cos(th + w * tau))) / w];
  };
  const out = new Float64Array(frames * 2);
  for (let f = 0; f < frames; f++) {
    const t = f / fps;
    const k = Math.floor(t / DRIFT_PERIOD);
    const tau = t - k * DRIFT_PERIOD;
    let [x, z] = along(k, tau);
    if (k > 0 && tau < DRIFT_RAMP) {
      const u = tau / DRIFT_RAMP;
      const keep = 1 - u * u * (3 - 2 * u);
      const [px, pz] = along(k - 1, DRIFT_PERIOD);
      x += keep * px;
      z += keep * pz;
    }
    out[f * 2] = x;
    out[f * 2 + 1] = z;
  }
  return out;
}

/**
 * A noisy copy of `motion` and the frames made outliers (ascending). The input is untouched; the copy has
 * no contacts, since noisy capture comes unlabelled.
 * - jitter: N(0, jitter²) added to each coordinate of each joint, every frame but the outlier frames;
 * - outliers: round(share × frames) distinct frames where every joint moves OUTLIER_DISTANCE + 3 × jitter
 *   in its own random direction. The glitch replaces that frame's jitter, so each joint there is exactly
 *   that far from the clean pose (before drift);
 * - drift: each foot chain (ankle and below) slides horizontally at `drift` m/s, resetting every
 *   DRIFT_PERIOD s; throws if the feet cannot be found by name.
 * Options are checked by checkNoiseOptions.
 */
export function addNoise(motion: Motion, options: NoiseOptions): { motion: Motion; outlierFrames: number[] } {
  const { jitter, outliers, drift, seed } = checkNoiseOptions(options);
  const { frames: F, fps } = motion;
  const J = motion.joints.length;
  const positions = motion.positions.slice();

  // Outlier frames: a partial Fisher–Yates shuffle draws distinct frames.
  const pick = stream(seed, 1);
  const order = Array.from({ length: F }, (_, f) => f);
  const count = Math.min(F, Math.round(outliers * F));
  for (let i = 0; i < count; i++) {
    const j = i + Math.floor(pick.uniform() * (F - i));
    [order[i], order[j]] = [order[j], order[i]];
  }
  const outlierFrames = order.slice(0, count).sort((a, b) => a - b);
  const isOutlier = new Uint8Array(F);
  for (const f of outlierFrames) isOutlier[f] = 1;

  const noise = stream(seed, 2);
  const reach = OUTLIER_DISTANCE + 3 * jitter;
  for (let f = 0; f < F; f++) {
    for (let j = 0; j < J; j++) {
      const i = (f * J + j) * 3;
      if (isOutlier[f]) {
        // A uniform direction on the sphere: a normalised 3D standard normal.
        let dx = 0, dy = 0, dz = 0, n = 0;
        while (n < 1e-9) {
          dx = pick.normal(); dy = pick.normal(); dz = pick.normal();
          n = Math.hypot(dx, dy, dz);
        }
        positions[i] += (reach * dx) / n;
        positions[i + 1] += (reach * dy) / n;
        positions[i + 2] += (reach * dz) / n;
      } else if (jitter > 0) {
        positions[i] += jitter * noise.normal();
        positions[i + 1] += jitter * noise.normal();
        positions[i + 2] += jitter * noise.normal();
      }
    }
  }

  if (drift > 0) {
    const slide = stream(seed, 3);
    for (const chain of footChains(motion)) {
      const offsets = driftOffsets(F, fps, drift, slide);
      for (let f = 0; f < F; f++) {
        for (const j of chain) {
          positions[(f * J + j) * 3] += offsets[f * 2];
          positions[(f * J + j) * 3 + 2] += offsets[f * 2 + 1];
        }
      }
    }
  }

  return { motion: { fps, frames: F, joints: [...motion.joints], parents: [...motion.parents], positions }, outlierFrames };
}
