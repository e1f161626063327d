// Small rotation helpers in double precision.
// Quaternions are [x, y, z, w] (the three.js layout); matrices are row-major 3×3 and act on column
// vectors (v_world = M · v_local). Angles are radians unless a name says otherwise.

export type Vec3 = [number, number, number];
export type Quat = [number, number, number, number];
/** Row-major 3×3 matrix: [m00, m01, m02, m10, …, m22]. */
export type Mat3 = [number, number, number, number, number, number, number, number, number];

export type Axis = 'x' | 'y' | 'z';

export const DEG = Math.PI / 180;

export function quatIdentity(): Quat {
  return [0, 0, 0, 1];
}

/** Hamilton product a·b: rotating by the result applies b first, then a. */
export function quatMultiply(a: Quat, b: Quat): Quat {
  // Indexed reads rather than destructuring: destructuring goes through the iterator protocol, which
  // is far slower in these hot loops.
  const ax = a[0], ay = a[1], az = a[2], aw = a[3];
  const bx = b[0], by = b[1], bz = b[2], bw = b[3];
  return [
    aw * bx + ax * bw + ay * bz - az * by,
    aw * by - ax * bz + ay * bw + az * bx,
    aw * bz + ax * by - ay * bx + az * bw,
    aw * bw - ax * bx - ay * by - az * bz,
  ];
}

/** Inverse of a unit quaternion. */
export function quatConjugate(q: Quat): Quat {
  return [-q[0], -q[1], -q[2], q[3]];
}

export function quatNormalize(q: Quat): Quat {
  const n = Math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  return n > 0 ? [q[0] / n, q[1] / n, q[2] / n, q[3] / n] : quatIdentity();
}

/** q · v · q⁻¹ for a unit quaternion. */
export function quatRotate(q: Quat, v: Vec3): Vec3 {
  const x = q[0], y = q[1], z = q[2], w = q[3];
  // t = 2 (q_xyz × v); v' = v + w t + q_xyz × t
  const tx = 2 * (y * v[2] - z * v[1]);
  const ty = 2 * (z * v[0] - x * v[2]);
  const tz = 2 * (x * v[1] - y * v[0]);
  return [
    v[0] + w * tx + (y * tz - z * ty),
    v[1] + w * ty + (z * tx - x * tz),
    v[2] + w * tz + (x * ty - y * tx),
  ];
}

export function quatFromAxisAngle(axis: Vec3, angle: number): Quat {
  const n = Math.hypot(axis[0], axis[1], axis[2]);
  if (n === 0) return quatIdentity();
  const s = Math.sin(angle / 2) / n;
  return [axis[0] * s, axis[1] * s, axis[2] * s, Math.cos(angle / 2)];
}

/** Rotation by `angle` about a coordinate axis. */
export function quatAboutAxis(axis: Axis, angle: number): Quat {
  const s = Math.sin(angle / 2);
  const c = Math.cos(angle / 2);
  if (axis === 'x') return [s, 0, 0, c];
  if (axis === 'y') return [0, s, 0, c];
  return [0, 0, s, c];
}

/**
 * Euler angles to a quaternion. `order` names the axes of `angles` in sequence, e.g. "ZYX".
 * Intrinsic (BVH channel order): R = R_a0 · R_a1 · R_a2.
 * Extrinsic (ASF axis/dof order, rotations about fixed axes applied first to last): R = R_a2 · R_a1 · R_a0.
 */
export function eulerToQuat(angles: ArrayLike<number>, order: string, intrinsic = true): Quat {
  if (angles.length !== order.length) {
    throw new Error(`eulerToQuat: ${angles.length} angles for axis order "${order}"`);
  }
  let q = quatIdentity();
  for (let i = 0; i < order.length; i++) {
    const r = quatAboutAxis(order[i].toLowerCase() as Axis, angles[i]);
    q = intrinsic ? quatMultiply(q, r) : quatMultiply(r, q);
  }
  return q;
}

export function quatToMatrix(q: Quat): Mat3 {
  const n = quatNormalize(q);
  const x = n[0], y = n[1], z = n[2], w = n[3];
  return [
    1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),
    2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
    2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y),
  ];
}

/** Quaternion (w ≥ 0) of a rotation matrix, stable for all angles. */
export function matrixToQuat(m: Mat3): Quat {
  const [m00, m01, m02, m10, m11, m12, m20, m21, m22] = m;
  const trace = m00 + m11 + m22;
  let q: Quat;
  // Use the formula whose divisor is largest.
  if (trace >= m00 && trace >= m11 && trace >= m22) {
    q = [m21 - m12, m02 - m20, m10 - m01, 1 + trace];
  } else if (m00 >= m11 && m00 >= m22) {
    q = [1 + m00 - m11 - m22, m01 + m10, m02 + m20, m21 - m12];
  } else if (m11 >= m22) {
    q = [m01 + m10, 1 - m00 + m11 - m22, m12 + m21, m02 - m20];
  } else {
    q = [m02 + m20, m12 + m21, 1 - m00 - m11 + m22, m10 - m01];
  }
  q = quatNormalize(q);
  return q[3] < 0 ? [-q[0], -q[1], -q[2], -q[3]] : q;
}

/**
 * Intrinsic Z-Y-X Euler angles [z, y, x] (radians) with R = Rz · Ry · Rx, as BVH
 * "Zrotation Yrotation Xrotation" channels expect. Exact at gimbal lock too (then x = 0).
 */
export function quatToEulerZYX(q: Quat): Vec3 {
  const m = quatToMatrix(q);
  const cy = Math.hypot(m[7], m[8]);
  const y = Math.atan2(-m[6], cy);
  if (cy < 1e-9) {
    // y = ±90°: only z ∓ x is defined; put it all in z.
    return [Math.atan2(-m[1], m[4]), y, 0];
  }
  return [Math.atan2(m[3], m[0]), y, Math.atan2(m[7], m[8])];
}

export function sub(a: Vec3, b: Vec3): Vec3 {
  return [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
}

export function add(a: Vec3, b: Vec3): Vec3 {
  return [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
}

export function scale(a: Vec3, s: number): Vec3 {
  return [a[0] * s, a[1] * s, a[2] * s];
}

export function dot(a: Vec3, b: Vec3): number {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

export function cross(a: Vec3, b: Vec3): Vec3 {
  return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
}

export function length(a: Vec3): number {
  return Math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); // Math.hypot is much slower
}

export function normalize(a: Vec3): Vec3 {
  const n = length(a);
  return n > 0 ? [a[0] / n, a[1] / n, a[2] / n] : [0, 0, 0];
}

/**
 * Minimal ("swing") rotation taking the direction of `from` to the direction of `to`.
 * Identity if either is zero; for opposite directions, a half turn about an axis perpendicular to `from`.
 */
export function swingRotation(from: Vec3, to: Vec3): Quat {
  const a = normalize(from);
  const b = normalize(to);
  if (length(a) === 0 || length(b) === 0) return quatIdentity();
  const c = dot(a, b);
  if (c < -1 + 1e-12) {
    const axis = Math.abs(a[0]) < 0.9 ? cross(a, [1, 0, 0]) : cross(a, [0, 1, 0]);
    return quatFromAxisAngle(axis, Math.PI);
  }
  // Half-angle construction: q = (a × b, 1 + a·b), normalised.
  const v = cross(a, b);
  return quatNormalize([v[0], v[1], v[2], 1 + c]);
}

/**
 * Rotation taking the frame spanned by (a0, b0) to the frame spanned by (a1, b1): a0's direction
 * maps exactly onto a1's, and the plane of (a0, b0) onto the plane of (a1, b1).
 * Returns undefined when either pair is (nearly) parallel.
 */
export function rotationFromTwoVectors(a0: Vec3, b0: Vec3, a1: Vec3, b1: Vec3): Quat | undefined {
  const frame = (a: Vec3, b: Vec3): Mat3 | undefined => {
    const e1 = normalize(a);
    const n = cross(a, b);
    if (length(n) < 1e-6 * length(a) * length(b) || length(e1) === 0) return undefined;
    const e2 = normalize(n);
    const e3 = cross(e1, e2);
    // Columns e1, e2, e3.
    return [e1[0], e2[0], e3[0], e1[1], e2[1], e3[1], e1[2], e2[2], e3[2]];
  };
  const f0 = frame(a0, b0);
  const f1 = frame(a1, b1);
  if (!f0 || !f1) return undefined;
  // R = F1 · F0ᵀ
  const r = new Array<number>(9);
  for (let i = 0; i < 3; i++) {
    for (let j = 0; j < 3; j++) {
      r[i * 3 + j] = f1[i * 3] * f0[j * 3] + f1[i * 3 + 1] * f0[j * 3 + 1] + f1[i * 3 + 2] * f0[j * 3 + 2];
    }
  }
  return matrixToQuat(r as Mat3);
}
