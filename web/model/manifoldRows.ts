// The motion manifold's per-frame rows (the port of training/data/windows.py: smooth, ground_frame, to_local,
// to_world, motion_rows), what the denoising autoencoder (public/models/manifold-*.onnx) reads and writes: per
// frame [joint positions (joints × 3) in the root's ground-projected facing frame (x left, y up, z forward), the
// control signal (forward, sideways, turn; web/motion/control.ts controlFromTrajectory), contact left, contact
// right], laid out as manifold.json's `rows` says.
//
// The root's ground trajectory is the root joint's ground projection and the facing is the normal of the
// hips-plus-shoulders across vector, both Gaussian-smoothed over SMOOTH_SIGMA seconds (edge-padded), so the signal
// carries the course and the sway of each step stays in the positions.
//
// tests/fixtures/manifold_rows.json (python -m training.fixtures.manifold_rows) checks this against Python on a
// held-out clip (tests/unit/manifoldRows.test.ts). The arithmetic is float64, in Python's order where it matters.
import { controlFromTrajectory } from '../motion/control';
import type { ManifoldInfo } from './latentErdInfo';

/** Seconds of the Gaussian that smooths the ground trajectory and the facing (windows.py SMOOTH_SIGMA). */
export const SMOOTH_SIGMA = 0.167;
/** The joints whose across vector (left minus right hip, plus left minus right shoulder) gives the facing. */
export const FACING_JOINTS = { leftHip: 'LeftUpLeg', rightHip: 'RightUpLeg', leftArm: 'LeftArm', rightArm: 'RightArm' } as const;

/** Where things are in a row and which joints the ground frame reads, from manifold.json's `rows`. */
export interface RowLayout {
  /** Joints per frame. */
  joints: number;
  /** Values per row. */
  dim: number;
  /** [start, end) of the joint positions, the control and the contacts in a row. */
  positions: [number, number];
  control: [number, number];
  contacts: [number, number];
  /** Joint indices of FACING_JOINTS; the root trajectory is joint 0's. */
  facing: { leftHip: number; rightHip: number; leftArm: number; rightArm: number };
}

/** The row layout of a manifold.json (or vae-lstm.json) `rows`; throws when a facing joint is missing. */
export function rowLayout(info: Pick<ManifoldInfo, 'rows'>): RowLayout {
  const { joints, dim, positions, control, contacts } = info.rows;
  const index = (name: string) => {
    const j = joints.indexOf(name);
    if (j < 0) throw new Error(`the manifold's rows have no joint "${name}" (the facing needs ${Object.values(FACING_JOINTS).join(', ')})`);
    return j;
  };
  const facing = {
    leftHip: index(FACING_JOINTS.leftHip),
    rightHip: index(FACING_JOINTS.rightHip),
    leftArm: index(FACING_JOINTS.leftArm),
    rightArm: index(FACING_JOINTS.rightArm),
  };
  return { joints: joints.length, dim, positions: [...positions], control: [...control], contacts: [...contacts], facing };
}

/**
 * Gaussian smoothing along frames of `x` (frames × width, flattened) with edge padding: a kernel of
 * 2·ceil(3σ) + 1 taps, normalised to sum 1 (windows.py smooth).
 */
export function smooth(x: ArrayLike<number>, width: number, sigmaFrames: number): Float64Array {
  if (!(sigmaFrames > 0)) throw new RangeError(`smooth: sigma must be positive, got ${sigmaFrames} frames`);
  const frames = x.length / width;
  const r = Math.ceil(3 * sigmaFrames);
  const k = new Float64Array(2 * r + 1);
  let total = 0;
  for (let i = -r; i <= r; i++) total += (k[i + r] = Math.exp(-0.5 * (i / sigmaFrames) ** 2));
  for (let i = 0; i < k.length; i++) k[i] /= total;
  const out = new Float64Array(frames * width);
  for (let t = 0; t < frames; t++) {
    for (let c = 0; c < width; c++) {
      let acc = 0;
      for (let i = 0; i < k.length; i++) acc += k[i] * x[Math.min(Math.max(t + i - r, 0), frames - 1) * width + c];
      out[t * width + c] = acc;
    }
  }
  return out;
}

/** A clip's smoothed root ground trajectory (frames × [x, z]) and facing headings (frames; 0 faces +z, π/2 faces +x). */
export interface GroundFrame {
  xz: Float64Array;
  heading: Float64Array;
}

/**
 * The ground frame of world positions (frames × joints × 3): the root joint's ground projection and the facing
 * (across vector × up), each smoothed over SMOOTH_SIGMA · fps frames (windows.py ground_frame). A frame whose
 * across vector has no ground component adds nothing to the smoothed facing (Python would give NaN there).
 */
export function groundFrame(positions: ArrayLike<number>, layout: RowLayout, fps: number): GroundFrame {
  const J = layout.joints;
  const frames = positions.length / (J * 3);
  const { leftHip, rightHip, leftArm, rightArm } = layout.facing;
  const forward = new Float64Array(frames * 2);
  const root = new Float64Array(frames * 2);
  for (let f = 0; f < frames; f++) {
    const p = (j: number, axis: number) => positions[(f * J + j) * 3 + axis];
    const across = (axis: number) => p(leftHip, axis) - p(rightHip, axis) + p(leftArm, axis) - p(rightArm, axis);
    const fx = -across(2), fz = across(0);
    const norm = Math.sqrt(fx * fx + fz * fz);
    if (norm > 0) {
      forward[2 * f] = fx / norm;
      forward[2 * f + 1] = fz / norm;
    }
    root[2 * f] = p(0, 0);
    root[2 * f + 1] = p(0, 2);
  }
  const sigma = SMOOTH_SIGMA * fps;
  const smoothed = smooth(forward, 2, sigma);
  const heading = new Float64Array(frames);
  for (let f = 0; f < frames; f++) heading[f] = Math.atan2(smoothed[2 * f], smoothed[2 * f + 1]);
  return { xz: smooth(root, 2, sigma), heading };
}

/** World positions (frames × joints × 3) in each frame's ground facing frame: x left, y up, z forward (windows.py to_local). */
export function toLocal(positions: ArrayLike<number>, joints: number, ground: GroundFrame): Float64Array {
  const out = new Float64Array(positions.length);
  const frames = positions.length / (joints * 3);
  for (let f = 0; f < frames; f++) {
    const c = Math.cos(ground.heading[f]), s = Math.sin(ground.heading[f]);
    const x0 = ground.xz[2 * f], z0 = ground.xz[2 * f + 1];
    for (let j = 0; j < joints; j++) {
      const i = (f * joints + j) * 3;
      const dx = positions[i] - x0, dz = positions[i + 2] - z0;
      out[i] = c * dx - s * dz;
      out[i + 1] = positions[i + 1];
      out[i + 2] = s * dx + c * dz;
    }
  }
  return out;
}

/** Local positions (frames × joints × 3, to_local's frame) back in the world with a ground frame (windows.py to_world). */
export function toWorld(local: ArrayLike<number>, joints: number, ground: GroundFrame): Float64Array {
  const out = new Float64Array(local.length);
  const frames = local.length / (joints * 3);
  for (let f = 0; f < frames; f++) {
    const c = Math.cos(ground.heading[f]), s = Math.sin(ground.heading[f]);
    const x0 = ground.xz[2 * f], z0 = ground.xz[2 * f + 1];
    for (let j = 0; j < joints; j++) {
      const i = (f * joints + j) * 3;
      const lx = local[i], lz = local[i + 2];
      out[i] = c * lx + s * lz + x0;
      out[i + 1] = local[i + 1];
      out[i + 2] = -s * lx + c * lz + z0;
    }
  }
  return out;
}

/**
 * Rows (frames × layout.dim, physical units, not normalised) of world positions (frames × joints × 3) and
 * contacts (frames × 2, 0/1) at `fps` (windows.py motion_rows). Also returns the ground frame it used.
 */
export function motionRows(positions: ArrayLike<number>, contacts: ArrayLike<number>, layout: RowLayout, fps: number): { rows: Float64Array; ground: GroundFrame } {
  const J = layout.joints;
  const frames = positions.length / (J * 3);
  if (!Number.isInteger(frames)) throw new RangeError(`motionRows: ${positions.length} position values are not whole frames of ${J} joints × 3`);
  if (contacts.length !== frames * 2) throw new RangeError(`motionRows: ${contacts.length} contact values for ${frames} frames (expected ${frames * 2})`);
  const ground = groundFrame(positions, layout, fps);
  const local = toLocal(positions, J, ground);
  const control = controlFromTrajectory(ground.xz, ground.heading, fps);
  const { dim } = layout;
  const [p0] = layout.positions, [c0] = layout.control, [k0] = layout.contacts;
  const rows = new Float64Array(frames * dim);
  for (let f = 0; f < frames; f++) {
    const row = f * dim;
    for (let i = 0; i < J * 3; i++) rows[row + p0 + i] = local[f * J * 3 + i];
    for (let i = 0; i < 3; i++) rows[row + c0 + i] = control[f * 3 + i];
    rows[row + k0] = contacts[f * 2];
    rows[row + k0 + 1] = contacts[f * 2 + 1];
  }
  return { rows, ground };
}
