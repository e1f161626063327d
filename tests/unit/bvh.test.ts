import { describe, expect, it } from 'vitest';
import { bvhJointNames, parseBVH, exportBVH } from '../../web/motion/bvh';
import { parseAMC, parseASF } from '../../web/motion/asfamc';
import { forwardKinematics } from '../../web/motion/skeleton';
import { eulerToQuat, type Quat } from '../../web/motion/math';
import type { Motion } from '../../web/motion/types';
import { readCorpus } from './corpus';
import { seededRandom } from './fuzz';
import { boneLengthDrift, distance, jointIndex, maxHeight, maxPositionError, position } from './motionStats';

const CMU_UNIT = 0.0254 / 0.45;

describe('parseBVH on the CMU BVH clip 07_04', () => {
  const text = readCorpus('cmu/bvh/07_04.bvh.gz');
  const m = parseBVH(text);

  it('matches the header: 450 frames at 120 fps', () => {
    expect(m.frames).toBe(450);
    expect(m.fps).toBe(120);
    expect(m.positions.length).toBe(450 * m.joints.length * 3);
  });

  it('keeps named joints in file order, drops zero-offset joints, names End Sites <joint>_end', () => {
    expect(m.joints.slice(0, 6)).toEqual(['Hips', 'LeftUpLeg', 'LeftLeg', 'LeftFoot', 'LeftToeBase', 'LeftToeBase_end']);
    expect(m.joints).not.toContain('LHipJoint'); // OFFSET 0 0 0
    expect(m.joints).not.toContain('LowerBack');
    expect(m.parents[jointIndex(m, 'LeftUpLeg')]).toBe(jointIndex(m, 'Hips')); // via the dropped LHipJoint
    expect(m.parents[jointIndex(m, 'Spine')]).toBe(jointIndex(m, 'Hips'));
    m.parents.forEach((p, j) => expect(p).toBeLessThan(j));
  });

  it('is in CMU units: femur length equals the subject-07 ASF femur', () => {
    const asf = parseASF(readCorpus('cmu/asf/07.asf'));
    const femur = asf.bones.find((b) => b.name === 'lfemur')!;
    const knee = jointIndex(m, 'LeftLeg');
    const hip = jointIndex(m, 'LeftUpLeg');
    expect(distance(position(m, 10, knee), position(m, 10, hip))).toBeCloseTo(femur.length * CMU_UNIT, 4);
  });

  it('has a plausible height, y up, and rigid bones', () => {
    const h = maxHeight(m);
    expect(h).toBeGreaterThan(1.3); // subject 07's joints span about 1.45 m (top of head not a joint)
    expect(h).toBeLessThan(1.9);
    const head = jointIndex(m, 'Head');
    const foot = jointIndex(m, 'LeftFoot');
    for (let f = 0; f < m.frames; f += 10) expect(position(m, f, head)[1]).toBeGreaterThan(position(m, f, foot)[1] + 1);
    expect(boneLengthDrift(m)).toBeLessThan(1e-4);
  });

  it('honours an explicit unitScale', () => {
    const cm = parseBVH(text, { unitScale: 0.01 });
    expect(cm.positions[3 * 5 + 1]).toBeCloseTo(m.positions[3 * 5 + 1] * (0.01 / CMU_UNIT), 5);
  });
});

describe('parseBVH unit detection', () => {
  it('reads the acLSTM standard skeleton as centimetres (about 1.53 m tall)', () => {
    const m = parseBVH(readCorpus('aclstm/standard.bvh.gz'));
    expect(m.fps).toBe(30);
    expect(maxHeight(m)).toBeGreaterThan(1.4);
    expect(maxHeight(m)).toBeLessThan(1.7);
    // Hip height from the root channel (85.19 cm in the first frame).
    expect(m.positions[1]).toBeCloseTo(0.851887, 5);
  });

  const figure = (legLength: number) => `HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
  JOINT Head
  {
    OFFSET 0 ${legLength} 0
    CHANNELS 3 Zrotation Yrotation Xrotation
    End Site
    {
      OFFSET 0 ${legLength / 4} 0
    }
  }
  JOINT Foot
  {
    OFFSET 0 ${-legLength} 0
    CHANNELS 3 Zrotation Yrotation Xrotation
  }
}
MOTION
Frames: 1
Frame Time: 0.04
0 ${legLength} 0 0 0 0 0 0 0 0 0 0
`;
  for (const [unit, leg, scale] of [['metres', 0.8, 1], ['centimetres', 80, 0.01], ['millimetres', 800, 0.001], ['inches', 31, 0.0254]] as const) {
    it(`detects ${unit}`, () => {
      const m = parseBVH(figure(leg));
      expect(m.fps).toBe(25);
      expect(m.positions[1]).toBeCloseTo(leg * scale, 6); // root height
    });
  }
});

describe('parseBVH kinematics on a hand-made file', () => {
  // Channel orders differ per joint; the wrist has position channels; the zero-offset "Twist" joint is
  // dropped but its rotation still applies to its children.
  const text = `HIERARCHY
ROOT Root
{
  OFFSET 1 0 0
  CHANNELS 6 Xrotation Xposition Yposition Zposition Yrotation Zrotation
  JOINT Twist
  {
    OFFSET 0 0 0
    CHANNELS 1 Yrotation
    JOINT Arm
    {
      OFFSET 0 100 0
      CHANNELS 3 Xrotation Zrotation Yrotation
      JOINT Wrist
      {
        OFFSET 0 50 0
        CHANNELS 4 Zrotation Xposition Yposition Zposition
        End Site
        {
          OFFSET 10 0 0
        }
      }
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.0333333
0 0 100 0 0 0   0   0 0 0   0 0 50 0
90 0 100 0 0 0  90  90 0 90  0 0 20 0
`;
  const m = parseBVH(text, { unitScale: 0.01 });

  it('lists kept joints with remapped parents', () => {
    expect(m.joints).toEqual(['Root', 'Arm', 'Wrist', 'Wrist_end']);
    expect(m.parents).toEqual([-1, 0, 1, 2]);
    expect(m.fps).toBe(30);
  });

  it('computes rest positions (root = OFFSET + position channels)', () => {
    expect(Array.from(m.positions.slice(0, 12)).map((v) => +v.toFixed(6))).toEqual([0.01, 1, 0, 0.01, 2, 0, 0.01, 2.5, 0, 0.11, 2.5, 0]);
  });

  it('applies channels in the listed order and replaces OFFSET by position channels', () => {
    // Root: Rx(90). Twist: Ry(90). Arm "Xrotation Zrotation Yrotation" = (90, 0, 90) → Rx·Ry.
    // Arm = root + Rx·Ry·(0,100,0) = (1, 100, 100) cm.
    // G_arm = Rx·Ry·Rx·Ry: Wrist = Arm + G_arm·(0,20,0) = (21, 100, 100) (Ry·Rx would give (1, 120, 100)).
    // End = Wrist + G_arm·(10,0,0) = (21, 100, 110).
    const f1 = Array.from(m.positions.slice(12, 24)).map((v) => +(v * 100).toFixed(4));
    expect(f1).toEqual([1, 100, 0, 1, 100, 100, 21, 100, 100, 21, 100, 110]);
  });
});

function expectRoundTrip(m: Motion) {
  const text = exportBVH(m);
  const back = parseBVH(text);
  expect(back.joints).toEqual(m.joints);
  expect(back.parents).toEqual(m.parents);
  expect(back.frames).toBe(m.frames);
  expect(back.fps).toBeCloseTo(m.fps, 6);
  expect(maxPositionError(back, m)).toBeLessThan(0.001);
  return text;
}

describe('exportBVH', () => {
  it('round-trips the CMU BVH clip 07_04 within 1 mm', () => {
    expectRoundTrip(parseBVH(readCorpus('cmu/bvh/07_04.bvh.gz')));
  });

  it('round-trips the ASF/AMC clip 16_11 within 1 mm', () => {
    const m = parseAMC(readCorpus('cmu/amc/16_11.amc.gz'), readCorpus('cmu/asf/16.asf'));
    const text = expectRoundTrip(m);
    // Multi-child joints get zero-offset helpers, leaves a zero End Site.
    expect(text).toMatch(/JOINT root_to_lhipjoint\n\s*\{\n\s*OFFSET 0\.000000 0\.000000 0\.000000/);
    expect(text).toMatch(/JOINT ltoes\n\s*\{\n\s*OFFSET [-\d. ]+\n\s*CHANNELS 3 Zrotation Yrotation Xrotation\n\s*End Site\n\s*\{\n\s*OFFSET 0\.000000 0\.000000 0\.000000/);
  });

  it('writes centimetres, ZYX channels and Frame Time = 1/fps', () => {
    // hips with two children (head, foot): helpers hips_to_head / hips_to_foot carry their rotations.
    const m: Motion = {
      fps: 60, frames: 2, joints: ['hips', 'head', 'foot'], parents: [-1, 0, 0],
      positions: new Float32Array([0.5, 1, -0.25, 0.5, 1.7, -0.25, 0.5, 0, -0.25, 0.5, 1, 0, 0.5, 1, 0.7, 0.5, 0, 0]),
    };
    const text = expectRoundTrip(m);
    expect(text).toContain('ROOT hips');
    expect(text).toContain('CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation');
    expect(text).toMatch(/JOINT head\n\s*\{\n\s*OFFSET 0\.000000 70\.0000\d\d 0\.000000\n\s*CHANNELS 3 Zrotation Yrotation Xrotation\n/);
    expect(text).toMatch(/Frame Time: 0\.01666666667\n/);
    const lines = text.trim().split('\n');
    // Channels: root pos, hips, hips_to_head, head, hips_to_foot, foot (ZYX each).
    expect(lines.at(-2)).toBe('50.000000 100.000000 -25.000000' + ' 0.000000'.repeat(15));
    // Frame 2: the head bone turns from +y to +z: +90° about x on hips_to_head. The hips' two bones
    // are parallel at rest, so they define no rotation of their own and the hips stay at zero.
    expect(lines.at(-1)).toBe('50.000000 100.000000 0.000000' + ' 0.000000'.repeat(3) + ' 0.000000 0.000000 90.000000' + ' 0.000000'.repeat(9));
  });

  it('needs an explicit unitScale to re-import figures under about 1.07 m tall', () => {
    // Unit detection aims at human-sized figures; a 0.5 m toy would be read as inches.
    const m: Motion = { fps: 30, frames: 1, joints: ['a', 'b'], parents: [-1, 0], positions: new Float32Array([0, 0, 0, 0, 0.5, 0]) };
    const text = exportBVH(m);
    expect(maxPositionError(parseBVH(text, { unitScale: 0.01 }), m)).toBeLessThan(1e-6);
    expect(parseBVH(text).positions[4]).toBeCloseTo(0.5 * 2.54, 5);
  });

  it('round-trips a random rigid skeleton (branching, zero-length bone, large rotations)', () => {
    // Deterministic pseudo-random rotations on a human-sized tree.
    let seed = 7;
    const random = () => ((seed = (seed * 1664525 + 1013904223) >>> 0) / 2 ** 32);
    // Depth-first joint order, as every importer produces; "marker" has a zero-length bone.
    const joints = ['pelvis', 'spine', 'head', 'larm', 'lhand', 'marker', 'lleg', 'lfoot', 'rleg', 'rfoot'];
    const parents = [-1, 0, 1, 1, 3, 1, 0, 6, 0, 8];
    const offsets = new Float32Array([0, 0, 0, 0, 0.5, 0, 0, 0.3, 0.05, 0.2, 0.2, 0, 0.3, 0, 0, 0, 0, 0, 0.1, -0.45, 0, 0, -0.45, 0.1, -0.1, -0.45, 0, 0, -0.45, 0.1]);
    const F = 40;
    const roots = new Float32Array(F * 3);
    const rots: number[] = [];
    for (let f = 0; f < F; f++) {
      roots.set([f * 0.02, 0.95, Math.sin(f / 5)], f * 3);
      for (let j = 0; j < joints.length; j++) {
        const q: Quat = eulerToQuat([(random() - 0.5) * 5, (random() - 0.5) * 3, (random() - 0.5) * 5], 'XYZ');
        rots.push(...(j === 0 && f === 0 ? [0, 0, 0, 1] : q));
      }
    }
    const positions = forwardKinematics({ joints, parents, offsets }, roots, new Float32Array(rots));
    expectRoundTrip({ fps: 30, frames: F, joints, parents, positions });
  });

  it('returns joints listed in non-depth-first order in depth-first order, positions intact', () => {
    const m: Motion = {
      fps: 30, frames: 1, joints: ['hips', 'spine', 'leg', 'head', 'foot'], parents: [-1, 0, 0, 1, 2],
      positions: new Float32Array([0, 1, 0, 0, 1.4, 0, 0.1, 0.5, 0, 0, 1.7, 0, 0.1, 0, 0.1]),
    };
    const back = parseBVH(exportBVH(m));
    expect(back.joints).toEqual(['hips', 'spine', 'head', 'leg', 'foot']);
    for (const name of m.joints) {
      expect(distance(position(back, 0, jointIndex(back, name)), position(m, 0, jointIndex(m, name)))).toBeLessThan(1e-6);
    }
  });
});

describe('exportBVH joint names (issue 21)', () => {
  /** A motion with these joint names: a tree (joints 3, 6, 9 … branch off the root) in depth-first order. */
  const namedMotion = (joints: string[]): Motion => {
    const parents = joints.map((_, j) => (j === 0 ? -1 : j % 3 === 0 ? 0 : j - 1));
    const positions = new Float32Array(joints.length * 3);
    joints.forEach((_, j) => positions.set([0.05 * j, 0.9 + 0.3 * (j % 3), 0.02 * j], j * 3));
    return { fps: 30, frames: 1, joints, parents, positions };
  };
  const roundTrip = (joints: string[]) => {
    const m = namedMotion(joints);
    const back = parseBVH(exportBVH(m), { unitScale: 0.01 });
    expect(back.parents).toEqual(m.parents);
    expect(maxPositionError(back, m)).toBeLessThan(1e-5);
    return back.joints;
  };

  it('writes every name the importer can return as it is, so it comes back unchanged', () => {
    const names = [
      'Hips', 'Left Arm', 'a b c', 'End Site', 'Site', 'End', 'JOINT', 'ROOT', 'MOTION', 'HIERARCHY', 'OFFSET', 'CHANNELS',
      'Frames:', 'Frame Time:', 'Xrotation', '#comment', '(a)', '[x]', '"quoted"', "it's", 'back\\slash', 'ünïcødé',
      '日本語の関節', '🦴 bone', 'x_end', 'Hips_to_Left Arm', '0', '-1.5', 'q'.repeat(500), 'unnamed', '\ufffd',
    ];
    expect(bvhJointNames(names)).toEqual(names);
    expect(roundTrip(names)).toEqual(names);
  });

  it('sanitises braces, whitespace and control characters into unique names the importer reads back', () => {
    const cases: Array<[string, string]> = [
      ['root', 'root'], ['brace{open', 'brace(open'], ['brace}close', 'brace)close'], ['{}', '()'],
      ['two  spaces', 'two spaces'], [' leading', 'leading'], ['trailing ', 'trailing'], ['tab\there', 'tab here'],
      ['new\nline', 'new line'], ['crlf\r\nline', 'crlf line'], ['sep\u2028line', 'sep line'], ['nbsp\u00a0name', 'nbsp name'],
      ['bell\u0007name', 'bell_name'], ['nul\u0000name', 'nul_name'], ['\n\t', 'unnamed'], [' ', 'unnamed_2'],
      // A name that needs no change keeps it; a sanitised one that collides gets the next free suffix.
      ['a{b', 'a(b_2'], ['a(b', 'a(b'], ['x  y', 'x y_3'], ['x y', 'x y'], ['x\ty', 'x y_4'], ['x y_2', 'x y_2'],
    ];
    const names = cases.map(([name]) => name);
    const expected = cases.map(([, written]) => written);
    expect(bvhJointNames(names)).toEqual(expected);
    expect(roundTrip(names)).toEqual(expected);
    for (const name of expected) expect(bvhJointNames([name])).toEqual([name]);
  });

  it('round-trips seeded random names: kept where importable, else as bvhJointNames says, always unique', () => {
    const random = seededRandom(5);
    const pieces = ['a', 'Z', '0', '_', 'é', '🦴', '(', ')', ' ', '  ', '\t', '\n', '\r', '{', '}', '\u2028', '\u00a0', '\u0001', '\u0085'];
    for (let round = 0; round < 20; round++) {
      const names = new Set<string>();
      while (names.size < 40) {
        let name = '';
        for (let k = 1 + random.int(6); k > 0; k--) name += random.pick(pieces);
        names.add(name);
      }
      const joints = [...names];
      const written = bvhJointNames(joints);
      expect(new Set(written).size).toBe(joints.length);
      joints.forEach((name, j) => {
        if (!/[{}\s\u0000-\u0008\u000e-\u001f\u007f-\u009f]/.test(name)) expect(written[j]).toBe(name);
      });
      expect(roundTrip(joints)).toEqual(written);
    }
  });

  it('writes deep skeletons without recursion: a 1024-joint chain round-trips', () => {
    const J = 1024;
    const positions = new Float32Array(J * 3);
    for (let j = 0; j < J; j++) positions.set([0.001 * Math.sin(j), (1.7 * j) / (J - 1), 0], j * 3);
    const m: Motion = { fps: 30, frames: 1, joints: Array.from({ length: J }, (_, j) => `j${j}`), parents: Array.from({ length: J }, (_, j) => j - 1), positions };
    const back = parseBVH(exportBVH(m), { unitScale: 0.01 });
    expect(back.joints).toEqual(m.joints);
    expect(maxPositionError(back, m)).toBeLessThan(1e-4);
  });

  it('refuses frame rates under 1 fps, whose frame time the importer rejects', () => {
    const m: Motion = { fps: 0.5, frames: 1, joints: ['a', 'b'], parents: [-1, 0], positions: new Float32Array([0, 0, 0, 0, 1.7, 0]) };
    expect(() => exportBVH(m)).toThrow('BVH export needs at least 1 fps (a "Frame Time" of at most 1 s, as the importer reads), got 0.5');
    expect(parseBVH(exportBVH({ ...m, fps: 1 })).fps).toBe(1);
  });
});
