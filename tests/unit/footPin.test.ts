// Feet pinned in a cleaned motion (web/motion/footPin.ts): a planted foot that slides is held at its median place,
// and with a tolerance a foot point wandering within it is left as captured, one beyond it brought back to it.
import { describe, expect, it } from 'vitest';
import { pinFeet } from '../../web/motion/footPin';
import { CANONICAL_JOINTS } from '../../web/motion/skeletonMap';

const J = CANONICAL_JOINTS.length;
const FRAMES = 21;
const idx = (name: (typeof CANONICAL_JOINTS)[number]) => CANONICAL_JOINTS.indexOf(name);
const LEFT_FOOT = ['LeftFoot', 'LeftToeBase', 'LeftToeBase_end'].map((n) => idx(n as never));

/** A standing pose whose left foot slides along +x by `slide(f)` (m) while the rest stays put. */
function standing(slide: (f: number) => number): Float32Array {
  const pose: Record<string, [number, number, number]> = {
    Hips: [0, 0.95, 0], LeftUpLeg: [0.1, 0.9, 0], LeftLeg: [0.1, 0.5, 0.02], LeftFoot: [0.1, 0.08, 0], LeftToeBase: [0.1, 0.03, 0.12], LeftToeBase_end: [0.1, 0.0, 0.2],
    RightUpLeg: [-0.1, 0.9, 0], RightLeg: [-0.1, 0.5, 0.02], RightFoot: [-0.1, 0.08, 0], RightToeBase: [-0.1, 0.03, 0.12], RightToeBase_end: [-0.1, 0.0, 0.2],
  };
  const out = new Float32Array(FRAMES * J * 3);
  for (let f = 0; f < FRAMES; f++) {
    CANONICAL_JOINTS.forEach((name, j) => {
      const p = pose[name] ?? [0, 1.3, 0];
      const dx = LEFT_FOOT.includes(j) ? slide(f) : 0;
      out.set([p[0] + dx, p[1], p[2]], (f * J + j) * 3);
    });
  }
  return out;
}

const toeEndX = (positions: Float32Array, f: number) => positions[(f * J + idx('LeftToeBase_end')) * 3];
/** The left foot planted over every frame, the right foot not. */
const contacts = Uint8Array.from({ length: FRAMES * 2 }, (_, i) => (i % 2 === 0 ? 1 : 0));

describe('pinFeet', () => {
  // The toe tip (the lowest point) slides 2 cm over the contact: its median place is the middle frame's.
  const slide = (f: number) => 0.02 * (f / (FRAMES - 1));
  const middle = slide((FRAMES - 1) / 2);

  it('holds a sliding planted foot at its median place away from the contact ends', () => {
    const out = pinFeet(standing(slide), contacts, CANONICAL_JOINTS);
    for (let f = 4; f < FRAMES - 4; f++) expect(Math.abs(toeEndX(out, f) - (0.1 + middle))).toBeLessThan(1e-6);
  });

  it('leaves a foot within the tolerance of its anchor as captured and brings one beyond it back to the tolerance', () => {
    const input = standing(slide);
    const tolerance = 0.005;
    const out = pinFeet(input, contacts, CANONICAL_JOINTS, tolerance);
    let kept = 0, pulled = 0;
    for (let f = 4; f < FRAMES - 4; f++) {
      const off = toeEndX(input, f) - (0.1 + middle);
      if (Math.abs(off) <= tolerance) {
        expect(toeEndX(out, f)).toBeCloseTo(toeEndX(input, f), 6);
        kept++;
      } else {
        expect(Math.abs(toeEndX(out, f) - (0.1 + middle))).toBeCloseTo(tolerance, 6);
        pulled++;
      }
    }
    expect(kept).toBeGreaterThan(0);
    expect(pulled).toBeGreaterThan(0);
  });
});
