// Toe swing per second: how much the feet swing relative to the body, the measure of "running that lasts" (issue 39).
// A running gait swings each toe forward and back past the hips at several metres per second; a gait that decays
// into a glide or a shuffle keeps moving the root while the toes ride along with it. Per frame transition t → t+1,
//   swing(t) = mean over the two toes of |horizontal (x, z) velocity of (toe − root)|, m/s,
// and second k is the mean of swing(k·n … k·n + n − 1), n = round(fps); a partial second is not reported. The toes
// are found by name or by the humanoid mapper (contacts.ts footJointsOf), so any humanoid skeleton is measured alike,
// generated motion and imported capture the same way.

import { footJointsOf } from './contacts';
import type { Motion } from './types';

/** Toe swing per whole second (m/s) of `motion`; throws when its feet cannot be found. */
export function toeSwingPerSecond(motion: Pick<Motion, 'joints' | 'parents' | 'frames' | 'positions' | 'fps'>): number[] {
  const feet = footJointsOf(motion);
  if (!feet) throw new Error('toeSwingPerSecond: the motion has no two feet to measure');
  const { frames, positions, fps } = motion;
  const J = motion.joints.length;
  const at = (f: number, j: number, axis: number) => positions[(f * J + j) * 3 + axis];
  const n = Math.max(1, Math.round(fps));
  const seconds: number[] = [];
  let sum = 0;
  let count = 0;
  for (let f = 0; f + 1 < frames; f++) {
    let swing = 0;
    for (const { toe } of feet) {
      const dx = at(f + 1, toe, 0) - at(f + 1, 0, 0) - (at(f, toe, 0) - at(f, 0, 0));
      const dz = at(f + 1, toe, 2) - at(f + 1, 0, 2) - (at(f, toe, 2) - at(f, 0, 2));
      swing += Math.hypot(dx, dz) * fps;
    }
    sum += swing / feet.length;
    if (++count === n) {
      seconds.push(sum / n);
      sum = 0;
      count = 0;
    }
  }
  return seconds;
}
