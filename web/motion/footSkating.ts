// Foot skating: mean horizontal speed (m/s) of each toe while its foot is labelled planted, in this
// frame and the previous one. The same measure as training/metrics.py foot_skating, so browser readouts
// and the Python reports compare directly.
import { findLegs, footPoints } from './legs';
import type { Motion } from './types';

const TOES = ['LeftToeBase', 'RightToeBase'];

export interface SkatingSample {
  /** Sum of planted toe speeds (m/s) and how many planted frame pairs they cover. */
  sum: number;
  count: number;
}

/** Planted toe speeds over frames [from, to) of a motion with contacts (frames × 2, left then right). */
export function skatingSample(motion: Motion & { contacts: Uint8Array }, from = 1, to = motion.frames): SkatingSample {
  const J = motion.joints.length;
  const toes = TOES.map((name) => motion.joints.indexOf(name));
  if (toes.some((j) => j < 0)) throw new Error(`foot skating needs joints ${TOES.join(' and ')}`);
  let sum = 0, count = 0;
  for (let f = Math.max(1, from); f < to; f++) {
    for (let side = 0; side < 2; side++) {
      if (!motion.contacts[f * 2 + side] || !motion.contacts[(f - 1) * 2 + side]) continue;
      const a = ((f - 1) * J + toes[side]) * 3, b = (f * J + toes[side]) * 3;
      sum += Math.hypot(motion.positions[b] - motion.positions[a], motion.positions[b + 2] - motion.positions[a + 2]) * motion.fps;
      count++;
    }
  }
  return { sum, count };
}

/** Mean planted toe speed (m/s), NaN when no foot is ever planted. */
export function footSkating(motion: Motion & { contacts: Uint8Array }): number {
  const { sum, count } = skatingSample(motion);
  return count ? sum / count : NaN;
}

/** Height (m) below which a foot point counts as on or near the floor (training/metrics.py NEAR_FLOOR). */
export const NEAR_FLOOR = 0.04;

/**
 * The independent sliding measure, which needs no contact labels: per foot and frame pair, the lowest of its
 * ankle, toe and toe tip (legs.ts footPoints) in the first frame, counted when it is within NEAR_FLOOR of the
 * floor (y = 0) in both frames; its horizontal speed (m/s). The same as training/metrics.py low_foot_speeds.
 */
export function lowFootSample(motion: Motion, from = 1, to = motion.frames): SkatingSample {
  const J = motion.joints.length;
  const feet = findLegs(motion.joints, 'foot sliding').map(footPoints);
  const P = motion.positions;
  let sum = 0, count = 0;
  for (let f = Math.max(1, from); f < to; f++) {
    for (const points of feet) {
      let low = points[0];
      for (const j of points) if (P[((f - 1) * J + j) * 3 + 1] < P[((f - 1) * J + low) * 3 + 1]) low = j;
      const a = ((f - 1) * J + low) * 3, b = (f * J + low) * 3;
      if (!(P[a + 1] < NEAR_FLOOR && P[b + 1] < NEAR_FLOOR)) continue;
      sum += Math.hypot(P[b] - P[a], P[b + 2] - P[a + 2]) * motion.fps;
      count++;
    }
  }
  return { sum, count };
}

/** Mean of lowFootSample (m/s), NaN when no foot comes near the floor. */
export function lowFootSliding(motion: Motion): number {
  const { sum, count } = lowFootSample(motion);
  return count ? sum / count : NaN;
}

/**
 * The foot stats of a returned motion, after and before the foot lock, measured the same way for every model:
 * `skating` (planted-toe speed by the contacts returned with it: the labels) and `sliding` (the lowest foot
 * point's speed while within 4 cm of the floor, no contacts needed: lowFootSliding).
 */
export function footStats(
  info: { fps: number; skeleton: { joints: string[]; parents: number[] } },
  frames: number,
  shown: { positions: Float32Array; contacts: Uint8Array },
  beforeLock: { positions: Float32Array; contacts: Uint8Array },
): { skating: number; skatingBeforeLock: number; sliding: number; slidingBeforeLock: number } {
  const motion = (m: { positions: Float32Array; contacts: Uint8Array }) => ({ fps: info.fps, frames, joints: info.skeleton.joints, parents: info.skeleton.parents, ...m });
  return {
    skating: footSkating(motion(shown)),
    skatingBeforeLock: footSkating(motion(beforeLock)),
    sliding: lowFootSliding(motion(shown)),
    slidingBeforeLock: lowFootSliding(motion(beforeLock)),
  };
}
