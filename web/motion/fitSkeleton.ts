// Fits raw predicted points (e.g. a network's output, whose bone lengths drift) to a rigid skeleton:
// the result keeps the skeleton's exact bone lengths and stays close to the prediction, and comes with
// the local joint rotations that produce it.
//
// Conventions (BVH-style, parents before children):
//   G_root = q_root,           p_root = predicted root
//   G_j    = G_parent(j) · q_j, p_j   = p_parent(j) + G_parent(j) · offset_j
// i.e. a joint's rotation turns the offsets of its children. Per frame, in parent order, each joint
// is placed by its parent's rotation and the true offset (forward kinematics), and its own world
// rotation is the one that best maps its children's rest offsets onto the directions from its fitted
// position to their predicted positions:
//   - one child: the minimal rotation (a swing from the parent's frame, no twist);
//   - several children spanning a plane (hips, chest, hands, head): the least-squares rotation over
//     all of them (Kabsch, solved as Horn's quaternion eigenproblem);
//   - no children: the parent's rotation (local identity).
// Aiming at the predicted points from the *fitted* parent keeps errors from piling up along chains.
import { quatConjugate, quatIdentity, quatMultiply, quatRotate, swingRotation, cross, length, normalize, type Quat, type Vec3 } from './math';
import type { Skeleton } from './types';

export interface SkeletonFit {
  /** frames × joints × 3, world metres, at the skeleton's exact bone lengths. */
  positions: Float32Array;
  /** frames × joints × 4 local rotations (x, y, z, w; w ≥ 0) in the convention above; [0] is the root's world rotation. */
  rotations: Float32Array;
}

/** Largest-eigenvalue eigenvector of a symmetric 4×4 matrix (row-major), by cyclic Jacobi rotations. */
function dominantEigenvector(m: number[]): [number, number, number, number] {
  const a = m.slice();
  const v = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
  let scale = 0;
  for (const x of a) scale = Math.max(scale, Math.abs(x));
  for (let sweep = 0; sweep < 32; sweep++) {
    let off = 0;
    for (let p = 0; p < 3; p++) for (let q = p + 1; q < 4; q++) off = Math.max(off, Math.abs(a[p * 4 + q]));
    if (off <= 1e-15 * scale) break;
    for (let p = 0; p < 3; p++) {
      for (let q = p + 1; q < 4; q++) {
        const apq = a[p * 4 + q];
        if (apq === 0) continue;
        const theta = (a[q * 4 + q] - a[p * 4 + p]) / (2 * apq);
        const t = (theta >= 0 ? 1 : -1) / (Math.abs(theta) + Math.sqrt(theta * theta + 1));
        const c = 1 / Math.sqrt(t * t + 1);
        const s = t * c;
        for (let k = 0; k < 4; k++) {
          const akp = a[k * 4 + p], akq = a[k * 4 + q];
          a[k * 4 + p] = c * akp - s * akq;
          a[k * 4 + q] = s * akp + c * akq;
        }
        for (let k = 0; k < 4; k++) {
          const apk = a[p * 4 + k], aqk = a[q * 4 + k];
          a[p * 4 + k] = c * apk - s * aqk;
          a[q * 4 + k] = s * apk + c * aqk;
        }
        for (let k = 0; k < 4; k++) {
          const vkp = v[k * 4 + p], vkq = v[k * 4 + q];
          v[k * 4 + p] = c * vkp - s * vkq;
          v[k * 4 + q] = s * vkp + c * vkq;
        }
      }
    }
  }
  let best = 0;
  for (let k = 1; k < 4; k++) if (a[k * 5] > a[best * 5]) best = k;
  return [v[best], v[4 + best], v[8 + best], v[12 + best]];
}

/**
 * The rotation R maximising Σ to_i · R from_i (Kabsch's least-squares rotation; Horn's closed form).
 * Undefined when the vectors carry no orientation (all zero).
 */
export function bestRotation(from: Vec3[], to: Vec3[]): Quat | undefined {
  let sxx = 0, sxy = 0, sxz = 0, syx = 0, syy = 0, syz = 0, szx = 0, szy = 0, szz = 0;
  for (let i = 0; i < from.length; i++) {
    const a = from[i], b = to[i];
    sxx += a[0] * b[0]; sxy += a[0] * b[1]; sxz += a[0] * b[2];
    syx += a[1] * b[0]; syy += a[1] * b[1]; syz += a[1] * b[2];
    szx += a[2] * b[0]; szy += a[2] * b[1]; szz += a[2] * b[2];
  }
  const n = [
    sxx + syy + szz, syz - szy, szx - sxz, sxy - syx,
    syz - szy, sxx - syy - szz, sxy + syx, szx + sxz,
    szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy,
    sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz,
  ];
  if (n.every((x) => Math.abs(x) < 1e-300)) return undefined;
  const [w, x, y, z] = dominantEigenvector(n);
  const norm = Math.hypot(w, x, y, z);
  return w >= 0 ? [x / norm, y / norm, z / norm, w / norm] : [-x / norm, -y / norm, -z / norm, -w / norm];
}

export class SkeletonFitter {
  private readonly parents: number[];
  private readonly offsets: Vec3[];
  private readonly children: number[][];
  /** Joints whose children's rest offsets span a plane: their rotation is fully determined by them. */
  private readonly planar: boolean[];

  constructor(skeleton: Skeleton) {
    const J = skeleton.parents.length;
    if (skeleton.offsets.length !== J * 3) throw new Error(`fitSkeleton: ${skeleton.offsets.length} offset values for ${J} joints`);
    skeleton.parents.forEach((p, j) => {
      if (j === 0 ? p !== -1 : !Number.isInteger(p) || p < 0 || p >= j) throw new Error(`fitSkeleton: joint ${j} has bad parent ${p} (the root must be first, parents before children)`);
    });
    this.parents = skeleton.parents;
    this.offsets = skeleton.parents.map((_, j) => [skeleton.offsets[j * 3], skeleton.offsets[j * 3 + 1], skeleton.offsets[j * 3 + 2]] as Vec3);
    this.children = skeleton.parents.map(() => []);
    for (let j = 1; j < J; j++) this.children[skeleton.parents[j]].push(j);
    this.planar = this.children.map((kids) =>
      kids.some((a, i) => kids.slice(i + 1).some((b) => length(cross(normalize(this.offsets[a]), normalize(this.offsets[b]))) > 1e-3)),
    );
  }

  /** Fits every frame of `points` (frames × joints × 3). */
  fit(points: ArrayLike<number>): SkeletonFit {
    const J = this.parents.length;
    if (points.length % (J * 3) !== 0) throw new Error(`fitSkeleton: ${points.length} values is not a whole number of ${J}-point frames`);
    const frames = points.length / (J * 3);
    const positions = new Float32Array(frames * J * 3);
    const rotations = new Float32Array(frames * J * 4);
    const world: Quat[] = new Array(J);
    const fitted: Vec3[] = new Array(J);
    const rel = (base: number, j: number, from: Vec3): Vec3 => [
      points[base + j * 3] - from[0],
      points[base + j * 3 + 1] - from[1],
      points[base + j * 3 + 2] - from[2],
    ];
    for (let f = 0; f < frames; f++) {
      const base = f * J * 3;
      for (let j = 0; j < J; j++) {
        const p = this.parents[j];
        const parentWorld = p < 0 ? quatIdentity() : world[p];
        if (p < 0) {
          fitted[j] = [points[base], points[base + 1], points[base + 2]];
        } else {
          const o = quatRotate(parentWorld, this.offsets[j]);
          fitted[j] = [fitted[p][0] + o[0], fitted[p][1] + o[1], fitted[p][2] + o[2]];
        }
        const kids = this.children[j];
        let g = parentWorld;
        if (kids.length > 0 && this.planar[j]) {
          g = bestRotation(kids.map((c) => this.offsets[c]), kids.map((c) => rel(base, c, fitted[j]))) ?? parentWorld;
        } else if (kids.length > 0) {
          // One child (or children along one line): swing their rest direction onto the predicted one.
          const from: Vec3 = [0, 0, 0];
          const to: Vec3 = [0, 0, 0];
          for (const c of kids) {
            const t = rel(base, c, fitted[j]);
            for (let k = 0; k < 3; k++) {
              from[k] += this.offsets[c][k];
              to[k] += t[k];
            }
          }
          g = quatMultiply(swingRotation(quatRotate(parentWorld, from), to), parentWorld);
        }
        world[j] = g;
        positions.set(fitted[j], base + j * 3);
        let local = quatMultiply(quatConjugate(parentWorld), g);
        if (local[3] < 0) local = [-local[0], -local[1], -local[2], -local[3]];
        rotations.set(local, (f * J + j) * 4);
      }
    }
    return { positions, rotations };
  }
}

/** Fits predicted points (frames × joints × 3) to `skeleton`; see the file comment. */
export function fitSkeleton(skeleton: Skeleton, points: ArrayLike<number>): SkeletonFit {
  return new SkeletonFitter(skeleton).fit(points);
}
