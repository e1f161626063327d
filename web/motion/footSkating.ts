// Foot skating: mean horizontal speed (m/s) of each toe while its foot is labelled planted, in this
// frame and the previous one. The same measure as training/metrics.py foot_skating, so browser readouts
// and the Python reports compare directly.
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
