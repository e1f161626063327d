// Foot-contact clean-up (Wang, Chai, Xia §4.3): planted feet stay in place and on the ground. A faithful
// port of training/footlock.py (see its docstring for the method); keep the two in step —
// tests/unit/footLock.test.ts checks this against footlock.py's output (tests/fixtures/footlock_reference.json).
//
// It works on world joint positions of the canonical skeleton plus the contact bits, is causal (FootLock.step
// once per frame, in order, for live streams; footLock() for a whole motion), changes only the knees, ankles
// and feet, and keeps every bone length exactly. Arithmetic is in double precision like the Python.

export interface FootLockSettings {
  /** Height (m) a planted toe point is brought to. */
  groundHeight: number;
  /** Frames to bring a planted toe to the ground height. */
  blendIn: number;
  /** Frames to release a lifted foot from its anchor. */
  blendOut: number;
  /** Fraction of thigh + shin the IK may stretch to. */
  reach: number;
  /** How much (m) the foot's forward direction adds to the raw knee's bend direction. */
  poleBias: number;
}

/** footlock.py's constants (refiner.json "footlock" carries the same values). */
export const FOOT_LOCK_DEFAULTS: Readonly<FootLockSettings> = Object.freeze({
  groundHeight: 0.03,
  blendIn: 3,
  blendOut: 6,
  reach: 0.999,
  poleBias: 0.05,
});

/** Per leg: hip, knee, ankle, toe, toe end (footlock.py LEGS). */
export const LEG_JOINTS = [
  ['LeftUpLeg', 'LeftLeg', 'LeftFoot', 'LeftToeBase', 'LeftToeBase_end'],
  ['RightUpLeg', 'RightLeg', 'RightFoot', 'RightToeBase', 'RightToeBase_end'],
] as const;

type V3 = [number, number, number];

const sub = (a: V3, b: V3): V3 => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const add = (a: V3, b: V3): V3 => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const scale = (a: V3, s: number): V3 => [a[0] * s, a[1] * s, a[2] * s];
const dot = (a: V3, b: V3): number => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const norm = (a: V3): number => Math.sqrt(dot(a, a));
const cross = (a: V3, b: V3): V3 => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];

export function smoothstep(t: number): number {
  t = Math.min(Math.max(t, 0), 1);
  return t * t * (3 - 2 * t);
}

/**
 * Knee and ankle with |knee − hip| = l1 and |ankle − knee| = l2, the ankle at `target` or, out of reach, as
 * close as the leg allows along the hip–target line; the knee bends towards the raw knee's offset from that
 * line plus poleBias × `forward` (footlock.py two_bone_ik).
 */
export function twoBoneIK(hip: V3, knee: V3, target: V3, l1: number, l2: number, reach: number, forward: V3 | null, poleBias: number): [V3, V3] {
  const dVec = sub(target, hip);
  let d = norm(dVec);
  const u: V3 = d > 1e-9 ? scale(dVec, 1 / d) : [0, -1, 0];
  d = Math.min(Math.max(d, Math.abs(l1 - l2) + 1e-6), reach * (l1 + l2));
  const pole = forward ? add(sub(knee, hip), scale(forward, poleBias)) : sub(knee, hip);
  let bend = sub(pole, scale(u, dot(pole, u)));
  let n = norm(bend);
  if (n < 1e-9) {
    // raw leg straight: bend forward (+z of the hip–target line's frame)
    bend = cross(u, [1, 0, 0]);
    n = norm(bend);
    if (n < 1e-9) {
      bend = [0, 0, 1];
      n = 1;
    }
  }
  bend = scale(bend, 1 / n);
  const a = (l1 * l1 - l2 * l2 + d * d) / (2 * d);
  const r = Math.sqrt(Math.max(l1 * l1 - a * a, 0));
  return [add(add(hip, scale(u, a)), scale(bend, r)), add(hip, scale(u, d))];
}

/**
 * The ankle target when the foot pivots about its locked toe (a heel lift) because the target is beyond
 * `reach` from the hip; null when it is reachable as it is or when even pivoting cannot reach
 * (footlock.py pivot_foot).
 */
function pivotFoot(hip: V3, ankleTarget: V3, toeTarget: V3, reach: number): V3 | null {
  if (norm(sub(ankleTarget, hip)) <= reach) return null;
  const r = norm(sub(toeTarget, ankleTarget));
  const dVec = sub(toeTarget, hip);
  const d = norm(dVec);
  if (d >= reach + r || d <= Math.abs(reach - r) || d < 1e-9) return null;
  const u = scale(dVec, 1 / d);
  const a = (reach * reach - r * r + d * d) / (2 * d);
  const rho = Math.sqrt(Math.max(reach * reach - a * a, 0));
  const centre = add(hip, scale(u, a));
  const rel = sub(ankleTarget, centre);
  const off = sub(rel, scale(u, dot(rel, u)));
  const n = norm(off);
  if (n < 1e-9) return null;
  return add(centre, scale(off, rho / n));
}

/** `w` turned by the smallest rotation taking direction a to direction b (footlock.py rotation_between). */
function rotateBetween(a: V3, b: V3, w: V3): V3 {
  a = scale(a, 1 / norm(a));
  b = scale(b, 1 / norm(b));
  const v = cross(a, b), c = dot(a, b);
  if (c < -1 + 1e-9) {
    // opposite: any half turn will do
    let axis = cross(a, [1, 0, 0]);
    if (!(norm(axis) > 1e-6)) axis = cross(a, [0, 1, 0]);
    axis = scale(axis, 1 / norm(axis));
    return sub(scale(axis, 2 * dot(axis, w)), w);
  }
  // (I + K + K²/(1 + c)) w with K w = v × w
  const vw = cross(v, w);
  return add(add(w, vw), scale(cross(v, vw), 1 / (1 + c)));
}

interface FootState {
  /** Locked toe (x, z), or null. */
  anchor: [number, number] | null;
  /** Toe height when the contact started. */
  startY: number;
  /** Where the locked toe was drawn in the last planted frame, or null. */
  locked: V3 | null;
  /** Frames since the contact started (0 = not planted). */
  planted: number;
  /** Frames left of the blend-out. */
  release: number;
}

/** Streaming foot lock: `step` once per frame, in order; `reset` before a new motion. */
export class FootLock {
  readonly settings: FootLockSettings;
  private readonly joints: number;
  /** Per leg: joint indices (hip, knee, ankle, toe, toe end) and bone lengths (thigh, shin). */
  private readonly legs: { index: number[]; l1: number; l2: number }[];
  private feet: FootState[] = [];

  /**
   * `joints`: the skeleton's joint names (LEG_JOINTS must be among them); `offsets`: joints × 3 rest offsets
   * (metres), whose lengths give thigh and shin.
   */
  constructor(joints: readonly string[], offsets: ArrayLike<number>, settings: Partial<FootLockSettings> = {}) {
    this.settings = { ...FOOT_LOCK_DEFAULTS, ...settings };
    const { blendIn, blendOut, reach } = this.settings;
    if (!Number.isInteger(blendIn) || blendIn < 0 || !Number.isInteger(blendOut) || blendOut < 1) {
      throw new RangeError(`footLock: blendIn must be an integer ≥ 0 and blendOut ≥ 1, got ${blendIn} and ${blendOut}`);
    }
    if (!(reach > 0 && reach <= 1)) throw new RangeError(`footLock: reach must be in (0, 1], got ${reach}`);
    if (offsets.length !== joints.length * 3) throw new Error(`footLock: ${offsets.length} offset values for ${joints.length} joints`);
    this.joints = joints.length;
    const length = (j: number) => Math.hypot(offsets[j * 3], offsets[j * 3 + 1], offsets[j * 3 + 2]);
    this.legs = LEG_JOINTS.map((names) => {
      const index = names.map((n) => joints.indexOf(n));
      const missing = names.filter((_, i) => index[i] < 0);
      if (missing.length) throw new Error(`footLock needs the leg joints ${names.join(', ')}; missing ${missing.join(', ')}`);
      return { index, l1: length(index[1]), l2: length(index[2]) };
    });
    this.reset();
  }

  reset(): void {
    this.feet = [0, 1].map(() => ({ anchor: null, startY: 0, locked: null, planted: 0, release: 0 }));
  }

  /**
   * One frame: world positions `pose` (joints × 3) and contact bits (left, right; non-zero = planted) →
   * cleaned positions in `out` (may be `pose` itself). Only knees, ankles, toes and toe ends change.
   */
  step(pose: ArrayLike<number>, contacts: ArrayLike<number>, out: Float32Array | Float64Array = new Float64Array(this.joints * 3)): Float32Array | Float64Array {
    const n = this.joints * 3;
    if (pose.length !== n || out.length !== n) throw new Error(`footLock.step: expected ${n} position values, got ${pose.length} in and ${out.length} out`);
    if (out !== pose) for (let k = 0; k < n; k++) out[k] = pose[k];
    const at = (j: number): V3 => [pose[j * 3], pose[j * 3 + 1], pose[j * 3 + 2]];
    const put = (j: number, p: V3) => {
      out[j * 3] = p[0];
      out[j * 3 + 1] = p[1];
      out[j * 3 + 2] = p[2];
    };
    const { groundHeight, blendIn, blendOut, reach, poleBias } = this.settings;
    for (let side = 0; side < 2; side++) {
      const foot = this.feet[side];
      const { index, l1, l2 } = this.legs[side];
      const [hipJ, kneeJ, ankleJ, toeJ, endJ] = index;
      const rawToe = at(toeJ), rawAnkle = at(ankleJ), hip = at(hipJ);
      const planted = contacts[side] > 0;
      let target: V3;
      if (planted) {
        if (foot.planted === 0) {
          // contact starts where the toe is drawn now: no jump
          const start = this.drawnToe(foot, rawToe);
          foot.anchor = [start[0], start[2]];
          foot.startY = start[1];
        }
        const w = blendIn > 0 ? smoothstep(foot.planted / blendIn) : 1;
        foot.planted++;
        target = [foot.anchor![0], (1 - w) * foot.startY + w * groundHeight, foot.anchor![1]];
      } else {
        foot.planted = 0;
        if (foot.release <= 0) continue; // free foot: raw pose
        target = this.drawnToe(foot, rawToe);
        foot.release--;
      }
      const toeFromAnkle = sub(rawToe, rawAnkle);
      let ankleTarget = sub(target, toeFromAnkle);
      const pivoted = pivotFoot(hip, ankleTarget, target, reach * (l1 + l2));
      if (pivoted) ankleTarget = pivoted;
      const flat: V3 = [toeFromAnkle[0], 0, toeFromAnkle[2]];
      const forward = scale(flat, 1 / Math.max(norm(flat), 1e-9));
      const [newKnee, newAnkle] = twoBoneIK(hip, at(kneeJ), ankleTarget, l1, l2, reach, forward, poleBias);
      let newToe: V3;
      if (!pivoted) {
        // the foot moves rigidly with the ankle
        const shift = sub(newAnkle, rawAnkle);
        newToe = add(rawToe, shift);
        put(endJ, add(at(endJ), shift));
      } else {
        // the foot turns about the toe (heel lifts): ankle → toe and toe → toe end turned alike
        put(endJ, add(target, rotateBetween(toeFromAnkle, sub(target, newAnkle), sub(at(endJ), rawToe))));
        newToe = target;
      }
      put(toeJ, newToe);
      put(kneeJ, newKnee);
      put(ankleJ, newAnkle);
      if (planted) {
        if (norm(sub(newAnkle, ankleTarget)) > 1e-6) foot.anchor = [newToe[0], newToe[2]]; // out of reach: the anchor follows the body
        foot.locked = newToe;
        foot.release = blendOut;
      }
    }
    return out;
  }

  /** Where the toe is drawn this frame if nothing new happens: the raw toe, or during a release the blend from the last locked position. */
  private drawnToe(foot: FootState, rawToe: V3): V3 {
    if (foot.release <= 0 || !foot.locked) return rawToe;
    const w = smoothstep(foot.release / this.settings.blendOut);
    return add(scale(foot.locked, w), scale(rawToe, 1 - w));
  }
}

/**
 * The foot lock over a whole motion: positions (frames × joints × 3) and contacts (frames × 2) → new
 * positions (float32, like a Motion's).
 */
export function footLock(
  positions: Float32Array | Float64Array,
  contacts: ArrayLike<number>,
  joints: readonly string[],
  offsets: ArrayLike<number>,
  settings: Partial<FootLockSettings> = {},
): Float32Array {
  const n = joints.length * 3;
  const frames = positions.length / n;
  if (!Number.isInteger(frames)) throw new Error(`footLock: ${positions.length} position values is not a whole number of ${joints.length}-joint frames`);
  if (contacts.length !== frames * 2) throw new Error(`footLock: ${contacts.length} contact values for ${frames} frames (expected ${frames * 2})`);
  const lock = new FootLock(joints, offsets, settings);
  const out = new Float32Array(positions.length);
  const pose = new Float64Array(n);
  for (let f = 0; f < frames; f++) {
    lock.step(positions.subarray(f * n, (f + 1) * n), [contacts[f * 2], contacts[f * 2 + 1]], pose);
    out.set(pose, f * n);
  }
  return out;
}
