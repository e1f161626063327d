// Motion clean-up's shared pipeline (web/runtime/cleanup/cleanup.ts) on a real held-out CMU clip: the result keeps the
// imported skeleton (joints, parents, frame count, one length per bone), the options are checked, and a skeleton
// that cannot be mapped is refused before any model work.
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { parseAMC } from '../../web/motion/asfamc';
import { addNoise } from '../../web/motion/noise';
import { medianBoneLengths, SkeletonMapError } from '../../web/motion/skeletonMap';
import type { Motion } from '../../web/motion/types';
import { parseGeneratorInfo } from '../../web/model/generatorInfo';
import { checkCleanupOptions, cleanUpOnCanonical, lowpassCleanup, mapCleaner } from '../../web/runtime/cleanup/cleanup';
import { GeneratorCore } from '../../web/runtime/generator/generatorCore';
import { readCorpus, readRepoFile } from './corpus';
import { ort, shippedSession } from './shippedModel';

const info = parseGeneratorInfo(JSON.parse(readRepoFile('public/models/generator.json')), 'generator.json');
// 35_13 is held out of the generator's training (generator.json training.valid_files).
const clip = parseAMC(readCorpus('cmu/amc/35_13.amc.gz'), readCorpus('cmu/asf/35.asf'), { fps: 120 });
const noisy = addNoise(clip, { jitter: 0.02, outliers: 0.01, seed: 3 }).motion;

function boneLength(m: Motion, f: number, j: number): number {
  const J = m.joints.length, p = m.parents[j];
  const P = m.positions;
  return Math.hypot(P[(f * J + j) * 3] - P[(f * J + p) * 3], P[(f * J + j) * 3 + 1] - P[(f * J + p) * 3 + 1], P[(f * J + j) * 3 + 2] - P[(f * J + p) * 3 + 2]);
}

let core: GeneratorCore;
beforeAll(async () => {
  core = new GeneratorCore(await shippedSession(info.file), info, ort.Tensor);
});
afterAll(() => core?.release());

describe('clean-up', () => {
  it('map keeps the imported skeleton: joints, parents, fps, frames, and one length per bone', async () => {
    let progress = 0;
    const cleaner = mapCleaner({ step: (b, x, h, c) => core.step(b, x, h, c), info, mean: core.mean, std: core.std, options: { method: 'map' }, onProgress: (p) => (progress = p) });
    const { motion, stats } = await cleanUpOnCanonical(info, noisy, 'map', cleaner);
    expect(motion.joints).toEqual(clip.joints);
    expect(motion.parents).toEqual(clip.parents);
    expect([motion.fps, motion.frames]).toEqual([clip.fps, clip.frames]);
    expect(motion.contacts.length).toBe(clip.frames * 2);
    expect(motion.positions.every(Number.isFinite)).toBe(true);
    expect(stats.scheme).toBe('CMU ASF');
    expect(progress).toBeGreaterThan(0.9);
    // One length per bone over the frames, nearer the clean clip's than the jittered input's median lengths are.
    const noisyLengths = medianBoneLengths(noisy), cleanLengths = medianBoneLengths(clip);
    let ours = 0, theirs = 0;
    for (let j = 1; j < motion.joints.length; j++) {
      for (let f = 7; f < motion.frames; f += 7) expect(Math.abs(boneLength(motion, f, j) - boneLength(motion, 0, j))).toBeLessThan(1e-4);
      ours += Math.abs(boneLength(motion, 0, j) - cleanLengths[j]);
      theirs += Math.abs(noisyLengths[j] - cleanLengths[j]);
    }
    expect(ours).toBeLessThan(theirs / 2);
    // The motion moved as the clip did: the root ends near where the clip's does.
    const J = clip.joints.length, last = (clip.frames - 1) * J * 3;
    expect(Math.hypot(motion.positions[last] - clip.positions[last], motion.positions[last + 2] - clip.positions[last + 2])).toBeLessThan(0.3);
  });

  it('map cleans a capture at a low frame rate (its filters stay under the clip Nyquist frequency)', async () => {
    const J = noisy.joints.length, every = 20; // 120 → 6 fps: a 4 Hz band would be above its Nyquist 3 Hz
    const frames = Math.floor(noisy.frames / every);
    const positions = new Float32Array(frames * J * 3);
    for (let f = 0; f < frames; f++) positions.set(noisy.positions.subarray(f * every * J * 3, (f * every + 1) * J * 3), f * J * 3);
    const sparse: Motion = { ...noisy, fps: 6, frames, positions };
    const cleaner = mapCleaner({ step: (b, x, h, c) => core.step(b, x, h, c), info, mean: core.mean, std: core.std, options: { method: 'map' } });
    const { motion } = await cleanUpOnCanonical(info, sparse, 'map', cleaner);
    expect([motion.fps, motion.frames]).toEqual([6, frames]);
    expect(motion.positions.every(Number.isFinite)).toBe(true);
  });

  it('refuses a skeleton it cannot map before running any model, naming what is missing', async () => {
    // The clip without its right leg (every joint below rhipjoint dropped).
    const cut = new Set<number>();
    clip.parents.forEach((p, j) => (clip.joints[j] === 'rhipjoint' || cut.has(p)) && cut.add(j));
    const kept = clip.joints.flatMap((_, j) => (cut.has(j) ? [] : [j]));
    const J = clip.joints.length;
    const positions = new Float32Array(clip.frames * kept.length * 3);
    for (let f = 0; f < clip.frames; f++) kept.forEach((j, k) => positions.set(clip.positions.subarray((f * J + j) * 3, (f * J + j) * 3 + 3), (f * kept.length + k) * 3));
    const oneLegged = { ...clip, joints: kept.map((j) => clip.joints[j]), parents: kept.map((j) => kept.indexOf(clip.parents[j])), positions };
    let called = false;
    const run = cleanUpOnCanonical(info, oneLegged, 'map', async () => {
      called = true;
      throw new Error('not reached');
    });
    await expect(run).rejects.toThrow(SkeletonMapError);
    await expect(run).rejects.toThrow(/no two legs/);
    expect(called).toBe(false);
  });

  it('lowpass keeps joints and frames and smooths the jitter', () => {
    const { motion, stats } = lowpassCleanup(noisy, { method: 'lowpass' });
    expect(motion.joints).toEqual(clip.joints);
    expect(motion.frames).toBe(clip.frames);
    expect(stats.cutoffHz).toBe(6);
    const err = (m: Motion) => m.positions.reduce((s, v, i) => s + Math.abs(v - clip.positions[i]), 0);
    expect(err(motion)).toBeLessThan(0.6 * err(noisy));
  });

  it('checks options with a reason naming the option', () => {
    expect(checkCleanupOptions({ method: 'map', sigmaRoot: 0.02 })).toEqual({ method: 'map', sigmaRoot: 0.02 });
    expect(() => checkCleanupOptions({ method: 'median' })).toThrow(/method must be one of map, manifold, lowpass/);
    expect(() => checkCleanupOptions({ method: 'map', sigmaAngle: -1 })).toThrow(/sigmaAngle must be a number of radians/);
    expect(() => checkCleanupOptions({ method: 'map', sigma: 1 })).toThrow(/unknown option "sigma"/);
    expect(() => checkCleanupOptions('map')).toThrow(/options must be an object/);
  });
});
