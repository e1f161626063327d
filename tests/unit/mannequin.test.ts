// The project's own character (web/viewer/mannequin.ts, character.ts): its geometry and skin, and the bones
// following a real captured clip.
import { describe, expect, it } from 'vitest';
import * as THREE from 'three';
import { parseAMC } from '../../web/motion/asfamc';
import { CANONICAL_JOINTS, CANONICAL_PARENTS, mapSkeleton, toCanonical } from '../../web/motion/skeletonMap';
import type { Motion } from '../../web/motion/types';
import { CharacterDriver, canonicalPoints, isCanonical } from '../../web/viewer/character';
import { BONES, bindPoints, BoneSolver, Mannequin, measureBones, restMannequin } from '../../web/viewer/mannequin';
import { readCorpus } from './corpus';

const K = CANONICAL_JOINTS.length;

/** CMU 16_11 (a walk, ASF/AMC), 240 frames. */
function clip(): Motion {
  const m = parseAMC(readCorpus('cmu/amc/16_11.amc.gz'), readCorpus('cmu/asf/16.asf'));
  const frames = Math.min(m.frames, 240);
  return { ...m, frames, positions: m.positions.slice(0, frames * m.joints.length * 3) };
}

/** The clip's canonical points at its own scale, as the viewer finds them. */
function canonicalOf(m: Motion): Float32Array {
  return toCanonical(m, { ...mapSkeleton(m, 1), scale: 1 });
}

/** Distance from p to the segment a–b. */
function toSegment(p: THREE.Vector3, a: THREE.Vector3, b: THREE.Vector3): number {
  const ab = b.clone().sub(a);
  const t = Math.min(Math.max(p.clone().sub(a).dot(ab) / Math.max(ab.lengthSq(), 1e-12), 0), 1);
  return p.distanceTo(a.clone().addScaledVector(ab, t));
}

describe.each([
  { lit: true, name: 'lit (GPU)' },
  { lit: false, name: 'matcap, fewer triangles (software GL)' },
])('mannequin geometry and skin: $name', ({ lit }) => {
  const mannequin = restMannequin({ lit });
  const geometry = mannequin.mesh.geometry;
  const index = geometry.getAttribute('skinIndex');
  const weight = geometry.getAttribute('skinWeight');
  const count = geometry.getAttribute('position').count;

  it('has one bone per canonical point, named after it', () => {
    expect(mannequin.skeleton.bones.length).toBe(K);
    expect(BONES).toBe(K);
    expect(mannequin.skeleton.bones.map((b) => b.name)).toEqual([...CANONICAL_JOINTS]);
    expect(mannequin.mesh).toBeInstanceOf(THREE.SkinnedMesh);
    expect(mannequin.vertexCount).toBe(count);
    expect(count).toBeGreaterThan(lit ? 5000 : 1500); // smooth, not boxes
  });

  it('binds every vertex: weights sum to 1 on valid bones', () => {
    let worst = 0;
    for (let v = 0; v < count; v++) {
      let sum = 0, bound = 0;
      for (let i = 0; i < 4; i++) {
        const w = weight.getComponent(v, i), b = index.getComponent(v, i);
        expect(w).toBeGreaterThanOrEqual(0);
        if (w > 0) {
          expect(b).toBeLessThan(K);
          bound++;
        }
        sum += w;
      }
      expect(bound, `vertex ${v} has no bone`).toBeGreaterThan(0);
      worst = Math.max(worst, Math.abs(sum - 1));
    }
    expect(worst).toBeLessThan(1e-6);
  });

  it('blends weights across the elbows and knees (no rigid crease)', () => {
    const blended = new Set<string>();
    for (let v = 0; v < count; v++) {
      const bones = [0, 1, 2, 3].filter((i) => weight.getComponent(v, i) > 0.2 && weight.getComponent(v, i) < 0.8).map((i) => CANONICAL_JOINTS[index.getComponent(v, i)]);
      if (bones.length === 2) blended.add(bones.sort().join('+'));
    }
    for (const side of ['Left', 'Right']) {
      expect(blended).toContain([`${side}Leg`, `${side}UpLeg`].sort().join('+'));
      expect(blended).toContain([`${side}Arm`, `${side}ForeArm`].sort().join('+'));
    }
  });

  it('has closed, outward-facing surfaces: the enclosed volume is positive and body-sized', () => {
    // Divergence theorem over the triangles: positive only if every tube's triangles face outwards.
    const pos = geometry.getAttribute('position');
    const ix = geometry.index!;
    let volume = 0;
    const a = new THREE.Vector3(), b = new THREE.Vector3(), c = new THREE.Vector3();
    for (let t = 0; t < ix.count; t += 3) {
      a.fromBufferAttribute(pos, ix.getX(t));
      b.fromBufferAttribute(pos, ix.getX(t + 1));
      c.fromBufferAttribute(pos, ix.getX(t + 2));
      volume += a.dot(b.clone().cross(c)) / 6;
    }
    // A 1.7 m person is about 0.065 m³; the tubes overlap a little at the joints.
    expect(volume).toBeGreaterThan(0.04);
    expect(volume).toBeLessThan(0.11);
  });
});

describe('mannequin posed from a captured clip (CMU 16_11)', () => {
  const motion = clip();
  const points = canonicalOf(motion);
  const driver = CharacterDriver.for(motion)!;

  it('maps the clip and builds its character', () => {
    expect(driver).not.toBeNull();
    expect(isCanonical(motion.joints)).toBe(false);
  });

  it('puts every bone on its canonical point within 1 mm', () => {
    const bones = driver.mannequin.skeleton.bones;
    let worst = 0;
    for (const f of [0, 57, 131, 239]) {
      driver.update(f, f, 0);
      for (let k = 0; k < K; k++) {
        const e = bones[k].matrixWorld.elements, o = (f * K + k) * 3;
        worst = Math.max(worst, Math.hypot(e[12] - points[o], e[13] - points[o + 1], e[14] - points[o + 2]));
      }
    }
    expect(worst).toBeLessThan(0.001);
  });

  it('gives bones pure rotations aiming at their child point', () => {
    driver.update(100, 100, 0);
    const bones = driver.mannequin.skeleton.bones;
    for (let k = 0; k < K; k++) {
      const m = bones[k].matrixWorld;
      const x = new THREE.Vector3(), y = new THREE.Vector3(), z = new THREE.Vector3();
      m.extractBasis(x, y, z);
      expect(x.length()).toBeCloseTo(1, 6);
      expect(y.length()).toBeCloseTo(1, 6);
      expect(x.dot(y)).toBeCloseTo(0, 6);
      expect(m.determinant()).toBeCloseTo(1, 6);
      const child = CANONICAL_PARENTS.indexOf(k);
      if (child >= 0 && k !== 0 && k !== 13) {
        const o = 100 * K * 3;
        const d = new THREE.Vector3(points[o + child * 3] - points[o + k * 3], points[o + child * 3 + 1] - points[o + k * 3 + 1], points[o + child * 3 + 2] - points[o + k * 3 + 2]).normalize();
        expect(y.dot(d), CANONICAL_JOINTS[k]).toBeGreaterThan(0.9999);
      }
    }
  });

  it('keeps the skin on the skeleton: every skinned vertex lies near a bone of the posed clip', () => {
    const mesh = driver.mannequin.mesh;
    const pos = mesh.geometry.getAttribute('position');
    const p = new THREE.Vector3();
    const seg: Array<[THREE.Vector3, THREE.Vector3]> = [];
    let worst = 0;
    for (const f of [20, 90, 170]) {
      driver.update(f, f, 0);
      seg.length = 0;
      const at = (k: number) => new THREE.Vector3().fromArray(points, (f * K + k) * 3);
      for (let k = 1; k < K; k++) seg.push([at(CANONICAL_PARENTS[k]), at(k)]);
      for (let v = 0; v < pos.count; v += 3) {
        mesh.applyBoneTransform(v, p.fromBufferAttribute(pos, v));
        worst = Math.max(worst, Math.min(...seg.map(([a, b]) => toSegment(p, a, b))));
      }
    }
    // The widest part (the chest) is under 20 cm from the spine; a flipped or twisted-off limb would be far more.
    expect(worst).toBeLessThan(0.2);
  });

  it('leaves every vertex where it was built when posed in its bind pose', () => {
    const lengths = measureBones(points, motion.frames);
    const m = new Mannequin(points, motion.frames);
    m.pose(bindPoints(lengths).flat());
    const pos = m.mesh.geometry.getAttribute('position');
    const p = new THREE.Vector3(), q = new THREE.Vector3();
    let worst = 0;
    for (let v = 0; v < pos.count; v += 7) {
      q.fromBufferAttribute(pos, v);
      m.mesh.applyBoneTransform(v, p.copy(q));
      worst = Math.max(worst, p.distanceTo(q));
    }
    expect(worst).toBeLessThan(1e-6);
    m.dispose();
  });

  it('takes a motion already on the canonical skeleton as it is', () => {
    const canonical: Motion = { fps: motion.fps, frames: motion.frames, joints: [...CANONICAL_JOINTS], parents: [...CANONICAL_PARENTS], positions: points };
    expect(isCanonical(canonical.joints)).toBe(true);
    expect(canonicalPoints(canonical, null)!.points).toBe(points);
    const d = CharacterDriver.for(canonical)!;
    d.update(10, 11, 0.5);
    const hips = d.mannequin.skeleton.bones[0].matrixWorld.elements;
    const o0 = 10 * K * 3, o1 = 11 * K * 3;
    expect(hips[12]).toBeCloseTo((points[o0] + points[o1]) / 2, 6);
    d.dispose();
  });

  it('solves the same rotations for the same pose, whatever came before (no drifting state)', () => {
    const a = new BoneSolver(), b = new BoneSolver();
    const frame = (f: number) => points.subarray(f * K * 3, (f + 1) * K * 3);
    for (let f = 0; f < 200; f += 7) a.solve(frame(f));
    a.solve(frame(150));
    b.solve(frame(150));
    for (let i = 0; i < a.matrices.length; i++) expect(a.matrices[i]).toBeCloseTo(b.matrices[i], 9);
  });
});

describe('skeletons without a character', () => {
  it('has none for a skeleton that is not a humanoid (the stick figure stays), without throwing', () => {
    const snake: Motion = { fps: 30, frames: 2, joints: ['a', 'b', 'c'], parents: [-1, 0, 1], positions: new Float32Array(18).map((_, i) => i * 0.1) };
    expect(CharacterDriver.for(snake)).toBeNull();
  });
});
