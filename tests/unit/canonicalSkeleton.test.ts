// The canonical joint list exists twice: training/mocap/canonical_skeleton.json (Python's, written by
// python -m training.mocap.rebuild_skeleton and checked against skeleton.py CANONICAL_LAYOUT on every load) and
// web/motion/skeletonMap.ts CANONICAL_JOINTS / CANONICAL_PARENTS (the page's copy, typed so that joint names are
// checked at compile time). The page maps imported motion onto its copy and hands it to the models, so the copy must
// name the same points in the same order with the same parents, as must the shipped models that carry the skeleton.
import { describe, expect, it } from 'vitest';
import { CANONICAL_JOINTS, CANONICAL_PARENTS } from '../../web/motion/skeletonMap';
import { readRepoFile } from './corpus';

interface SkeletonJson {
  joints: string[];
  parents: number[];
}

const python = JSON.parse(readRepoFile('training/mocap/canonical_skeleton.json')) as SkeletonJson;
const MODELS_WITH_THE_SKELETON = ['generator', 'manifold', 'vae-lstm'];

describe('canonical joint list: web/motion/skeletonMap.ts = training/mocap/canonical_skeleton.json', () => {
  it('names the same joints in the same order', () => {
    expect([...CANONICAL_JOINTS]).toEqual(python.joints);
  });

  it('gives each joint the same parent', () => {
    expect(CANONICAL_PARENTS).toEqual(python.parents);
  });

  for (const id of MODELS_WITH_THE_SKELETON) {
    it(`is the skeleton public/models/${id}.json was trained on`, () => {
      const { skeleton } = JSON.parse(readRepoFile(`public/models/${id}.json`)) as { skeleton: SkeletonJson };
      expect(skeleton.joints).toEqual(python.joints);
      expect(skeleton.parents).toEqual(python.parents);
    });
  }
});
