// Parity with the Python loader (training/): positions it computed for the same inputs, stored in
// tests/fixtures/fk_parity.json by the Python side. Joints are matched by name.
import { describe, expect, it } from 'vitest';
import { forwardKinematics } from '../../web/motion/skeleton';
import { parseAMC } from '../../web/motion/asfamc';
import { parseBVH } from '../../web/motion/bvh';
import type { Motion } from '../../web/motion/types';
import { readCorpus, readRepoFile, repoFileExists } from './corpus';

const FIXTURE = 'tests/fixtures/fk_parity.json';
const TOLERANCE = 0.001; // metres

interface ClipParity {
  frames: number[];
  joints: string[];
  positions: number[];
}
interface Fixture {
  canonical: {
    skeleton: { joints: string[]; parents: number[]; offsets: number[] };
    frames: number;
    root_positions: number[];
    rotations: number[];
    positions: number[];
  };
  amc: ClipParity & { asf: string; amc: string };
  bvh: ClipParity & { file: string };
  bvh_bandai: ClipParity & { file: string };
}

/** Largest distance between our positions and the fixture's, over its frames and joints (by name). */
function maxError(m: Motion, expected: ClipParity): number {
  let worst = 0;
  expected.frames.forEach((frame, fi) => {
    expected.joints.forEach((name, ji) => {
      const j = m.joints.indexOf(name);
      if (j < 0) throw new Error(`joint ${name} from the fixture is missing in ${m.joints.join(', ')}`);
      const b = (frame * m.joints.length + j) * 3;
      const e = (fi * expected.joints.length + ji) * 3;
      const d = Math.hypot(m.positions[b] - expected.positions[e], m.positions[b + 1] - expected.positions[e + 1], m.positions[b + 2] - expected.positions[e + 2]);
      worst = Math.max(worst, d);
    });
  });
  return worst;
}

describe.skipIf(!repoFileExists(FIXTURE))('parity with the Python loader', () => {
  const fixture = (repoFileExists(FIXTURE) ? JSON.parse(readRepoFile(FIXTURE)) : undefined) as Fixture;

  it('forwardKinematics matches on the canonical skeleton', () => {
    const c = fixture.canonical;
    const skeleton = { joints: c.skeleton.joints, parents: c.skeleton.parents, offsets: new Float32Array(c.skeleton.offsets) };
    const positions = forwardKinematics(skeleton, new Float32Array(c.root_positions), new Float32Array(c.rotations));
    expect(positions.length).toBe(c.positions.length);
    let worst = 0;
    for (let i = 0; i < positions.length; i++) worst = Math.max(worst, Math.abs(positions[i] - c.positions[i]));
    expect(worst).toBeLessThan(TOLERANCE);
  });

  it('parseAMC matches on the listed frames', () => {
    const { asf, amc } = fixture.amc;
    const m = parseAMC(readCorpus(amc), readCorpus(asf));
    expect(maxError(m, fixture.amc)).toBeLessThan(TOLERANCE);
  });

  it('parseBVH matches on the listed frames', () => {
    const m = parseBVH(readCorpus(fixture.bvh.file));
    expect(m.joints).toEqual(expect.arrayContaining(fixture.bvh.joints));
    expect(maxError(m, fixture.bvh)).toBeLessThan(TOLERANCE);
  });

  it('parseBVH matches on a Bandai Namco file (position channels on every joint, centimetres detected)', () => {
    const m = parseBVH(readCorpus(fixture.bvh_bandai.file));
    expect(m.joints).toEqual(expect.arrayContaining(fixture.bvh_bandai.joints));
    expect(maxError(m, fixture.bvh_bandai)).toBeLessThan(TOLERANCE);
  });
});
