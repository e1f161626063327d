// Joint rotations solved from world positions against a rest pose, for the exporters that write rotations
// (BVH: bvh.ts, glTF: gltf.ts). Both write the same node tree: one node per joint whose rest offset from the
// node above is `rest[j]` (restPose.ts), and, for a joint with several children, a zero-offset helper node
// per child between the joint and that child, so every child bone gets a rotation of its own and positions
// are reproduced exactly whatever the angles between a joint's children (rigid bones: exactly, up to float
// rounding).
//
// A joint's global rotation aims its child bone: one child, the minimal swing from the rotation of the node
// above (so local rotations stay small and twist-free); several children, the rotation that takes the rest
// pair of children whose bones are least parallel onto that pair now (the node above's rotation when no pair
// is far enough from parallel), and each helper the minimal swing from it onto its child's bone.
import { quatIdentity, quatMultiply, quatRotate, rotationFromTwoVectors, swingRotation, cross, length, normalize, type Quat, type Vec3 } from './math';
import type { Motion } from './types';

/** A validated Motion as the exporters read it, with each joint's children in index order. */
export interface RigClip {
  frames: number;
  joints: string[];
  parents: number[];
  positions: Float32Array;
  children: number[][];
}

export function rigClip(m: Motion): RigClip {
  const children: number[][] = m.joints.map(() => []);
  for (let j = 1; j < m.joints.length; j++) children[m.parents[j]].push(j);
  return { frames: m.frames, joints: m.joints, parents: m.parents, positions: m.positions, children };
}

export function jointAt(clip: RigClip, f: number, j: number): Vec3 {
  const P = clip.positions;
  const b = (f * clip.joints.length + j) * 3;
  return [P[b], P[b + 1], P[b + 2]];
}

/** Joint j's position minus its parent's in frame f. */
export function boneVector(clip: RigClip, f: number, j: number): Vec3 {
  const a = jointAt(clip, f, clip.parents[j]);
  const b = jointAt(clip, f, j);
  return [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
}

/**
 * For joints with several children, the pair of children whose rest bones are least parallel
 * defines the joint's own rotation; undefined where no pair is far enough from parallel.
 */
export function rotationPairs(clip: RigClip, rest: Vec3[]): Array<[number, number] | undefined> {
  return clip.children.map((kids) => {
    let best: [number, number] | undefined;
    let bestSin = 1e-3;
    for (let a = 0; a < kids.length; a++) {
      for (let b = a + 1; b < kids.length; b++) {
        const s = length(cross(normalize(rest[kids[a]]), normalize(rest[kids[b]])));
        if (s > bestSin) {
          bestSin = s;
          best = [kids[a], kids[b]];
        }
      }
    }
    return best;
  });
}

/** Global rotation of the node directly above joint j: identity for the root, j's helper node, or j's parent. */
export function parentNodeGlobal(clip: RigClip, j: number, jointGlobal: Quat[], helperGlobal: Quat[]): Quat {
  const p = clip.parents[j];
  return p < 0 ? quatIdentity() : clip.children[p].length > 1 ? helperGlobal[j] : jointGlobal[p];
}

/**
 * Frame f's global rotations, parents first: jointGlobal per joint, helperGlobal per child of a joint with
 * several children (indexed by the child).
 */
export function solveGlobalRotations(
  clip: RigClip, rest: Vec3[], framePair: Array<[number, number] | undefined>, f: number, jointGlobal: Quat[], helperGlobal: Quat[],
): void {
  for (let j = 0; j < clip.joints.length; j++) {
    const base = parentNodeGlobal(clip, j, jointGlobal, helperGlobal);
    const kids = clip.children[j];
    const current = kids.map((c) => boneVector(clip, f, c));
    let g = base;
    if (kids.length === 1) {
      g = quatMultiply(swingRotation(quatRotate(base, rest[kids[0]]), current[0]), base);
    } else if (kids.length > 1) {
      const pair = framePair[j];
      if (pair) {
        const [a, b] = pair;
        g = rotationFromTwoVectors(rest[a], rest[b], boneVector(clip, f, a), boneVector(clip, f, b)) ?? base;
      }
      kids.forEach((c, k) => {
        helperGlobal[c] = quatMultiply(swingRotation(quatRotate(g, rest[c]), current[k]), g);
      });
    }
    jointGlobal[j] = g;
  }
}
