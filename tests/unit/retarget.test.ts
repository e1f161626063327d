// retarget.ts: a humanoid motion onto character rigs of five namings (issue 40, "Bring your own character").
// The measures of the "Done when" on each rig × source; docs/models/retarget.md reports the same numbers
// (npm run evaluate:retarget, tests/eval/retarget.eval.ts).
import { beforeAll, describe, expect, it } from 'vitest';
import { CANONICAL_JOINTS, SkeletonMapError, type HumanoidMap } from '../../web/motion/humanoid';
import { quatMultiply, quatRotate, type Quat, type Vec3 } from '../../web/motion/math';
import { mapRig, restPositions, retarget, type CharacterRig, type RetargetResult } from '../../web/motion/retarget';
import { PLANTED_FLOOR, RIGS, buildRig, loadSources, measure, quaterniusRig, type Source } from './retargetCases';

let sources: Source[];
const rigs = RIGS.map((spec) => ({ spec, rig: buildRig(spec) }));
/** The project's CC0 character (../shared/characters/quaternius-human-male.glb), read as a glTF loader gives it. */
const quaternius = quaterniusRig();
const results = new Map<string, RetargetResult>();
const resultOf = (r: number, s: number): RetargetResult => {
  const key = `${r}/${s}`;
  if (!results.has(key)) results.set(key, retarget(sources[s].motion, rigs[r].rig));
  return results.get(key)!;
};

beforeAll(() => {
  sources = loadSources();
});

/** World positions (frames × bones × 3, rig units) by FK of local rotations and root translations from the rig's rest. */
function forwardKinematics(rig: CharacterRig, result: RetargetResult): Float32Array {
  const B = rig.bones.length, F = result.motion.frames;
  const out = new Float32Array(F * B * 3);
  for (let f = 0; f < F; f++) {
    const world: Quat[] = [];
    const pos: Vec3[] = [];
    for (let b = 0; b < B; b++) {
      const o = (f * B + b) * 4;
      const local: Quat = [result.rotations[o], result.rotations[o + 1], result.rotations[o + 2], result.rotations[o + 3]];
      const p = rig.parents[b];
      if (p < 0) {
        world[b] = local;
        pos[b] = b === result.rootBone ? [result.rootTranslations[f * 3], result.rootTranslations[f * 3 + 1], result.rootTranslations[f * 3 + 2]] : rig.restTranslations[b];
      } else {
        world[b] = quatMultiply(world[p], local);
        const d = quatRotate(world[p], rig.restTranslations[b]);
        pos[b] = [pos[p][0] + d[0], pos[p][1] + d[1], pos[p][2] + d[2]];
      }
      out.set(pos[b], (f * B + b) * 3);
    }
  }
  return out;
}

describe('mapRig', () => {
  it.each(rigs.map(({ spec, rig }, i) => [spec.label, i, rig] as const))('maps %s', (_, i, rig) => {
    const map = mapRig(rig);
    const name = (point: string) => rig.bones[map.source[CANONICAL_JOINTS.indexOf(point as never)]];
    const expected = [
      ['LeftUpLeg', 'LeftLeg'], ['mixamorig:LeftUpLeg', 'mixamorig:LeftLeg'], ['thigh_l', 'calf_l'], ['leftUpperLeg', 'leftLowerLeg'], ['UpperLeg_L', 'LowerLeg_L'],
    ][i];
    expect([name('LeftUpLeg'), name('LeftLeg')]).toEqual(expected);
    expect(name('RightArm')).toMatch(/Right|_r$|right|_R$/);
  });

  it('uses a humanoid map the file gives (VRM) as it is; the mapper finds the same bones without it', () => {
    const rig = rigs[3].rig;
    const given: HumanoidMap = rig.humanoid!;
    expect(given.scheme).toBe('VRM file');
    expect(mapRig(rig)).toBe(given);
    const found = mapRig({ ...rig, humanoid: undefined });
    given.source.forEach((bone, k) => bone >= 0 && expect(rig.bones[found.source[k]]).toBe(rig.bones[bone]));
    const broken = { ...given, source: given.source.map((j, k) => (CANONICAL_JOINTS[k] === 'LeftFoot' ? -1 : j)) };
    expect(() => mapRig({ ...rig, humanoid: broken })).toThrow(/no bone for LeftFoot/);
  });

  it('gives the rest pose as FK of the rest rotations and translations', () => {
    const rig: CharacterRig = {
      bones: ['a', 'b', 'c'], parents: [-1, 0, 1],
      restRotations: [[0, Math.SQRT1_2, 0, Math.SQRT1_2], [0, 0, 0, 1], [0, 0, 0, 1]],
      restTranslations: [[1, 0, 0], [0, 0, 2], [0, 1, 0]],
    };
    // a at (1,0,0) turned 90° about y: its +z child lies along +x.
    const expected = [1, 0, 0, 3, 0, 0, 3, 1, 0];
    restPositions(rig).forEach((v, i) => expect(v).toBeCloseTo(expected[i], 6));
  });
});

describe('retarget: bad input', () => {
  const rig = rigs[0].rig;
  it('refuses a rig that is not a humanoid, naming what is missing', () => {
    const legless: CharacterRig = {
      bones: ['root', 'spine', 'head'], parents: [-1, 0, 1],
      restRotations: [[0, 0, 0, 1], [0, 0, 0, 1], [0, 0, 0, 1]], restTranslations: [[0, 1, 0], [0, 0.5, 0], [0, 0.3, 0]],
    };
    expect(() => retarget(sources[0].motion, legless)).toThrow(SkeletonMapError);
    expect(() => retarget(sources[0].motion, legless)).toThrow(/legs/);
  });
  it('refuses malformed rig data with a short message', () => {
    const cases: Array<[CharacterRig, RegExp]> = [
      [{ ...rig, parents: rig.parents.slice(1) }, /parents for \d+ bones/],
      [{ ...rig, parents: rig.parents.map((p, b) => (b === 3 ? 7 : p)) }, /parents must come before children/],
      [{ ...rig, restTranslations: rig.restTranslations.map((t, b) => (b === 2 ? [NaN, 0, 0] : t)) }, /not a finite number/],
      [{ ...rig, bones: ['a'], parents: [-1], restRotations: [[0, 0, 0, 1]], restTranslations: [[0, 0, 0]] }, /1 bone,/],
    ];
    for (const [bad, message] of cases) {
      let error: unknown;
      try {
        retarget(sources[0].motion, bad);
      } catch (e) {
        error = e;
      }
      expect(error).toBeInstanceOf(SkeletonMapError);
      expect((error as Error).message).toMatch(message);
      expect((error as Error).message.length).toBeLessThanOrEqual(300);
    }
  });
  it('refuses a motion without frames', () => {
    expect(() => retarget({ ...sources[0].motion, frames: 0, positions: new Float32Array(0) }, rig)).toThrow(/frames/);
  });
});

describe('retarget: the result drives the rig', () => {
  it.each(rigs.map(({ spec }, i) => [spec.label, i] as const))('%s: FK of rotations and root translations from the rest gives the positions; bones keep their lengths', (_, r) => {
    const { rig } = rigs[r];
    const result = resultOf(r, 0);
    const B = rig.bones.length;
    expect(result.motion.joints).toEqual(rig.bones);
    expect(result.motion.parents).toEqual(rig.parents);
    expect(result.rotations.length).toBe(result.motion.frames * B * 4);
    expect(result.rootTranslations.length).toBe(result.motion.frames * 3);
    const fk = forwardKinematics(rig, result);
    const height = result.mapping.height;
    let worst = 0;
    for (let i = 0; i < fk.length; i++) worst = Math.max(worst, Math.abs(fk[i] - result.motion.positions[i] * result.unitsPerMetre));
    expect(worst / height).toBeLessThan(1e-4);
    let lengthError = 0;
    for (let f = 0; f < result.motion.frames; f += 7) {
      for (let b = 1; b < B; b++) {
        const p = rig.parents[b];
        const d = [0, 1, 2].map((c) => result.motion.positions[(f * B + b) * 3 + c] - result.motion.positions[(f * B + p) * 3 + c]);
        const rest = Math.hypot(...rig.restTranslations[b]) / result.unitsPerMetre;
        lengthError = Math.max(lengthError, Math.abs(Math.hypot(...d) - rest));
      }
    }
    expect(lengthError).toBeLessThan(1e-4);
  });

  it('moves the root the hips hang from when a helper root comes first, and keeps the helper at rest', () => {
    const base = rigs[0].rig;
    // A helper bone (an IK target, say) as a root of its own, before the skeleton's root.
    const rig: CharacterRig = {
      bones: ['ik_target', ...base.bones], parents: [-1, ...base.parents.map((p) => (p < 0 ? -1 : p + 1))],
      restRotations: [[0, 0, 0, 1], ...base.restRotations], restTranslations: [[0.5, 0, 0.5], ...base.restTranslations],
    };
    const result = retarget(sources[0].motion, rig);
    expect(result.rootBone).toBe(1);
    const fk = forwardKinematics(rig, result);
    let worst = 0;
    for (let i = 0; i < fk.length; i++) worst = Math.max(worst, Math.abs(fk[i] - result.motion.positions[i]));
    expect(worst).toBeLessThan(1e-4);
    const B = rig.bones.length, last = result.motion.frames - 1;
    expect(Array.from(result.motion.positions.subarray(last * B * 3, last * B * 3 + 3))).toEqual([0.5, 0, 0.5]);
    // The rest of the character moves as it does without the helper.
    const plain = resultOf(0, 0).motion.positions;
    expect(Math.abs(result.motion.positions[(last * B + 1) * 3] - plain[last * (B - 1) * 3])).toBeLessThan(1e-5);
  });

  it('retargets a single frame, and uses the contacts a motion carries', () => {
    const model = sources[3].motion;
    const one = { ...model, frames: 1, positions: model.positions.slice(0, CANONICAL_JOINTS.length * 3), contacts: model.contacts!.slice(0, 2) };
    const result = retarget(one, rigs[1].rig);
    expect(result.motion.frames).toBe(1);
    expect(result.motion.positions.every(Number.isFinite)).toBe(true);
    const full = retarget(model, rigs[1].rig);
    expect(Array.from(full.contacts)).toEqual(Array.from(model.contacts!));
    expect(full.motion.contacts).toBe(full.contacts);
  });

  it('a live window retargeted with the whole stream\'s calibration poses its frames as the whole stream\'s retargeting does', () => {
    const stream = sources[3].motion;
    const J = stream.joints.length, B = rigs[4].rig.bones.length;
    const whole = retarget(stream, rigs[4].rig, { footIK: false });
    const from = 40, frames = 31;
    const window = { ...stream, frames, positions: stream.positions.slice(from * J * 3, (from + frames) * J * 3), contacts: stream.contacts!.slice(from * 2, (from + frames) * 2) };
    const same = retarget(window, rigs[4].rig, { footIK: false, calibration: whole.calibration });
    const own = retarget(window, rigs[4].rig, { footIK: false });
    const gap = (r: RetargetResult) => {
      let worst = 0;
      for (let i = 0; i < frames * B * 3; i++) worst = Math.max(worst, Math.abs(r.motion.positions[i] - whole.motion.positions[from * B * 3 + i]));
      return worst;
    };
    expect(gap(same)).toBeLessThan(1e-5);
    // Measured on the window alone, the numbers differ (here the feet's slopes and the ankles' height), and so does the pose.
    expect(gap(own)).toBeGreaterThan(1e-3);
    expect(() => retarget(window, rigs[4].rig, { calibration: { ...whole.calibration, footSlopes: [0] } })).toThrow(/calibration/);
  });

  it('stands a motion whose floor is not y = 0 on it', () => {
    const walk = sources[0].motion;
    const base = retarget(walk, rigs[2].rig);
    for (const lift of [0.3, -0.2]) {
      const moved = { ...walk, positions: walk.positions.map((v, i) => (i % 3 === 1 ? v + lift : v)) };
      const result = retarget(moved, rigs[2].rig);
      let worst = 0, sum = 0;
      for (let i = 0; i < base.motion.positions.length; i++) {
        const d = Math.abs(result.motion.positions[i] - base.motion.positions[i]);
        worst = Math.max(worst, d);
        sum += d;
      }
      // The same up to rounding (the leg IK magnifies it where a leg is at full stretch).
      expect(sum / base.motion.positions.length).toBeLessThan(1e-5);
      expect(worst).toBeLessThan(0.005);
    }
  });

  it('a live stream retargeted a frame at a time over the last 31 frames, with the first calibration, follows the whole retargeting', () => {
    // As the viewer does live: each new frame retargeted with 30 frames before it (planted feet carry over).
    const stream = sources[3].motion;
    const J = stream.joints.length, B = quaternius.bones.length;
    const whole = retarget(stream, quaternius);
    let worst = 0;
    for (let end = 31; end <= stream.frames; end += 3) {
      const from = end - 31;
      const window = { ...stream, frames: 31, positions: stream.positions.slice(from * J * 3, end * J * 3), contacts: stream.contacts!.slice(from * 2, end * 2) };
      const live = retarget(window, quaternius, { calibration: whole.calibration }).motion.positions;
      for (let i = 0; i < B * 3; i++) worst = Math.max(worst, Math.abs(live[30 * B * 3 + i] - whole.motion.positions[(end - 1) * B * 3 + i]));
    }
    expect(worst).toBeLessThan(0.01);
  });

  it('detects the rig units: centimetres for the Mixamo rig, metres for the others', () => {
    expect(rigs.map((_, r) => resultOf(r, 0).unitsPerMetre)).toEqual([1, 100, 1, 1, 1]);
    const mixamo = resultOf(1, 0), cmu = resultOf(0, 0);
    // Both stand as tall as their legs say, in metres.
    const hipsHeight = (res: RetargetResult) => res.motion.positions[res.mapping.source[0] * 3 + 1];
    expect(hipsHeight(mixamo) / hipsHeight(cmu)).toBeCloseTo(mixamo.scale / cmu.scale, 1);
  });

  it('does not depend on the rig\'s rest orientations or on which way its rest pose faces', () => {
    const spec = RIGS[3];
    const variants = [
      buildRig(spec),
      buildRig({ ...spec, facingMinusZ: !spec.facingMinusZ }),
      buildRig({ ...spec, orientation: 'random', seed: 11 }),
      buildRig({ ...spec, orientation: 'alongBone', seed: 12 }),
    ];
    const positions = variants.map((rig) => retarget(sources[1].motion, rig).motion.positions);
    for (const p of positions.slice(1)) {
      let worst = 0, sum = 0;
      for (let i = 0; i < p.length; i++) {
        worst = Math.max(worst, Math.abs(p[i] - positions[0][i]));
        sum += Math.abs(p[i] - positions[0][i]);
      }
      // The same up to rounding, which the leg IK magnifies where a leg is at full stretch (a push-off).
      expect(sum / p.length).toBeLessThan(1e-4);
      expect(worst).toBeLessThan(0.01);
    }
  });

  it('follows the source: with the foot IK off, every measured bone points as the source\'s does, but the feet', () => {
    const result = retarget(sources[1].motion, rigs[2].rig, { footIK: false });
    const m = measure(sources[1].motion, result);
    expect(m.angle).toBeLessThan(2);
    expect(m.worstBone).toMatch(/Foot→|Leg→.*Foot/);
  });
});

/** World rotations (frames × bones) by FK of a result's local rotations. */
function worldRotations(rig: CharacterRig, result: RetargetResult): Quat[][] {
  const B = rig.bones.length;
  return Array.from({ length: result.motion.frames }, (_, f) => {
    const world: Quat[] = [];
    for (let b = 0; b < B; b++) {
      const o = (f * B + b) * 4;
      const local: Quat = [result.rotations[o], result.rotations[o + 1], result.rotations[o + 2], result.rotations[o + 3]];
      world[b] = rig.parents[b] < 0 ? local : quatMultiply(world[rig.parents[b]], local);
    }
    return world;
  });
}

const cross = (a: Vec3, b: Vec3): Vec3 => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const angleOf = (a: Vec3, b: Vec3) => (Math.acos(Math.max(-1, Math.min(1, (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (Math.hypot(...a) * Math.hypot(...b))))) * 180) / Math.PI;

describe('retarget: limbs twist as they bend', () => {
  // The bones' directions alone leave a thigh or upper arm free to twist about itself, which a skinned mesh shows.
  // A knee or elbow must bend about its own hinge: the axis that is the hinge in the rig's rest pose (across the limb,
  // square to the body's forward), carried by the thigh's or upper arm's world rotation, against the axis the limb
  // actually bends about on the character (square to its two bones).
  it.each([...rigs.map(({ spec, rig }) => [spec.label.split(' (')[0], rig] as const), ['Quaternius (GLB)', quaternius] as const])('%s', (_, rig) => {
    for (const s of [0, 2]) {
      const result = retarget(sources[s].motion, rig);
      const worlds = worldRotations(rig, result);
      const rest: Quat[] = [];
      rig.parents.forEach((p, b) => (rest[b] = p < 0 ? rig.restRotations[b] : quatMultiply(rest[p], rig.restRotations[b])));
      const R = result.restCanonical, P = result.motion.positions, B = rig.bones.length;
      const restAt = (name: string): Vec3 => { const k = CANONICAL_JOINTS.indexOf(name as never); return [R[k * 3], R[k * 3 + 1], R[k * 3 + 2]]; };
      const sub3 = (a: Vec3, b: Vec3): Vec3 => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
      const forward = cross(sub3(restAt('LeftUpLeg'), restAt('RightUpLeg')), [0, 1, 0]);
      for (const [upper, middle, lower, bendsForward] of [['LeftUpLeg', 'LeftLeg', 'LeftFoot', false], ['RightUpLeg', 'RightLeg', 'RightFoot', false], ['LeftArm', 'LeftForeArm', 'LeftHand', true], ['RightArm', 'RightForeArm', 'RightHand', true]] as const) {
        const [a, b, c] = [upper, middle, lower].map((n) => result.mapping.source[CANONICAL_JOINTS.indexOf(n)]);
        // The rest hinge: across the upper bone, square to the way the lower bone swings (forward for the forearm, back for the shin).
        const swing: Vec3 = bendsForward ? forward : [-forward[0], -forward[1], -forward[2]];
        const hingeRest = cross(sub3(restAt(middle), restAt(upper)), swing);
        const local = quatRotate([-rest[a][0], -rest[a][1], -rest[a][2], rest[a][3]], hingeRest);
        const angles: number[] = [];
        for (let f = 0; f < result.motion.frames; f++) {
          const at = (j: number): Vec3 => [P[(f * B + j) * 3], P[(f * B + j) * 3 + 1], P[(f * B + j) * 3 + 2]];
          const u = sub3(at(b), at(a)), l = sub3(at(c), at(b));
          if (angleOf(u, l) < 30) continue;
          angles.push(angleOf(quatRotate(worlds[f][a], local), cross(u, l)));
        }
        if (angles.length < 5) continue;
        const mean = angles.reduce((x, y) => x + y, 0) / angles.length;
        expect(mean, `${upper}: mean angle between its rest hinge and the axis it bends about`).toBeLessThan(10);
        expect(Math.max(...angles), `${upper}: the largest angle between its rest hinge and the axis it bends about`).toBeLessThan(45);
      }
    }
  });
});

describe('retarget: the issue\'s measures on 5 rigs × 4 sources', () => {
  // rig × source: mean limb-bone angle ≤ 10°; lowest-foot sliding ≤ the source's + 0.03 m/s; planted feet on the floor.
  const cases = RIGS.flatMap((spec, r) => ['walk', 'run', 'dance', 'model-like walk'].map((what, s) => [spec.label.split(' (')[0], what, r, s] as const));
  it.each(cases)('%s × %s', (_, __, r, s) => {
    const m = measure(sources[s].motion, resultOf(r, s));
    expect(m.angle).toBeLessThanOrEqual(10);
    expect(m.sliding).toBeLessThanOrEqual(m.sourceSliding + 0.03);
    expect(m.plantedMean).toBeLessThanOrEqual(0.01);
    expect(m.planted95).toBeLessThanOrEqual(PLANTED_FLOOR);
  });

  it.each(['walk', 'run', 'dance', 'model-like walk'].map((what, s) => [what, s] as const))('the CC0 character from its GLB × %s', (_, s) => {
    const result = retarget(sources[s].motion, quaternius);
    expect(result.mapping.scheme).toBe('Unreal');
    expect(result.unitsPerMetre).toBe(1);
    const m = measure(sources[s].motion, result);
    expect(m.angle).toBeLessThanOrEqual(10);
    expect(m.sliding).toBeLessThanOrEqual(m.sourceSliding + 0.03);
    expect(m.plantedMean).toBeLessThanOrEqual(0.01);
    expect(m.planted95).toBeLessThanOrEqual(PLANTED_FLOOR);
  });

  it('the foot IK is what keeps the feet planted: without it the planted feet stand off the floor', () => {
    const on = measure(sources[0].motion, resultOf(2, 0));
    const off = measure(sources[0].motion, retarget(sources[0].motion, rigs[2].rig, { footIK: false }));
    expect(off.plantedMean).toBeGreaterThan(2 * on.plantedMean);
    expect(off.planted95).toBeGreaterThan(PLANTED_FLOOR);
  });
});
