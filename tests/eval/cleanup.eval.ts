// npm run evaluate:cleanup → docs/models/cleanup.json and cleanup.md: the clean-up methods against the low-pass
// baseline on held-out CMU clips with synthetic noise, run by the page's own code (web/runtime/cleanup/cleanup.ts) on
// onnxruntime-web's Node build (the wasm runtime the browser workers use).
import { writeFileSync } from 'node:fs';
import { it } from 'vitest';
import { parseAMC } from '../../web/motion/asfamc';
import { parseBVH } from '../../web/motion/bvh';
import { detectContacts } from '../../web/motion/contacts';
import { addNoise } from '../../web/motion/noise';
import { boneLengthChange, canonicalView, floorHeight, footSliding, jerk, meanJointError } from '../../web/motion/motionStats';
import type { Motion } from '../../web/motion/types';
import { parseGeneratorInfo } from '../../web/model/generatorInfo';
import { parseManifoldInfo } from '../../web/model/latentErdInfo';
import { cleanUpOnCanonical, lowpassCleanup, manifoldCleaner, mapCleaner, type CleanupMethod, type CleanupResult } from '../../web/runtime/cleanup/cleanup';
import { GeneratorCore } from '../../web/runtime/generator/generatorCore';
import { projectOnManifold } from '../../web/runtime/autoencoder/manifoldProjection';
import { readCorpus, readRepoFile, REPO_ROOT } from '../unit/corpus';
import { ort, shippedSession } from '../unit/shippedModel';

/** Held-out walks of the generator's split (generator.json training.valid_files), up to 10 s each. */
const CLIPS = ['07_10', '16_16', '39_04', '105_06', '35_13'];
/** Five other held-out walks of the split, measured the same way: a check on the report's clips, on which the clean-up's constants were chosen. */
const CHECK_CLIPS = ['08_09', '16_24', '35_02', '39_14', '10_04'];
const LEVELS = [0.01, 0.03, 0.05];
const OUTLIERS = 0.01;
const MAX_FRAMES = 1200;
const METHODS: CleanupMethod[] = ['map', 'manifold', 'lowpass'];

/**
 * Other skeletons (issue 40), measured the same way against the filter: the 3ds Max-friendly CMU conversion of an
 * Indian dance (LeftHip, LeftKnee …; zero-offset collar and hip joints) and a Bandai Namco walk (UpperLeg_L …, a root
 * bone on the floor; read in centimetres, its unit, which the importer's detection takes for inches until issue 39).
 */
const SKELETON_CLIPS = [
  { label: '3ds Max-friendly CMU (Indian dance 94_01)', file: 'aclstm-extra/indian/94_01.bvh.gz', unitScale: undefined },
  { label: 'Bandai Namco (walk, normal style)', file: 'bandai/bvh/dataset-2_walk_normal_001.bvh.gz', unitScale: 0.01 },
];

const info = parseGeneratorInfo(JSON.parse(readRepoFile('public/models/generator.json')), 'generator.json');
const manifold = parseManifoldInfo(JSON.parse(readRepoFile('public/models/manifold.json')), 'manifold.json');

function loadClip(name: string): Motion {
  const m = parseAMC(readCorpus(`cmu/amc/${name}.amc.gz`), readCorpus(`cmu/asf/${name.split('_')[0]}.asf`), { fps: 120 });
  const frames = Math.min(m.frames, MAX_FRAMES);
  const positions = m.positions.slice(0, frames * m.joints.length * 3);
  // Rest the clip on y = 0 (the lowest foot point's 5th percentile), as the other reports' clips are.
  const floor = floorHeight(canonicalView({ ...m, frames, positions }));
  for (let i = 1; i < positions.length; i += 3) positions[i] -= floor;
  return { ...m, frames, positions };
}

/** Every `step`-th frame (120 → 30 fps), so speeds and jerk are measured at the rate of the other reports. */
function decimate(m: Motion, step: number): Motion {
  const J = m.joints.length;
  const frames = Math.floor((m.frames - 1) / step) + 1;
  const positions = new Float32Array(frames * J * 3);
  for (let f = 0; f < frames; f++) positions.set(m.positions.subarray(f * step * J * 3, (f * step + 1) * J * 3), f * J * 3);
  const contacts = m.contacts ? new Uint8Array(frames * 2) : undefined;
  if (contacts) for (let f = 0; f < frames; f++) contacts.set(m.contacts!.subarray(f * step * 2, f * step * 2 + 2), f * 2);
  return { ...m, fps: m.fps / step, frames, positions, ...(contacts ? { contacts } : {}) };
}

function contactF1(found: Uint8Array, truth: Uint8Array): number {
  let tp = 0, fp = 0, fn = 0;
  for (let i = 0; i < truth.length; i++) {
    if (found[i] && truth[i]) tp++;
    else if (found[i]) fp++;
    else if (truth[i]) fn++;
  }
  return tp ? (2 * tp) / (2 * tp + fp + fn) : 0;
}

interface Row { set: 'report' | 'check'; method: string; level: number; error: number; jerk: number; sliding: number; contactF1: number; boneChange: number; realTime: number }

it('evaluates the clean-up methods', async () => {
  const core = new GeneratorCore(await shippedSession(info.file), info, ort.Tensor);
  const [encoder, decoder] = await Promise.all([shippedSession(manifold.files.encoder), shippedSession(manifold.files.decoder)]);
  const project = (positions: Float32Array) =>
    projectOnManifold({
      manifold,
      positions,
      fps: info.fps,
      encode: async (rows, frames) => (await encoder.run({ rows: new ort.Tensor('float32', rows, [1, frames, manifold.rows.dim]) })).latent.data as Float32Array,
      decode: async (latent, steps) => (await decoder.run({ latent: new ort.Tensor('float32', latent, [1, steps, manifold.latent]) })).rows.data as Float32Array,
    });
  const run = async (method: CleanupMethod, noisy: Motion): Promise<CleanupResult> => {
    if (method === 'lowpass') return lowpassCleanup(noisy, { method });
    const cleaner = method === 'map'
      ? mapCleaner({ step: (b, x, h, c) => core.step(b, x, h, c), info, mean: core.mean, std: core.std, options: { method } })
      : manifoldCleaner(project);
    return cleanUpOnCanonical(info, noisy, method, cleaner);
  };

  const rows: Row[] = [];
  const realRows: { clip: string; jerk: number; sliding: number; seconds: number }[] = [];
  for (const name of [...CLIPS, ...CHECK_CLIPS]) {
    const set = CLIPS.includes(name) ? 'report' : 'check';
    const clean = loadClip(name);
    const clean30 = decimate(clean, 4);
    const truth = detectContacts(clean30)!;
    if (set === 'report') realRows.push({ clip: name, jerk: jerk(clean30), sliding: footSliding(clean, 0), seconds: clean.frames / clean.fps });
    for (const level of LEVELS) {
      const { motion: noisy } = addNoise(clean, { jitter: level, outliers: OUTLIERS, seed: 1 });
      const measure = (method: string, m: Motion, contacts: Uint8Array, ms: number) => {
        const m30 = decimate(m, 4);
        rows.push({
          set, method, level,
          error: meanJointError(m, clean),
          jerk: jerk(m30),
          sliding: footSliding(m, 0), // the clips rest on y = 0: every method's motion is measured over the same floor
          contactF1: contactF1(contacts, truth),
          boneChange: boneLengthChange(m, clean),
          realTime: ms > 0 ? (clean.frames / clean.fps) / (ms / 1000) : Infinity,
        });
      };
      measure('noisy input', noisy, detectContacts(decimate(noisy, 4)) ?? new Uint8Array(truth.length), 0);
      for (const method of METHODS) {
        const began = performance.now();
        const r = await run(method, noisy);
        const ms = performance.now() - began;
        measure(method, r.motion, decimate(r.motion, 4).contacts!, ms);
      }
      console.log(name, level, 'done');
    }
  }
  const mean = (method: string, level: number, key: keyof Row, set = 'report') => {
    const v = rows.filter((r) => r.set === set && r.method === method && r.level === level).map((r) => r[key] as number).filter(Number.isFinite);
    return v.reduce((a, b) => a + b, 0) / v.length;
  };
  const summary = LEVELS.flatMap((level) => ['noisy input', ...METHODS].map((method) => ({
    method, level,
    error_cm: +(100 * mean(method, level, 'error')).toFixed(2),
    jerk: +mean(method, level, 'jerk').toFixed(0),
    sliding: +mean(method, level, 'sliding').toFixed(3),
    contact_f1: +mean(method, level, 'contactF1').toFixed(3),
    bone_change_cm: +(100 * mean(method, level, 'boneChange')).toFixed(2),
    x_real_time: method === 'noisy input' ? null : +mean(method, level, 'realTime').toFixed(1),
  })));
  const check = { clips: CHECK_CLIPS, summary: LEVELS.flatMap((level) => ['noisy input', ...METHODS].map((method) => ({
    method, level,
    error_cm: +(100 * mean(method, level, 'error', 'check')).toFixed(2),
    sliding: +mean(method, level, 'sliding', 'check').toFixed(3),
  }))) };
  const skeletonRows: { skeleton: string; method: string; level: number; error_cm: number; sliding: number; seconds: number }[] = [];
  for (const { label, file, unitScale } of SKELETON_CLIPS) {
    const m = parseBVH(readCorpus(file), unitScale ? { unitScale } : {});
    const frames = Math.min(m.frames, Math.round(10 * m.fps));
    const positions = m.positions.slice(0, frames * m.joints.length * 3);
    const floor = floorHeight(canonicalView({ ...m, frames, positions }));
    for (let i = 1; i < positions.length; i += 3) positions[i] -= floor;
    const clean = { ...m, frames, positions };
    const add = (method: string, level: number, motion: Motion) =>
      skeletonRows.push({ skeleton: label, method, level, error_cm: +(100 * meanJointError(motion, clean)).toFixed(2), sliding: +footSliding(motion, 0).toFixed(3), seconds: +(frames / m.fps).toFixed(1) });
    add('clean capture', 0, clean);
    for (const level of LEVELS) {
      const { motion: noisy } = addNoise(clean, { jitter: level, outliers: OUTLIERS, seed: 1 });
      add('noisy input', level, noisy);
      for (const method of ['map', 'lowpass'] as const) add(method, level, (await run(method, noisy)).motion);
      console.log(label, level, 'done');
    }
  }
  const real = { jerk: +(realRows.reduce((a, r) => a + r.jerk, 0) / realRows.length).toFixed(0), sliding: +(realRows.filter((r) => Number.isFinite(r.sliding)).reduce((a, r, _, all) => a + r.sliding / all.length, 0)).toFixed(3) };
  const out = { clips: realRows, levels: LEVELS, outliers: OUTLIERS, real, summary, check, skeletons: skeletonRows, rows };
  writeFileSync(`${REPO_ROOT}docs/models/cleanup.json`, JSON.stringify(out, null, 1) + '\n');
  console.log(JSON.stringify(summary));
  console.log(JSON.stringify(check.summary));
  await core.release();
});
