// Skeleton fitting (web/motion/fitSkeleton.ts) on the acLSTM dance skeleton: exact bone lengths after
// fitting, exact forward-kinematics poses come back unchanged, noisy points stay close, and the local
// rotations it returns rebuild its positions.
import { describe, expect, it } from 'vitest';
import { bestRotation, fitSkeleton } from '../../web/motion/fitSkeleton';
import { quatFromAxisAngle, quatMultiply, quatRotate, type Quat, type Vec3 } from '../../web/motion/math';
import type { Skeleton } from '../../web/motion/types';
import { decodeDance } from '../../web/runtime/aclstm/danceDecode';
import { parseDanceInfo } from '../../web/runtime/aclstm/danceModel';
import { readRepoFile } from './corpus';

const info = parseDanceInfo(JSON.parse(readRepoFile('public/models/aclstm.json')), 'public/models/aclstm.json');
const skeleton: Skeleton = { joints: info.skeleton.joints, parents: info.skeleton.parents, offsets: Float32Array.from(info.skeleton.offsets) };
const J = skeleton.parents.length;
const seedDecode = JSON.parse(readRepoFile('tests/fixtures/aclstm_reference.json')).decode as { features: number[]; frames: number; positions: number[] };

/** Deterministic pseudo-random numbers in [0, 1). */
function rng(seed: number): () => number {
  let s = seed >>> 0;
  return () => {
    s = (s + 0x6d2b79f5) >>> 0;
    let t = s;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

function randomQuat(r: () => number, maxAngle: number): Quat {
  return quatFromAxisAngle([r() - 0.5, r() - 0.5, r() - 0.5], (r() * 2 - 1) * maxAngle);
}

/** BVH-convention FK: G_j = G_parent · q_j, p_j = p_parent + G_parent · offset_j. */
function fk(root: Vec3, local: ArrayLike<number>, frame = 0): Float64Array {
  const out = new Float64Array(J * 3);
  const world: Quat[] = [];
  for (let j = 0; j < J; j++) {
    const r = (frame * J + j) * 4;
    const q: Quat = [local[r], local[r + 1], local[r + 2], local[r + 3]];
    const p = skeleton.parents[j];
    if (p < 0) {
      world[j] = q;
      out.set(root, 0);
      continue;
    }
    world[j] = quatMultiply(world[p], q);
    const o = quatRotate(world[p], [skeleton.offsets[j * 3], skeleton.offsets[j * 3 + 1], skeleton.offsets[j * 3 + 2]]);
    for (let k = 0; k < 3; k++) out[j * 3 + k] = out[p * 3 + k] + o[k];
  }
  return out;
}

function randomPose(r: () => number, maxAngle: number): Float64Array {
  const local = new Float64Array(J * 4);
  for (let j = 0; j < J; j++) local.set(randomQuat(r, j === 0 ? Math.PI : maxAngle), j * 4);
  return fk([r() * 4 - 2, 0.9 + r() * 0.2, r() * 4 - 2], local);
}

function worstBoneError(positions: ArrayLike<number>, frames: number): number {
  let worst = 0;
  for (let f = 0; f < frames; f++) {
    for (let j = 1; j < J; j++) {
      const a = (f * J + skeleton.parents[j]) * 3, b = (f * J + j) * 3;
      const got = Math.hypot(positions[b] - positions[a], positions[b + 1] - positions[a + 1], positions[b + 2] - positions[a + 2]);
      const want = Math.hypot(skeleton.offsets[j * 3], skeleton.offsets[j * 3 + 1], skeleton.offsets[j * 3 + 2]);
      worst = Math.max(worst, Math.abs(got - want));
    }
  }
  return worst;
}

function distances(a: ArrayLike<number>, b: ArrayLike<number>): number[] {
  const out: number[] = [];
  for (let i = 0; i < a.length; i += 3) out.push(Math.hypot(a[i] - b[i], a[i + 1] - b[i + 1], a[i + 2] - b[i + 2]));
  return out;
}

describe('bestRotation', () => {
  it('recovers a rotation from exact vector pairs, whatever its angle', () => {
    const r = rng(1);
    for (let trial = 0; trial < 50; trial++) {
      const q = randomQuat(r, Math.PI);
      const from: Vec3[] = [0, 1, 2, 3].map(() => [r() - 0.5, r() - 0.5, r() - 0.5]);
      const to = from.map((v) => quatRotate(q, v));
      const got = bestRotation(from, to)!;
      for (const v of from) {
        const a = quatRotate(got, v), b = quatRotate(q, v);
        expect(Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2])).toBeLessThan(1e-9);
      }
    }
  });

  it('is undefined without any orientation to match', () => {
    expect(bestRotation([[0, 0, 0]], [[0, 0, 0]])).toBeUndefined();
  });
});

describe('fitSkeleton', () => {
  it('returns exact forward-kinematics poses unchanged', () => {
    const r = rng(2);
    const frames = 20;
    const poses = new Float64Array(frames * J * 3);
    for (let f = 0; f < frames; f++) poses.set(randomPose(r, 1.2), f * J * 3);
    const fit = fitSkeleton(skeleton, poses);
    expect(fit.positions.length).toBe(poses.length);
    expect(Math.max(...distances(fit.positions, poses))).toBeLessThan(1e-5); // float32 output
  });

  it('keeps every bone at its skeleton length for distorted points', () => {
    const r = rng(3);
    const frames = 10;
    const points = new Float64Array(frames * J * 3);
    for (let f = 0; f < frames; f++) points.set(randomPose(r, 1).map((v) => v * (0.8 + 0.4 * r())), f * J * 3);
    expect(worstBoneError(points, frames)).toBeGreaterThan(0.01); // the input really is off
    const fit = fitSkeleton(skeleton, points);
    expect(worstBoneError(fit.positions, frames)).toBeLessThan(1e-5);
    expect(fit.positions.every(Number.isFinite)).toBe(true);
  });

  it('stays close to noisy points', () => {
    const r = rng(4);
    const frames = 30;
    const clean = new Float64Array(frames * J * 3);
    for (let f = 0; f < frames; f++) clean.set(randomPose(r, 0.8), f * J * 3);
    const sigma = 0.01;
    // Box–Muller normal noise of 1 cm per axis.
    const noisy = clean.map((v) => v + sigma * Math.sqrt(-2 * Math.log(1 - r())) * Math.cos(2 * Math.PI * r()));
    const fit = fitSkeleton(skeleton, noisy);
    const d = distances(fit.positions, clean);
    const mean = d.reduce((a, b) => a + b, 0) / d.length;
    expect(mean).toBeLessThan(0.02);
    expect(Math.max(...d)).toBeLessThan(0.06);
    expect(worstBoneError(fit.positions, frames)).toBeLessThan(1e-5);
  });

  it('moves real mocap (the seed motion decoded from the fixture) by under a few millimetres', () => {
    const points = decodeDance(seedDecode.features, J).positions;
    const fit = fitSkeleton(skeleton, points);
    const d = distances(fit.positions, points);
    expect(d.reduce((a, b) => a + b, 0) / d.length).toBeLessThan(0.003);
    expect(worstBoneError(fit.positions, seedDecode.frames)).toBeLessThan(1e-5);
  });

  it('returns local rotations that rebuild its positions by forward kinematics', () => {
    const r = rng(5);
    const points = randomPose(r, 1).map((v) => v + (r() - 0.5) * 0.05);
    const fit = fitSkeleton(skeleton, points);
    for (let j = 0; j < J; j++) {
      const q = fit.rotations.subarray(j * 4, j * 4 + 4);
      expect(Math.hypot(...q)).toBeCloseTo(1, 5);
      expect(q[3]).toBeGreaterThanOrEqual(0);
    }
    const rebuilt = fk([fit.positions[0], fit.positions[1], fit.positions[2]], fit.rotations);
    expect(Math.max(...distances(rebuilt, fit.positions))).toBeLessThan(1e-5);
  });

  it('rejects points that do not fit the skeleton', () => {
    expect(() => fitSkeleton(skeleton, new Float32Array(J * 3 + 1))).toThrow(/not a whole number of 57-point frames/);
    expect(() => fitSkeleton({ joints: ['a', 'b'], parents: [-1, 2], offsets: new Float32Array(6) }, new Float32Array(6))).toThrow(/bad parent/);
  });
});
