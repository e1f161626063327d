import { describe, expect, it } from 'vitest';
import {
  DEG, eulerToQuat, matrixToQuat, quatConjugate, quatMultiply, quatRotate, quatToEulerZYX, quatToMatrix,
  rotationFromTwoVectors, swingRotation, cross, dot, length, normalize, type Mat3, type Quat, type Vec3,
} from '../../web/motion/math';

// Independent reference: plain rotation matrices about the coordinate axes.
function axisMatrix(axis: string, a: number): Mat3 {
  const c = Math.cos(a), s = Math.sin(a);
  if (axis === 'x') return [1, 0, 0, 0, c, -s, 0, s, c];
  if (axis === 'y') return [c, 0, s, 0, 1, 0, -s, 0, c];
  return [c, -s, 0, s, c, 0, 0, 0, 1];
}
function matMul(a: Mat3, b: Mat3): Mat3 {
  const r = new Array<number>(9).fill(0);
  for (let i = 0; i < 3; i++) for (let j = 0; j < 3; j++) for (let k = 0; k < 3; k++) r[i * 3 + j] += a[i * 3 + k] * b[k * 3 + j];
  return r as Mat3;
}
const IDENTITY: Mat3 = [1, 0, 0, 0, 1, 0, 0, 0, 1];

/** Deterministic pseudo-random numbers so failures are reproducible. */
function rng(seed: number) {
  let s = seed >>> 0;
  return () => {
    s = (s * 1664525 + 1013904223) >>> 0;
    return s / 2 ** 32;
  };
}

function expectSameRotation(a: Quat, b: Quat, tol = 1e-9) {
  // q and −q are the same rotation.
  expect(Math.abs(Math.abs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]) - 1)).toBeLessThan(tol);
}
function expectVec(a: Vec3, b: Vec3, tol = 1e-9) {
  for (let i = 0; i < 3; i++) expect(a[i]).toBeCloseTo(b[i], -Math.log10(tol));
}

const ORDERS = ['XYZ', 'XZY', 'YXZ', 'YZX', 'ZXY', 'ZYX'];

describe('eulerToQuat', () => {
  const random = rng(1);
  for (const order of ORDERS) {
    it(`matches the matrix product for order ${order}, intrinsic and extrinsic`, () => {
      for (let n = 0; n < 20; n++) {
        const angles = [random() * 6 - 3, random() * 3 - 1.5, random() * 6 - 3];
        const mats = [...order].map((axis, i) => axisMatrix(axis.toLowerCase(), angles[i]));
        const intrinsic = mats.reduce((acc, m) => matMul(acc, m), IDENTITY);
        const extrinsic = mats.reduce((acc, m) => matMul(m, acc), IDENTITY);
        const qi = quatToMatrix(eulerToQuat(angles, order, true));
        const qe = quatToMatrix(eulerToQuat(angles, order, false));
        for (let k = 0; k < 9; k++) {
          expect(qi[k]).toBeCloseTo(intrinsic[k], 12);
          expect(qe[k]).toBeCloseTo(extrinsic[k], 12);
        }
      }
    });
  }

  it('treats intrinsic ZYX and extrinsic XYZ (reversed angles) as the same rotation', () => {
    expectSameRotation(eulerToQuat([0.3, -0.7, 1.1], 'ZYX', true), eulerToQuat([1.1, -0.7, 0.3], 'XYZ', false));
  });

  it('rotates +z by 90° about y onto +x (right-handed)', () => {
    expectVec(quatRotate(eulerToQuat([90 * DEG], 'Y'), [0, 0, 1]), [1, 0, 0]);
  });
});

describe('quatToEulerZYX', () => {
  it('round-trips random rotations given in any order', () => {
    const random = rng(2);
    for (const order of ORDERS) {
      for (let n = 0; n < 50; n++) {
        const q = eulerToQuat([random() * 6 - 3, random() * 6 - 3, random() * 6 - 3], order, random() < 0.5);
        const [z, y, x] = quatToEulerZYX(q);
        expect(Math.abs(y)).toBeLessThanOrEqual(Math.PI / 2 + 1e-12);
        expectSameRotation(eulerToQuat([z, y, x], 'ZYX'), q);
      }
    }
  });

  it('recovers the original angles inside the principal range', () => {
    const [z, y, x] = quatToEulerZYX(eulerToQuat([0.4, -0.9, 2.5], 'ZYX'));
    expect(z).toBeCloseTo(0.4, 12);
    expect(y).toBeCloseTo(-0.9, 12);
    expect(x).toBeCloseTo(2.5, 12);
  });

  it('stays exact at gimbal lock (y = ±90°)', () => {
    for (const yDeg of [90, -90]) {
      const q = eulerToQuat([30 * DEG, yDeg * DEG, 50 * DEG], 'ZYX');
      expectSameRotation(eulerToQuat(quatToEulerZYX(q), 'ZYX'), q, 1e-9);
    }
  });
});

describe('matrixToQuat', () => {
  it('inverts quatToMatrix, including half turns', () => {
    const random = rng(3);
    const cases: Quat[] = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]];
    for (let n = 0; n < 50; n++) cases.push(eulerToQuat([random() * 7, random() * 7, random() * 7], 'XYZ'));
    for (const q of cases) expectSameRotation(matrixToQuat(quatToMatrix(q)), q);
  });
});

describe('swingRotation', () => {
  it('takes one direction to another by the minimal rotation', () => {
    const random = rng(4);
    for (let n = 0; n < 50; n++) {
      const a: Vec3 = [random() - 0.5, random() - 0.5, random() - 0.5];
      const b: Vec3 = [random() - 0.5, random() - 0.5, random() - 0.5];
      const q = swingRotation(a, b);
      expectVec(quatRotate(q, normalize(a)), normalize(b));
      // Minimal: rotation angle equals the angle between a and b, about an axis ⟂ both.
      const angle = 2 * Math.acos(Math.min(1, Math.abs(q[3])));
      expect(angle).toBeCloseTo(Math.acos(dot(normalize(a), normalize(b))), 9);
      const axis: Vec3 = [q[0], q[1], q[2]];
      expect(Math.abs(dot(axis, a))).toBeLessThan(1e-9);
      expect(Math.abs(dot(axis, b))).toBeLessThan(1e-9);
    }
  });

  it('handles identical, opposite and zero vectors', () => {
    expectSameRotation(swingRotation([0, 2, 0], [0, 5, 0]), [0, 0, 0, 1]);
    expectVec(quatRotate(swingRotation([0, 1, 0], [0, -1, 0]), [0, 1, 0]), [0, -1, 0]);
    expectVec(quatRotate(swingRotation([1, 0, 0], [-3, 0, 0]), [1, 0, 0]), [-1, 0, 0]);
    expectSameRotation(swingRotation([0, 0, 0], [1, 0, 0]), [0, 0, 0, 1]);
  });
});

describe('rotationFromTwoVectors', () => {
  it('recovers a rotation from two rotated vectors', () => {
    const random = rng(5);
    for (let n = 0; n < 20; n++) {
      const r = eulerToQuat([random() * 7, random() * 7, random() * 7], 'YXZ');
      const a: Vec3 = [random() - 0.5, random() - 0.5, random() - 0.5];
      const b: Vec3 = [random() - 0.5, random() - 0.5, random() - 0.5];
      expectSameRotation(rotationFromTwoVectors(a, b, quatRotate(r, a), quatRotate(r, b))!, r);
    }
  });

  it('returns undefined for parallel vectors', () => {
    expect(rotationFromTwoVectors([1, 0, 0], [2, 0, 0], [0, 1, 0], [1, 0, 0])).toBeUndefined();
  });

  it('composes with multiply and conjugate consistently', () => {
    const a = eulerToQuat([0.2, 0.3, 0.4], 'XYZ');
    const b = eulerToQuat([-0.5, 0.1, 0.9], 'ZXY');
    const v: Vec3 = [0.3, -1, 2];
    expectVec(quatRotate(quatMultiply(a, b), v), quatRotate(a, quatRotate(b, v)));
    expectVec(quatRotate(quatConjugate(a), quatRotate(a, v)), v);
    expect(length(cross([1, 0, 0], [0, 1, 0]))).toBe(1);
  });
});
