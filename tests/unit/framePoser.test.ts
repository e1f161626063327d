// featureDecode.ts framePoser (one frame, the clean-up smoother's hot path) against decodeFeatures on the same rows.
import { expect, it } from 'vitest';
import { decodeFeatures, framePoser } from '../../web/model/featureDecode';
import { parseGeneratorInfo } from '../../web/model/generatorInfo';
import { readRepoFile } from './corpus';

const info = parseGeneratorInfo(JSON.parse(readRepoFile('public/models/generator.json')), 'generator.json');

it('poses one row as decodeFeatures does, from any root and on other offsets', () => {
  const D = info.onnx.dim;
  const offsets = info.skeleton.offsets.map((v, i) => v * (1 + 0.1 * Math.sin(i)));
  const pose = framePoser(info, offsets);
  for (const [k, root] of [[0.3, { x: 0.3, z: -0.2, heading: 0.8 }], [1.1, { x: -2, z: 5, heading: -2.5 }]] as const) {
    const row = Float32Array.from({ length: D }, (_, d) => info.normalisation.mean[d] + 0.7 * info.normalisation.std[d] * Math.sin(d * k));
    const want = decodeFeatures(info, row, { ...root }, offsets).positions;
    const got = pose(row, root);
    for (let i = 0; i < want.length; i++) expect(Math.abs(got[i] - want[i])).toBeLessThan(1e-5);
  }
});
