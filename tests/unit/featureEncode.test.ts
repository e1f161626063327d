// Canonical positions → generator features (web/model/featureEncode.ts) and back through featureDecode.ts: every
// segment the features model points where the positions say, on a real held-out clip.
import { expect, it } from 'vitest';
import { parseAMC } from '../../web/motion/asfamc';
import { mapSkeleton, toCanonical } from '../../web/motion/skeletonMap';
import { resampledFrames, resampleLinear } from '../../web/motion/resample';
import { canonicalRotations, encodeFeatures } from '../../web/model/featureEncode';
import { decodeFeatures } from '../../web/model/featureDecode';
import { parseGeneratorInfo } from '../../web/model/generatorInfo';
import { readCorpus, readRepoFile } from './corpus';

const info = parseGeneratorInfo(JSON.parse(readRepoFile('public/models/generator.json')), 'generator.json');

it('decodes back to the same segment directions and root track', () => {
  const clip = parseAMC(readCorpus('cmu/amc/35_13.amc.gz'), readCorpus('cmu/asf/35.asf'), { fps: 120 });
  const frames = resampledFrames(clip.frames, 120, 30);
  const points = resampleLinear(toCanonical(clip, mapSkeleton(clip, 0.83)), 75, 120, 30, frames);
  const { features, start } = encodeFeatures(info, points, canonicalRotations(info, points));
  expect(features.length).toBe(frames * info.onnx.dim);
  const decoded = decodeFeatures(info, features, start).positions;
  const { parents } = info.skeleton;
  const fixed = new Set(info.features.fixed_joints);
  let worst = 0;
  for (let f = 0; f < frames; f++) {
    expect(Math.hypot(decoded[f * 75] - points[f * 75], decoded[f * 75 + 2] - points[f * 75 + 2])).toBeLessThan(1e-4);
    for (let j = 1; j < 25; j++) {
      if (fixed.has(j)) continue;
      const seg = (P: ArrayLike<number>) => [0, 1, 2].map((a) => P[(f * 25 + j) * 3 + a] - P[(f * 25 + parents[j]) * 3 + a]);
      const a = seg(decoded), b = seg(points);
      const cos = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (Math.hypot(...a) * Math.hypot(...b));
      worst = Math.max(worst, Math.acos(Math.min(1, cos)));
    }
  }
  expect(worst).toBeLessThan(0.01);
});
