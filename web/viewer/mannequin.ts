// The project's own character: a smooth grey mannequin made here by code (no asset), one SkinnedMesh whose 25
// bones are the canonical skeleton's points (web/motion/skeletonMap.ts CANONICAL_JOINTS), proportioned to the
// motion's own bone lengths and posed every frame from joint positions alone.
//
// Bone k sits on canonical point k and turns the body part that starts there (the thigh's bone is on the hip
// point, the shin's on the knee). Its rotation is solved per frame from positions: the bone's +y axis aims at
// its child point and its +x axis is a side vector made perpendicular to it: the hips' left→right for the
// pelvis, the shoulders' for the spine, neck and head, and for a limb the normal of its bend plane (knee or
// elbow) when it is bent, sliding to the pelvis side (legs) or the chest's front (arms) as it straightens, so
// a limb's upper and lower parts and its hand or foot share one hinge and never flip. The same solver on the
// bind pose gives the bind rotations, so a still motion in the bind pose leaves every vertex where it was built.
//
// The surface is a few closed tubes (torso, neck, head, arms, legs, hands, feet), each a chain of elliptical
// rings around a centre line with a radius profile, weighted to one or two bones with the weights blended
// over a short stretch around each joint (elbows and knees bend smoothly instead of creasing).

import * as THREE from 'three';
import { CANONICAL_JOINTS, CANONICAL_PARENTS } from '../motion/skeletonMap';
import { PALETTE } from './palette';

/** Number of canonical points, and so of bones. */
export const BONES = CANONICAL_JOINTS.length;
const J = Object.fromEntries(CANONICAL_JOINTS.map((name, k) => [name, k])) as Record<(typeof CANONICAL_JOINTS)[number], number>;

/**
 * The point each bone aims its +y axis at (its body part's far end); -1 for the tips, which copy their
 * parent's rotation and carry no vertices.
 */
const AIM: number[] = CANONICAL_JOINTS.map((_, k) => {
  if (k === J.Hips) return J.Spine;
  if (k === J.Neck) return J.Neck1;
  const child = CANONICAL_PARENTS.indexOf(k);
  return child;
});

/** Per side (left, right): the leg's hip, knee, ankle and the arm's shoulder, elbow, wrist. */
const LEGS = [[J.LeftUpLeg, J.LeftLeg, J.LeftFoot], [J.RightUpLeg, J.RightLeg, J.RightFoot]] as const;
const ARMS = [[J.LeftArm, J.LeftForeArm, J.LeftHand], [J.RightArm, J.RightForeArm, J.RightHand]] as const;
/** Per side, the bones turned with the leg's side vector, then those turned with the arm's. */
const LEG_BONES = [[J.LeftUpLeg, J.LeftLeg, J.LeftFoot, J.LeftToeBase], [J.RightUpLeg, J.RightLeg, J.RightFoot, J.RightToeBase]] as const;
const ARM_BONES = [[J.LeftArm, J.LeftForeArm, J.LeftHand], [J.RightArm, J.RightForeArm, J.RightHand]] as const;
/** The tips: no body part of their own. */
const TIPS = [J.LeftToeBase_end, J.RightToeBase_end, J.Head_end, J.LeftHand_end, J.RightHand_end] as const;

/** Canonical leg length (hip → knee → ankle) of training/mocap/canonical_skeleton.json; the shape's sizes are for it. */
const CANONICAL_LEG = 0.829;

export interface MannequinColors {
  body: THREE.Color;
  left: THREE.Color;
  right: THREE.Color;
}

/** Light warm grey, with the limbs of each side tinted a little towards the page's left/right colours. */
export const MANNEQUIN_COLORS: MannequinColors = {
  body: new THREE.Color('#c9ccd3'),
  left: new THREE.Color('#c9ccd3').lerp(PALETTE.left, 0.3),
  right: new THREE.Color('#c9ccd3').lerp(PALETTE.right, 0.3),
};

/** The companion beside the main figure: the same, darker and greyer. */
export const COMPANION_MANNEQUIN_COLORS: MannequinColors = {
  body: new THREE.Color('#8e939e'),
  left: new THREE.Color('#8e939e').lerp(PALETTE.left, 0.18),
  right: new THREE.Color('#8e939e').lerp(PALETTE.right, 0.18),
};

// ---------------------------------------------------------------- small vector helpers on plain arrays

type V3 = [number, number, number];
const v = (x = 0, y = 0, z = 0): V3 => [x, y, z];
const add = (a: V3, b: V3): V3 => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const sub = (a: V3, b: V3): V3 => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const scale = (a: V3, s: number): V3 => [a[0] * s, a[1] * s, a[2] * s];
const dot = (a: V3, b: V3) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a: V3, b: V3): V3 => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const len = (a: V3) => Math.hypot(a[0], a[1], a[2]);
const unit = (a: V3): V3 => { const l = len(a) || 1; return [a[0] / l, a[1] / l, a[2] / l]; };
const lerp3 = (a: V3, b: V3, t: number): V3 => [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t];
const smoothstep = (a: number, b: number, x: number) => { const t = Math.min(Math.max((x - a) / (b - a), 0), 1); return t * t * (3 - 2 * t); };

// ---------------------------------------------------------------- the pose solver (no allocation per frame)

/**
 * Solves every bone's world rotation and position from the 25 canonical points. Keeps the last good side
 * vector of each bone, used when a side vector is momentarily parallel to its bone.
 */
export class BoneSolver {
  /** Per bone, a 4×4 column-major world matrix (three.js order). */
  readonly matrices = new Float64Array(BONES * 16);
  private readonly lastSide = new Float64Array(BONES * 3);
  // scratch
  private readonly a = new Float64Array(3);
  private readonly b = new Float64Array(3);
  private readonly c = new Float64Array(3);
  private readonly hipsSide = new Float64Array(3);
  private readonly shoulderSide = new Float64Array(3);
  private readonly spineSide = new Float64Array(3);
  private readonly legSide = [new Float64Array(3), new Float64Array(3)];
  private readonly armSide = [new Float64Array(3), new Float64Array(3)];
  private readonly armFallback = new Float64Array(3);

  constructor() {
    for (let k = 0; k < BONES; k++) this.lastSide[k * 3] = 1;
  }

  /** Fills `matrices` from points (25 × 3, world). */
  solve(P: ArrayLike<number>): void {
    const { hipsSide, shoulderSide, spineSide } = this;
    diff(P, J.LeftUpLeg, J.RightUpLeg, hipsSide); normalise(hipsSide);
    diff(P, J.LeftArm, J.RightArm, shoulderSide); normalise(shoulderSide);
    for (let i = 0; i < 3; i++) spineSide[i] = hipsSide[i] + shoulderSide[i];
    this.frame(P, J.Hips, hipsSide);
    this.frame(P, J.Spine, spineSide);
    this.frame(P, J.Spine1, shoulderSide);
    this.frame(P, J.Neck, shoulderSide);
    this.frame(P, J.Neck1, shoulderSide);
    this.frame(P, J.Head, shoulderSide);
    // Limbs: the side vector is the bend plane's normal (thigh × shin, upper arm × forearm) when bent, sliding
    // to a steady fallback as the limb straightens.
    const chest = J.Spine1 * 16;
    const M = this.matrices;
    for (let s = 0; s < 2; s++) {
      const leg = LEGS[s], arm = ARMS[s];
      this.limbSide(P, leg[0], leg[1], leg[2], hipsSide, this.legSide[s], 0.1, 0.3);
      const shoulder = arm[0], elbow = arm[1], wrist = arm[2];
      // Arms' fallback: upper arm × (chest front + a little chest up), the elbow's axis when it bends forward.
      const { a, armFallback: c } = this;
      diff(P, elbow, shoulder, a); normalise(a);
      const fx = M[chest + 8] + 0.3 * M[chest + 4], fy = M[chest + 9] + 0.3 * M[chest + 5], fz = M[chest + 10] + 0.3 * M[chest + 6];
      c[0] = a[1] * fz - a[2] * fy; c[1] = a[2] * fx - a[0] * fz; c[2] = a[0] * fy - a[1] * fx;
      normalise(c);
      this.limbSide(P, shoulder, elbow, wrist, c, this.armSide[s], 0.12, 0.35);
    }
    for (let s = 0; s < 2; s++) {
      for (let i = 0; i < LEG_BONES[s].length; i++) this.frame(P, LEG_BONES[s][i], this.legSide[s]);
      for (let i = 0; i < ARM_BONES[s].length; i++) this.frame(P, ARM_BONES[s][i], this.armSide[s]);
    }
    // Tips: the parent's rotation, on their own point.
    for (let t = 0; t < TIPS.length; t++) {
      const k = TIPS[t];
      const p = CANONICAL_PARENTS[k];
      for (let i = 0; i < 12; i++) M[k * 16 + i] = M[p * 16 + i];
      M[k * 16 + 12] = P[k * 3]; M[k * 16 + 13] = P[k * 3 + 1]; M[k * 16 + 14] = P[k * 3 + 2]; M[k * 16 + 15] = 1;
    }
  }

  /** A limb's side vector into `out`: its bend normal blended with `fallback` (unit) by how bent it is. */
  private limbSide(P: ArrayLike<number>, top: number, mid: number, end: number, fallback: Float64Array, out: Float64Array, straight: number, bent: number): void {
    const { a, b, c } = this;
    diff(P, mid, top, a); normalise(a);
    diff(P, end, mid, b); normalise(b);
    c[0] = a[1] * b[2] - a[2] * b[1]; c[1] = a[2] * b[0] - a[0] * b[2]; c[2] = a[0] * b[1] - a[1] * b[0];
    const sinBend = Math.hypot(c[0], c[1], c[2]);
    const w = smoothstep(straight, bent, sinBend);
    const k = sinBend > 1e-9 ? w / sinBend : 0;
    for (let i = 0; i < 3; i++) out[i] = c[i] * k + fallback[i] * (1 - w);
  }

  /** Bone k's matrix: +y towards its aim point, +x along `side` made perpendicular, on point k. */
  private frame(P: ArrayLike<number>, k: number, side: ArrayLike<number>): void {
    const y = this.a;
    diff(P, AIM[k], k, y);
    normalise(y);
    const last = this.lastSide;
    let x0 = side[0], x1 = side[1], x2 = side[2];
    let d = x0 * y[0] + x1 * y[1] + x2 * y[2];
    x0 -= d * y[0]; x1 -= d * y[1]; x2 -= d * y[2];
    let l = Math.hypot(x0, x1, x2);
    if (l < 1e-4) {
      // Side parallel to the bone: keep the last side (then any perpendicular).
      x0 = last[k * 3]; x1 = last[k * 3 + 1]; x2 = last[k * 3 + 2];
      d = x0 * y[0] + x1 * y[1] + x2 * y[2];
      x0 -= d * y[0]; x1 -= d * y[1]; x2 -= d * y[2];
      l = Math.hypot(x0, x1, x2);
      if (l < 1e-4) {
        if (Math.abs(y[0]) < 0.9) { x0 = 1 - y[0] * y[0]; x1 = -y[0] * y[1]; x2 = -y[0] * y[2]; } else { x0 = -y[1] * y[0]; x1 = 1 - y[1] * y[1]; x2 = -y[1] * y[2]; }
        l = Math.hypot(x0, x1, x2);
      }
    }
    x0 /= l; x1 /= l; x2 /= l;
    last[k * 3] = x0; last[k * 3 + 1] = x1; last[k * 3 + 2] = x2;
    // z = x × y
    const z0 = x1 * y[2] - x2 * y[1], z1 = x2 * y[0] - x0 * y[2], z2 = x0 * y[1] - x1 * y[0];
    const M = this.matrices, o = k * 16;
    M[o] = x0; M[o + 1] = x1; M[o + 2] = x2; M[o + 3] = 0;
    M[o + 4] = y[0]; M[o + 5] = y[1]; M[o + 6] = y[2]; M[o + 7] = 0;
    M[o + 8] = z0; M[o + 9] = z1; M[o + 10] = z2; M[o + 11] = 0;
    M[o + 12] = P[k * 3]; M[o + 13] = P[k * 3 + 1]; M[o + 14] = P[k * 3 + 2]; M[o + 15] = 1;
  }
}

function diff(P: ArrayLike<number>, a: number, b: number, out: Float64Array): void {
  out[0] = P[a * 3] - P[b * 3];
  out[1] = P[a * 3 + 1] - P[b * 3 + 1];
  out[2] = P[a * 3 + 2] - P[b * 3 + 2];
}

function normalise(a: Float64Array): void {
  const l = Math.hypot(a[0], a[1], a[2]);
  if (l > 1e-12) { a[0] /= l; a[1] /= l; a[2] /= l; }
}

// ---------------------------------------------------------------- proportions and the bind pose

/**
 * Each bone's length (canonical point to its parent) measured on the motion: the median over up to 64 frames,
 * left and right averaged (a mannequin is symmetric).
 */
export function measureBones(points: Float32Array, frames: number): Float64Array {
  const lengths = new Float64Array(BONES);
  const step = Math.max(1, Math.floor(frames / 64));
  const samples: number[] = [];
  for (let k = 1; k < BONES; k++) {
    const p = CANONICAL_PARENTS[k];
    samples.length = 0;
    for (let f = 0; f < frames; f += step) {
      const o = f * BONES * 3;
      const l = Math.hypot(points[o + k * 3] - points[o + p * 3], points[o + k * 3 + 1] - points[o + p * 3 + 1], points[o + k * 3 + 2] - points[o + p * 3 + 2]);
      if (Number.isFinite(l)) samples.push(l);
    }
    samples.sort((x, y) => x - y);
    lengths[k] = samples.length ? samples[samples.length >> 1] : 0;
  }
  for (const name of CANONICAL_JOINTS) {
    if (!name.startsWith('Left')) continue;
    const l = J[name], r = J[name.replace('Left', 'Right') as keyof typeof J];
    lengths[l] = lengths[r] = (lengths[l] + lengths[r]) / 2;
  }
  return lengths;
}

/**
 * Canonical directions of the rigid parts (training/mocap/canonical_skeleton.json offsets, left side), the
 * bind pose's limbs straight: legs down, feet forward, arms 45° down (an A-pose: the least bending at the
 * shoulder for the poses people hold most).
 */
const BIND_DIRECTIONS: Record<string, V3> = {
  LeftUpLeg: v(0.0907, -0.1002, 0.0412), LeftLeg: v(0, -1, 0), LeftFoot: v(0, -1, 0), LeftToeBase: v(0, -0.029, 0.114), LeftToeBase_end: v(0, 0, 1),
  Spine: v(0, 0.115, -0.009), Spine1: v(0, 1, 0), Neck: v(0, 0.117, 0.004), Neck1: v(0, 0.095, 0.008), Head: v(0, 0.095, -0.014), Head_end: v(0, 0.098, -0.006),
  LeftArm: v(0.18, 0.064, -0.01), LeftForeArm: v(Math.SQRT1_2, -Math.SQRT1_2, 0), LeftHand: v(Math.SQRT1_2, -Math.SQRT1_2, 0), LeftHand_end: v(Math.SQRT1_2, -Math.SQRT1_2, 0),
};

/** The bind pose's points (25 × 3, hips at the origin) for the given bone lengths. */
export function bindPoints(lengths: Float64Array): V3[] {
  const pts: V3[] = [v()];
  for (let k = 1; k < BONES; k++) {
    const name = CANONICAL_JOINTS[k];
    const left = name.replace('Right', 'Left');
    let d = unit(BIND_DIRECTIONS[left]);
    if (name.startsWith('Right')) d = [-d[0], d[1], d[2]];
    pts.push(add(pts[CANONICAL_PARENTS[k]], scale(d, lengths[k])));
  }
  return pts;
}

// ---------------------------------------------------------------- the surface

/** A ring of a tube: centre, radii along the ring's side (rx) and front (rz) axes, bone weights, colour. */
interface Ring {
  c: V3;
  rx: number;
  rz: number;
  w: Array<[number, number]>;
}

/** One closed tube: rings along a centre line (ends closed by a point each), side reference, colour. */
interface Tube {
  rings: Ring[];
  side: V3;
  color: THREE.Color;
}

/** Rings between key rings: centres, radii and weights interpolated (Catmull–Rom for centres and radii). */
function sample(keys: Ring[], perSpan: number | number[]): Ring[] {
  const out: Ring[] = [];
  const cr = (p0: number, p1: number, p2: number, p3: number, t: number) =>
    0.5 * (2 * p1 + (-p0 + p2) * t + (2 * p0 - 5 * p1 + 4 * p2 - p3) * t * t + (-p0 + 3 * p1 - 3 * p2 + p3) * t * t * t);
  for (let i = 0; i + 1 < keys.length; i++) {
    const k0 = keys[Math.max(0, i - 1)], k1 = keys[i], k2 = keys[i + 1], k3 = keys[Math.min(keys.length - 1, i + 2)];
    const n = Array.isArray(perSpan) ? perSpan[i] : perSpan;
    for (let s = 0; s < n; s++) {
      const t = s / n;
      const c: V3 = [0, 1, 2].map((a) => cr(k0.c[a], k1.c[a], k2.c[a], k3.c[a], t)) as V3;
      const rx = Math.max(cr(k0.rx, k1.rx, k2.rx, k3.rx, t), 0);
      const rz = Math.max(cr(k0.rz, k1.rz, k2.rz, k3.rz, t), 0);
      const w = new Map<number, number>();
      for (const [b, x] of k1.w) w.set(b, (w.get(b) ?? 0) + x * (1 - t));
      for (const [b, x] of k2.w) w.set(b, (w.get(b) ?? 0) + x * t);
      out.push({ c, rx, rz, w: [...w.entries()].filter(([, x]) => x > 1e-6) });
    }
  }
  out.push(keys[keys.length - 1]);
  return out;
}

/** Key rings closing a tube's end with a rounded cap: `n` rings on a quarter ellipse beyond `end` along `dir`. */
function cap(end: Ring, dir: V3, depth: number, n: number): Ring[] {
  const rings: Ring[] = [];
  for (let i = 1; i <= n; i++) {
    const a = (i / (n + 1)) * (Math.PI / 2);
    rings.push({ c: add(end.c, scale(dir, Math.sin(a) * depth)), rx: end.rx * Math.cos(a), rz: end.rz * Math.cos(a), w: end.w });
  }
  return rings;
}

/** Rigid weight on one bone. */
const on = (b: number): Array<[number, number]> => [[b, 1]];
/** Blend of two bones, `t` on the second. */
const blend = (a: number, b: number, t: number): Array<[number, number]> => [[a, 1 - t], [b, t]];

/** The mannequin's tubes in the bind pose (metres, for bone lengths `L`, hips at the origin). */
export function buildTubes(L: Float64Array, colors: MannequinColors, detail = 1): Tube[] {
  // Rings per span and per cap at this level of detail.
  const d = (n: number) => Math.max(1, Math.round(n * detail));
  const ds = (n: number | number[]) => (Array.isArray(n) ? n.map(d) : d(n));
  const P = bindPoints(L);
  const s = (L[J.LeftLeg] + L[J.LeftFoot]) / CANONICAL_LEG || 1; // size relative to the canonical body
  const up: V3 = v(0, 1, 0), down: V3 = v(0, -1, 0), fwd: V3 = v(0, 0, 1), back: V3 = v(0, 0, -1);
  const tubes: Tube[] = [];
  const ring = (c: V3, rx: number, rz: number, w: Array<[number, number]>): Ring => ({ c, rx: rx * s, rz: rz * s, w });

  // Torso: pelvis → waist → chest → shoulder yoke, one tube up the spine.
  {
    const hip = P[J.Hips], sp = P[J.Spine], sp1 = P[J.Spine1], neck = P[J.Neck];
    const hipY = P[J.LeftUpLeg][1];
    const yoke = add(neck, v(0, 0.045 * s, -0.012 * s));
    const keys: Ring[] = [
      ring(v(0, hipY - 0.075 * s, -0.01 * s), 0.1, 0.075, on(J.Hips)),
      ring(v(0, hipY - 0.01 * s, -0.012 * s), 0.158, 0.1, on(J.Hips)),
      ring(add(hip, v(0, 0.02 * s, -0.01 * s)), 0.155, 0.1, on(J.Hips)),
      ring(lerp3(hip, sp, 0.75), 0.135, 0.09, blend(J.Hips, J.Spine, 0.35)),
      ring(lerp3(sp, sp1, 0.35), 0.128, 0.088, blend(J.Spine, J.Spine1, 0.15)),
      ring(add(lerp3(sp, sp1, 0.9), v(0, 0, 0.008 * s)), 0.145, 0.1, blend(J.Spine, J.Spine1, 0.7)),
      ring(add(lerp3(sp1, neck, 0.5), v(0, 0, 0.012 * s)), 0.16, 0.105, on(J.Spine1)),
      ring(add(lerp3(sp1, neck, 0.95), v(0, 0, 0.004 * s)), 0.172, 0.1, on(J.Spine1)),
      ring(yoke, 0.17, 0.085, on(J.Spine1)),
    ];
    const rings = sample(keys, ds(4));
    const top = cap(rings[rings.length - 1], up, 0.05 * s, d(5));
    const bottom = cap(rings[0], down, 0.045 * s, d(4)).reverse();
    tubes.push({ rings: [...bottom, ...rings, ...top], side: v(1, 0, 0), color: colors.body });
  }

  // Neck: from inside the yoke to under the head.
  {
    const neck = P[J.Neck], n1 = P[J.Neck1], head = P[J.Head];
    const keys: Ring[] = [
      ring(add(neck, v(0, 0.01 * s, -0.01 * s)), 0.06, 0.058, on(J.Neck)),
      ring(lerp3(neck, n1, 0.8), 0.05, 0.05, blend(J.Neck, J.Neck1, 0.4)),
      ring(lerp3(n1, head, 0.45), 0.046, 0.048, on(J.Neck1)),
    ];
    const rings = sample(keys, ds(4));
    tubes.push({ rings: [...cap(rings[0], down, 0.02 * s, d(2)).reverse(), ...rings, ...cap(rings[rings.length - 1], up, 0.02 * s, d(2))], side: v(1, 0, 0), color: colors.body });
  }

  // Head: an egg, a little forward of the neck, the jaw narrower.
  {
    const head = P[J.Head], top = P[J.Head_end];
    const centre = add(lerp3(head, top, 0.15), v(0, 0, 0.018 * s));
    const ry = 0.112 * s;
    const keys: Ring[] = [];
    const n = Math.max(8, Math.round(14 * detail));
    for (let i = 1; i < n; i++) {
      const a = (i / n) * Math.PI; // 0 = chin, π = crown
      const y = -Math.cos(a) * ry;
      const jaw = 1 - 0.18 * (1 - smoothstep(-1, 0.1, -Math.cos(a))); // narrower towards the chin
      const r = Math.sin(a);
      keys.push({ c: add(centre, v(0, y, (1 - jaw) * 0.03 * s)), rx: 0.078 * s * r * jaw, rz: 0.094 * s * r, w: on(J.Head) });
    }
    tubes.push({ rings: keys, side: v(1, 0, 0), color: colors.body });
  }

  for (const side of ['Left', 'Right'] as const) {
    const k = (name: string) => J[`${side}${name}` as keyof typeof J];
    const color = side === 'Left' ? colors.left : colors.right;
    const sx = side === 'Left' ? 1 : -1;

    // Leg: hip ball → thigh → knee → calf → ankle.
    {
      const hip = P[k('UpLeg')], knee = P[k('Leg')], ankle = P[k('Foot')];
      const T = k('UpLeg'), S = k('Leg');
      const keys: Ring[] = [
        ring(add(hip, v(-0.01 * s * sx, 0.015 * s, 0)), 0.082, 0.085, on(T)),
        ring(lerp3(hip, knee, 0.3), 0.078, 0.08, on(T)),
        ring(lerp3(hip, knee, 0.72), 0.06, 0.062, on(T)),
        ring(add(lerp3(hip, knee, 0.92), v(0, 0, 0.004 * s)), 0.05, 0.052, blend(T, S, 0.2)),
        ring(add(knee, v(0, 0, 0.004 * s)), 0.048, 0.05, blend(T, S, 0.5)),
        ring(lerp3(knee, ankle, 0.1), 0.046, 0.048, blend(T, S, 0.85)),
        ring(add(lerp3(knee, ankle, 0.3), v(0, 0, -0.01 * s)), 0.052, 0.056, on(S)),
        ring(lerp3(knee, ankle, 0.75), 0.036, 0.038, on(S)),
        ring(lerp3(knee, ankle, 0.98), 0.031, 0.033, on(S)),
      ];
      const rings = sample(keys, ds([4, 4, 3, 3, 3, 3, 4, 3]));
      tubes.push({ rings: [...cap(rings[0], up, 0.06 * s, d(4)).reverse(), ...rings, ...cap(rings[rings.length - 1], down, 0.03 * s, d(3))], side: v(1, 0, 0), color });
    }

    // Foot: heel → instep → ball → toe tip, the sole flat on the ground when planted.
    {
      const ankle = P[k('Foot')], ball = P[k('ToeBase')], tip = P[k('ToeBase_end')];
      const F = k('Foot'), T = k('ToeBase');
      const soleY = ankle[1] - 0.07 * s; // the ankle point stands about 7 cm above the floor in the corpus
      const keys: Ring[] = [
        ring(v(ankle[0], soleY + 0.035 * s, ankle[2] - 0.045 * s), 0.028, 0.03, on(F)),
        ring(v(ankle[0], soleY + 0.042 * s, ankle[2] + 0.0 * s), 0.036, 0.042, on(F)),
        ring(v(ankle[0], soleY + 0.033 * s, lerp3(ankle, ball, 0.55)[2]), 0.042, 0.033, on(F)),
        ring(v(ball[0], soleY + 0.022 * s, ball[2]), 0.046, 0.022, blend(F, T, 0.5)),
        ring(v(tip[0], soleY + 0.015 * s, lerp3(ball, tip, 0.75)[2]), 0.038, 0.015, on(T)),
      ];
      const rings = sample(keys, ds(4));
      tubes.push({ rings: [...cap(rings[0], back, 0.03 * s, d(4)).reverse(), ...rings, ...cap(rings[rings.length - 1], fwd, 0.025 * s, d(3))], side: v(1, 0, 0), color });
    }

    // Arm: shoulder ball → upper arm → elbow → forearm → wrist.
    {
      const sh = P[k('Arm')], el = P[k('ForeArm')], wr = P[k('Hand')];
      const U = k('Arm'), F = k('ForeArm'), H = k('Hand');
      const dir = unit(sub(el, sh));
      const keys: Ring[] = [
        ring(sh, 0.054, 0.054, on(U)),
        ring(lerp3(sh, el, 0.35), 0.048, 0.05, on(U)),
        ring(lerp3(sh, el, 0.85), 0.038, 0.04, blend(U, F, 0.15)),
        ring(el, 0.035, 0.037, blend(U, F, 0.5)),
        ring(lerp3(el, wr, 0.15), 0.037, 0.039, blend(U, F, 0.85)),
        ring(lerp3(el, wr, 0.4), 0.038, 0.04, on(F)),
        ring(lerp3(el, wr, 0.95), 0.026, 0.03, blend(F, H, 0.2)),
      ];
      const rings = sample(keys, ds([4, 4, 3, 3, 3, 4]));
      tubes.push({ rings: [...cap(rings[0], scale(dir, -1), 0.035 * s, d(4)).reverse(), ...rings, ...cap(rings[rings.length - 1], dir, 0.02 * s, d(2))], side: v(0, 0, 1), color });
    }

    // Hand: a mitten, flat, its width along the body's front in the bind pose (palm to the thigh when hanging).
    {
      const wr = P[k('Hand')], end = P[k('Hand_end')];
      const F = k('ForeArm'), H = k('Hand');
      const dir = unit(sub(end, wr));
      const keys: Ring[] = [
        ring(wr, 0.027, 0.02, blend(F, H, 0.5)),
        ring(add(wr, scale(dir, 0.05 * s)), 0.04, 0.021, on(H)),
        ring(lerp3(wr, end, 0.8), 0.038, 0.017, on(H)),
        ring(lerp3(wr, end, 1.05), 0.03, 0.013, on(H)),
      ];
      const rings = sample(keys, ds(3));
      tubes.push({ rings: [...cap(rings[0], scale(dir, -1), 0.012 * s, d(2)).reverse(), ...rings, ...cap(rings[rings.length - 1], dir, 0.022 * s, d(3))], side: v(0, 0, 1), color });
    }
  }
  return tubes;
}

/** One BufferGeometry (positions, normals, colours, skin indices and weights) from the tubes, `SEGMENTS` vertices around each ring. */
export function tubeGeometry(tubes: Tube[], SEGMENTS = 24): THREE.BufferGeometry {
  let vertexCount = 0;
  for (const t of tubes) vertexCount += t.rings.length * SEGMENTS + 2;
  const pos = new Float32Array(vertexCount * 3);
  const col = new Float32Array(vertexCount * 3);
  const skinIndex = new Uint16Array(vertexCount * 4);
  const skinWeight = new Float32Array(vertexCount * 4);
  const index: number[] = [];
  let n = 0;
  const put = (p: V3, w: Array<[number, number]>, color: THREE.Color) => {
    pos.set(p, n * 3);
    color.toArray(col, n * 3);
    const top = [...w].sort((a, b) => b[1] - a[1]).slice(0, 4);
    const total = top.reduce((acc, [, x]) => acc + x, 0);
    top.forEach(([b, x], i) => {
      skinIndex[n * 4 + i] = b;
      skinWeight[n * 4 + i] = x / total;
    });
    return n++;
  };
  for (const tube of tubes) {
    const R = tube.rings;
    const first = n;
    for (let i = 0; i < R.length; i++) {
      // The ring's axes: the tangent of the centre line, the side reference made perpendicular, and front.
      const t = unit(sub(R[Math.min(i + 1, R.length - 1)].c, R[Math.max(i - 1, 0)].c));
      const x = unit(sub(tube.side, scale(t, dot(tube.side, t))));
      const z = cross(x, t);
      for (let k = 0; k < SEGMENTS; k++) {
        const a = (k / SEGMENTS) * Math.PI * 2;
        put(add(R[i].c, add(scale(x, Math.cos(a) * R[i].rx), scale(z, Math.sin(a) * R[i].rz))), R[i].w, tube.color);
      }
    }
    // Poles just beyond the first and last rings (where a round cap through those rings would end).
    const t0 = unit(sub(R[0].c, R[1].c)), t1 = unit(sub(R[R.length - 1].c, R[R.length - 2].c));
    const gap0 = (R[0].rx + R[0].rz) * 0.08, gap1 = (R[R.length - 1].rx + R[R.length - 1].rz) * 0.08;
    const south = put(add(R[0].c, scale(t0, gap0)), R[0].w, tube.color);
    const north = put(add(R[R.length - 1].c, scale(t1, gap1)), R[R.length - 1].w, tube.color);
    const at = (i: number, k: number) => first + i * SEGMENTS + (k % SEGMENTS);
    for (let i = 0; i + 1 < R.length; i++) {
      for (let k = 0; k < SEGMENTS; k++) {
        // Counter-clockwise seen from outside (x → z turns about the tangent t, rings go along t).
        index.push(at(i, k), at(i + 1, k), at(i, k + 1), at(i + 1, k), at(i + 1, k + 1), at(i, k + 1));
      }
    }
    for (let k = 0; k < SEGMENTS; k++) {
      index.push(south, at(0, k), at(0, k + 1));
      index.push(north, at(R.length - 1, k + 1), at(R.length - 1, k));
    }
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setIndex(index);
  geometry.setAttribute('position', new THREE.BufferAttribute(pos, 3));
  geometry.setAttribute('color', new THREE.BufferAttribute(col, 3));
  geometry.setAttribute('skinIndex', new THREE.Uint16BufferAttribute(skinIndex, 4));
  geometry.setAttribute('skinWeight', new THREE.BufferAttribute(skinWeight, 4));
  geometry.computeVertexNormals();
  return geometry;
}

// ---------------------------------------------------------------- the character

/** Bone lengths of the canonical skeleton (training/mocap/canonical_skeleton.json), metres, CANONICAL_JOINTS order. */
const CANONICAL_LENGTHS = [0, 0.141, 0.399, 0.43, 0.118, 0.059, 0.141, 0.399, 0.43, 0.118, 0.059, 0.116, 0.115, 0.117, 0.095, 0.096, 0.098, 0.192, 0.294, 0.187, 0.131, 0.192, 0.294, 0.187, 0.131];

/** A mannequin of the canonical proportions standing in its bind pose (to compile its shader before any motion). */
export function restMannequin(options: MannequinOptions = {}): Mannequin {
  const points = Float32Array.from(bindPoints(Float64Array.from(CANONICAL_LENGTHS)).flat());
  return new Mannequin(points, 1, options);
}

/**
 * Studio light baked into a matcap (a lit sphere seen from the camera), for software GL where every lit pixel
 * costs: key from the upper left, soft fill from above, a cool rim and a little gloss, as the stick figure's
 * shader (figure.ts). Made once, shared.
 */
let studioMatcap: THREE.DataTexture | null = null;
export function matcap(): THREE.DataTexture {
  if (studioMatcap) return studioMatcap;
  const N = 128;
  const data = new Uint8Array(N * N * 4);
  const key = unit(v(-0.42, 0.62, 0.66)), half = unit(add(key, v(0, 0, 1)));
  for (let j = 0; j < N; j++) {
    for (let i = 0; i < N; i++) {
      const x = ((i + 0.5) / N) * 2 - 1, y = ((j + 0.5) / N) * 2 - 1;
      const z = Math.sqrt(Math.max(0, 1 - x * x - y * y));
      const n: V3 = unit(v(x, y, z));
      const diffuse = Math.max(dot(n, key), 0);
      const fill = 0.5 + 0.5 * n[1];
      const edge = 1 - Math.max(n[2], 0);
      const spec = Math.max(dot(n, half), 0) ** 24;
      const light = 0.3 + 0.2 * fill + 0.62 * diffuse;
      const rim: V3 = [0.45, 0.55, 0.9];
      const o = (j * N + i) * 4;
      for (let c = 0; c < 3; c++) data[o + c] = Math.round(255 * Math.min(1, light * 0.92 + rim[c] * edge * edge * 0.22 + spec * 0.25));
      data[o + 3] = 255;
    }
  }
  studioMatcap = new THREE.DataTexture(data, N, N, THREE.RGBAFormat);
  studioMatcap.magFilter = THREE.LinearFilter;
  studioMatcap.minFilter = THREE.LinearFilter;
  studioMatcap.needsUpdate = true;
  return studioMatcap;
}

export interface MannequinOptions {
  colors?: MannequinColors;
  /**
   * Lit by the scene's lights (MeshStandardMaterial, casting shadows), for a GPU; otherwise shaded by a baked
   * studio matcap, a texture lookup per pixel (software GL).
   */
  lit?: boolean;
}

/**
 * The last few surfaces made, by proportions (to the millimetre), colours and detail: every model's motion is on
 * the canonical skeleton, so a new stream (a restart, a new seed) finds its surface here instead of building it
 * again on the page's thread (tens of milliseconds). A geometry shared by two meshes may be disposed by one:
 * three.js uploads it again for the other.
 */
const GEOMETRIES = new Map<string, THREE.BufferGeometry>();
function cachedGeometry(lengths: Float64Array, colors: MannequinColors, lit: boolean): THREE.BufferGeometry {
  const key = [lit, colors.body.getHex(), colors.left.getHex(), colors.right.getHex(), ...Array.from(lengths, (l) => Math.round(l * 1000))].join(',');
  let geometry = GEOMETRIES.get(key);
  if (!geometry) {
    // Software GL pays for every triangle (figure.ts): there, half the rings and 14 vertices around each.
    geometry = lit ? tubeGeometry(buildTubes(lengths, colors)) : tubeGeometry(buildTubes(lengths, colors, 0.5), 14);
    if (GEOMETRIES.size >= 4) GEOMETRIES.delete(GEOMETRIES.keys().next().value!);
  }
  GEOMETRIES.delete(key);
  GEOMETRIES.set(key, geometry); // most recent last
  return geometry;
}

/** The mannequin for a motion's canonical points: a SkinnedMesh posed with `pose(points)`. */
export class Mannequin {
  readonly mesh: THREE.SkinnedMesh;
  readonly skeleton: THREE.Skeleton;
  readonly vertexCount: number;
  private readonly solver = new BoneSolver();
  private readonly material: THREE.MeshStandardMaterial | THREE.MeshMatcapMaterial;

  /** `points`: the motion's canonical points, frames × 25 × 3 (for its bone lengths). */
  constructor(points: Float32Array, frames: number, { colors = MANNEQUIN_COLORS, lit = true }: MannequinOptions = {}) {
    const lengths = measureBones(points, frames);
    const bind = bindPoints(lengths);
    const geometry = cachedGeometry(lengths, colors, lit);
    this.vertexCount = geometry.getAttribute('position').count;

    // Bind rotations: the same solver on the bind pose.
    const bindSolver = new BoneSolver();
    bindSolver.solve(bind.flat());
    const bones: THREE.Bone[] = [];
    const inverses: THREE.Matrix4[] = [];
    for (let k = 0; k < BONES; k++) {
      const bone = new THREE.Bone();
      bone.name = CANONICAL_JOINTS[k];
      // Posed by writing matrixWorld directly (bones are not in the scene graph, nothing recomputes them).
      bone.matrixAutoUpdate = false;
      bone.matrixWorldAutoUpdate = false;
      bones.push(bone);
      inverses.push(new THREE.Matrix4().fromArray(bindSolver.matrices, k * 16).invert());
    }
    this.skeleton = new THREE.Skeleton(bones, inverses);
    this.material = lit
      ? new THREE.MeshStandardMaterial({ vertexColors: true, roughness: 0.62, metalness: 0.0 })
      : new THREE.MeshMatcapMaterial({ vertexColors: true, matcap: matcap() });
    this.mesh = new THREE.SkinnedMesh(geometry, this.material);
    this.mesh.bindMode = THREE.DetachedBindMode;
    this.mesh.bind(this.skeleton, new THREE.Matrix4());
    this.mesh.frustumCulled = false; // its bounds move with the bones, which three.js would not follow
    this.mesh.castShadow = lit;
    this.mesh.receiveShadow = false;
    this.mesh.name = 'mannequin';
    this.pose(points.subarray(0, BONES * 3));
  }

  /** Poses the mannequin from one frame of canonical points (25 × 3, world). */
  pose(points: ArrayLike<number>): void {
    this.solver.solve(points);
    const M = this.solver.matrices;
    const bones = this.skeleton.bones;
    for (let k = 0; k < BONES; k++) {
      const e = bones[k].matrixWorld.elements;
      for (let i = 0; i < 16; i++) e[i] = M[k * 16 + i];
    }
  }

  /** See-through (the stick figure inside shows) or solid. */
  setSeeThrough(on: boolean): void {
    const m = this.material;
    if (m.transparent === on) return;
    m.transparent = on;
    m.opacity = on ? 0.38 : 1;
    m.depthWrite = !on;
    m.needsUpdate = true;
  }

  dispose(): void {
    this.mesh.geometry.dispose();
    this.material.dispose();
    this.skeleton.dispose();
  }
}
