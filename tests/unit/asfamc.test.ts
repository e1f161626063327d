import { describe, expect, it } from 'vitest';
import { parseAMC, parseASF } from '../../web/motion/asfamc';
import { readCorpus } from './corpus';
import { boneLengthDrift, distance, jointIndex, maxHeight, position } from './motionStats';
import { LINE_ENDINGS } from './fuzz';

const CMU_UNIT = 0.0254 / 0.45;

describe('parseASF on CMU subject 16', () => {
  const asf = parseASF(readCorpus('cmu/asf/16.asf'));

  it('reads units, root and all 30 bones', () => {
    expect(asf.lengthScale).toBeCloseTo(CMU_UNIT, 12);
    expect(asf.angleUnit).toBe('deg');
    expect(asf.root.order).toEqual(['TX', 'TY', 'TZ', 'RX', 'RY', 'RZ']);
    expect(asf.bones).toHaveLength(30);
    const femur = asf.bones.find((b) => b.name === 'lfemur')!;
    expect(femur.length).toBeCloseTo(7.03469, 6);
    expect(femur.axis).toEqual([0, 0, 20]);
    expect(femur.axisOrder).toBe('XYZ');
    expect(femur.dof).toEqual(['rx', 'ry', 'rz']);
    expect(asf.bones.find((b) => b.name === 'lhipjoint')!.dof).toEqual([]);
  });

  it('orders joints depth-first from the :hierarchy, children as listed', () => {
    expect(asf.joints.slice(0, 8)).toEqual(['root', 'lhipjoint', 'lfemur', 'ltibia', 'lfoot', 'ltoes', 'rhipjoint', 'rfemur']);
    expect(asf.joints).toHaveLength(31);
    expect(asf.parents[asf.joints.indexOf('ltibia')]).toBe(asf.joints.indexOf('lfemur'));
    expect(asf.parents[asf.joints.indexOf('lowerback')]).toBe(0);
    expect(asf.parents[asf.joints.indexOf('lthumb')]).toBe(asf.joints.indexOf('lwrist'));
  });
});

describe('parseAMC on the CMU walk 16_11', () => {
  const asfText = readCorpus('cmu/asf/16.asf');
  const m = parseAMC(readCorpus('cmu/amc/16_11.amc.gz'), asfText);

  it('has every frame of the index at 120 fps', () => {
    expect(m.frames).toBe(534);
    expect(m.fps).toBe(120);
    expect(m.joints[0]).toBe('root');
    expect(m.positions.length).toBe(534 * 31 * 3);
  });

  it('places joints at bone ends with the ASF bone lengths, rigidly', () => {
    const asf = parseASF(asfText);
    for (const bone of asf.bones) {
      const j = jointIndex(m, bone.name);
      expect(distance(position(m, 100, j), position(m, 100, m.parents[j]))).toBeCloseTo(bone.length * CMU_UNIT, 4);
    }
    expect(boneLengthDrift(m)).toBeLessThan(1e-4);
  });

  it('stands upright at a plausible height, feet on the ground', () => {
    const h = maxHeight(m);
    expect(h).toBeGreaterThan(1.45);
    expect(h).toBeLessThan(1.95);
    const head = jointIndex(m, 'head');
    const toe = jointIndex(m, 'ltoes');
    let minToe = Infinity;
    for (let f = 0; f < m.frames; f++) {
      expect(position(m, f, head)[1]).toBeGreaterThan(1.3);
      minToe = Math.min(minToe, position(m, f, toe)[1]);
    }
    expect(Math.abs(minToe)).toBeLessThan(0.1);
  });

  it('walks: the feet travel metres over the clip', () => {
    for (const foot of ['lfoot', 'rfoot']) {
      const j = jointIndex(m, foot);
      const a = position(m, 0, j);
      const b = position(m, m.frames - 1, j);
      expect(Math.hypot(b[0] - a[0], b[2] - a[2])).toBeGreaterThan(1.5);
    }
  });

  it('accepts an already parsed skeleton and an fps option', () => {
    const again = parseAMC(readCorpus('cmu/amc/16_11.amc.gz'), parseASF(asfText), { fps: 60 });
    expect(again.fps).toBe(60);
    expect(Array.from(again.positions.slice(0, 300))).toEqual(Array.from(m.positions.slice(0, 300)));
  });
});

describe('ASF/AMC kinematics on hand-made files', () => {
  // One inch per unit (length 1.0) so expected positions are easy to state in inches.
  const asf = (bones: string, hierarchy: string, extra = '') => `:version 1.10
:name test
:units
  mass 1.0
  length 1.0
  angle deg
${extra}:root
   order TX TY TZ RX RY RZ
   axis XYZ
   position 0 0 0
   orientation 0 0 0
:bonedata
${bones}
:hierarchy
  begin
${hierarchy}
  end
`;
  const inch = (v: number[]) => v.map((x) => +(x / 0.0254).toFixed(6) + 0); // + 0 turns −0 into 0

  it('conjugates dof rotations by the bone axis: G = C·M·C⁻¹', () => {
    // Axis rotated 90° about z: a dof rotation about the bone's local x is a rotation about world y.
    const text = asf(`  begin
     id 1
     name bone
     direction 0 0 1
     length 1
     axis 0 0 90 XYZ
    dof rx
    limits (-180.0 180.0)
  end`, '    root bone');
    const m = parseAMC(`:FULLY-SPECIFIED\n:DEGREES\n1\nroot 0 0 0 0 0 0\nbone 90\n`, text);
    expect(inch(Array.from(m.positions.slice(3, 6)))).toEqual([1, 0, 0]);
  });

  it('applies dofs extrinsically in the listed order ("rx ry" → Ry·Rx) and the root transform', () => {
    const text = asf(`  begin
     id 1
     name up
     direction 0 1 0
     length 2
     axis 0 0 0 XYZ
    dof rx ry
  end
  begin
     id 2
     name tip
     direction 0 1 0
     length 1
     axis 0 0 0 XYZ
  end`, '    root up\n    up tip');
    // Bone "up": Rx(90) takes +y to +z, then Ry(90) takes +z to +x (intrinsic order would give +z).
    // Root: translate (1, 2, 3) and turn 90° about y, taking that +x on to −z.
    const m = parseAMC(`# comment\n1\nroot 1 2 3 0 90 0\nup 90 90\n`, text);
    expect(m.joints).toEqual(['root', 'up', 'tip']);
    expect(m.parents).toEqual([-1, 0, 1]);
    expect(inch(Array.from(m.positions))).toEqual([1, 2, 3, 1, 2, 3 - 2, 1, 2, 3 - 3]);
    // Without the root turn the chain points along +x.
    const n = parseAMC(`1\nroot 1 2 3 0 0 0\nup 90 90\n`, text);
    expect(inch(Array.from(n.positions.slice(3)))).toEqual([3, 2, 3, 4, 2, 3]);
  });

  it('uses radians when the ASF says so and lengths of 1/L inch', () => {
    const text = asf(`  begin
     name b
     direction 1 0 0
     length 0.45
     axis 0 0 0 XYZ
    dof rz
  end`, '    root b').replace('length 1.0', 'length 0.45').replace('angle deg', 'angle rad');
    const m = parseAMC(`1\nroot 0 0 0 0 0 0\nb ${Math.PI / 2}\n`, text);
    expect(inch(Array.from(m.positions.slice(3, 6)))).toEqual([0, 1, 0]);
  });
});

describe('ASF/AMC line breaks and truncation', () => {
  const asfText = readCorpus('cmu/asf/16.asf');
  const FIVE_FRAMES = 3 + 30 * 5; // 3 header lines, then a frame number and 29 bone lines per frame
  const amcText = readCorpus('cmu/amc/16_11.amc.gz').split('\n').slice(0, FIVE_FRAMES).join('\n') + '\n';
  const skeleton = parseASF(asfText);
  const reference = parseAMC(amcText, skeleton);

  it('reads CRLF, CR, U+2028 and U+2029 line breaks exactly as LF', () => {
    expect(reference.frames).toBe(5);
    for (const [name, lineBreak] of Object.entries(LINE_ENDINGS)) {
      const m = parseAMC(amcText.replace(/\n/g, lineBreak), asfText.replace(/\n/g, lineBreak));
      expect(Array.from(m.positions), name).toEqual(Array.from(reference.positions));
    }
  });

  it('rejects every cut inside the last frame but one inside its last number (undetectable: docs/api.md)', () => {
    const lastFrame = amcText.lastIndexOf('\n5\n') + 1;
    const end = amcText.length;
    expect(amcText.slice(end - 15)).toBe('\nltoes 3.01279\n');
    const accepted: number[] = [];
    for (let cut = lastFrame; cut < end; cut++) {
      try {
        const m = parseAMC(amcText.slice(0, cut), skeleton);
        expect(m.frames).toBe(cut === lastFrame ? 4 : 5);
        accepted.push(cut);
      } catch (e) {
        expect((e as Error).message).toMatch(/^AMC line \d+: /);
      }
    }
    // The clip cut where frame 5 starts reads as four frames; cut after "3", "3.", "3.0", … "3.01279" of
    // "ltoes 3.01279", the last value reads as the shorter number.
    expect(accepted).toEqual([lastFrame, end - 7, end - 6, end - 5, end - 4, end - 3, end - 2, end - 1]);
  });
});
