// Forward kinematics for rigid skeletons with per-joint local rotations.
import type { Motion, Skeleton } from './types';
import { quatMultiply, quatNormalize, quatRotate, type Quat, type Vec3 } from './math';

/**
 * World joint positions (frames × joints × 3) from root positions (frames × 3) and local rotations
 * (frames × joints × 4, quaternions x, y, z, w).
 *
 * "Bone-end" semantics, as in ASF and the Python side: the rotation stored at joint j rotates the
 * segment that ENDS at j.
 *   G_root = q_root,            p_root = rootPosition
 *   G_j    = G_parent(j) · q_j, p_j    = p_parent(j) + G_j · offset_j
 */
export function forwardKinematics(skeleton: Skeleton, rootPositions: Float32Array, rotations: Float32Array): Float32Array {
  const { parents, offsets } = skeleton;
  const joints = parents.length;
  if (offsets.length !== joints * 3) throw new Error(`forwardKinematics: ${offsets.length} offset values for ${joints} joints`);
  const frames = rootPositions.length / 3;
  if (!Number.isInteger(frames)) throw new Error(`forwardKinematics: root positions length ${rootPositions.length} is not a multiple of 3`);
  if (rotations.length !== frames * joints * 4) {
    throw new Error(`forwardKinematics: expected ${frames * joints * 4} rotation values (${frames}×${joints}×4), got ${rotations.length}`);
  }
  for (let j = 0; j < joints; j++) {
    if (parents[j] >= j || (parents[j] < 0 && j !== 0)) throw new Error(`forwardKinematics: joint ${j} has bad parent ${parents[j]}`);
  }

  const out = new Float32Array(frames * joints * 3);
  const globals: Quat[] = new Array(joints);
  const pos: Vec3[] = new Array(joints);
  for (let f = 0; f < frames; f++) {
    for (let j = 0; j < joints; j++) {
      const r = (f * joints + j) * 4;
      const q = quatNormalize([rotations[r], rotations[r + 1], rotations[r + 2], rotations[r + 3]]);
      const p = parents[j];
      if (p < 0) {
        globals[j] = q;
        pos[j] = [rootPositions[f * 3], rootPositions[f * 3 + 1], rootPositions[f * 3 + 2]];
      } else {
        globals[j] = quatMultiply(globals[p], q);
        const o = quatRotate(globals[j], [offsets[j * 3], offsets[j * 3 + 1], offsets[j * 3 + 2]]);
        pos[j] = [pos[p][0] + o[0], pos[p][1] + o[1], pos[p][2] + o[2]];
      }
      out.set(pos[j], (f * joints + j) * 3);
    }
  }
  return out;
}

/** Distance of each joint from its parent at one frame (0 for the root), in metres. */
export function boneLengths(motion: Motion, frame = 0): Float64Array {
  const J = motion.joints.length;
  const lengths = new Float64Array(J);
  const base = frame * J * 3;
  const P = motion.positions;
  for (let j = 0; j < J; j++) {
    const p = motion.parents[j];
    if (p < 0) continue;
    lengths[j] = Math.hypot(P[base + j * 3] - P[base + p * 3], P[base + j * 3 + 1] - P[base + p * 3 + 1], P[base + j * 3 + 2] - P[base + p * 3 + 2]);
  }
  return lengths;
}
