// Motion clean-up (issue 16): the pipeline every method shares, run inside a model worker.
//
//   imported motion (its own skeleton, any fps)
//     → canonical points by joint names (motion/skeletonMap), at the models' 30 fps (motion/resample)
//     → a canonical cleaner: `map` (MAP under the generator, optimizer/denoise) or `manifold` (the autoencoder)
//     → contacts labelled on the cleaned motion and planted feet locked (motion/footLock plantFeet)
//     → back onto the imported skeleton at its own fps: every bone keeps its length and turns with its canonical
//       segment; joints the canonical skeleton lacks (fingers, extra spine joints) turn with the segment that
//       carries them (skeletonMap.fromCanonical).
// `lowpass`, the baseline, filters the imported joint positions directly and labels contacts by height and speed.
import { decodeFeatures } from '../model/featureDecode';
import { CanonicalIK, canonicalRotations, encodeFeatures, headingOf } from '../model/featureEncode';
import type { GeneratorInfo } from '../model/generatorInfo';
import { detectContacts } from '../motion/contacts';
import { plantFeet } from '../motion/footLock';
import { lowpassMotion } from '../motion/lowpass';
import { resampledFrames, resampleLinear, resampleNearest, resampleQuaternions } from '../motion/resample';
import { CANONICAL_JOINTS, fromCanonical, mapSkeleton, toCanonical } from '../motion/skeletonMap';
import type { Motion } from '../motion/types';
import { describeValue } from '../motion/describe';
import { denoiseFeatures, type DenoiseSettings } from '../optimizer/denoise';
import type { StepFn } from '../optimizer/rollout';

export const CLEANUP_METHODS = ['map', 'manifold', 'lowpass'] as const;
export type CleanupMethod = (typeof CLEANUP_METHODS)[number];

export interface CleanupOptions {
  method: CleanupMethod;
  /** map: σ of the root observation (m); default estimated from the motion's own jitter. */
  sigmaRoot?: number;
  /** map: σ of the joint-angle observations (rad); default estimated likewise. */
  sigmaAngle?: number;
  /** lowpass: the Butterworth filter's cut-off (Hz, default 6). */
  cutoffHz?: number;
}

export interface CleanupStats {
  method: CleanupMethod;
  /** The naming scheme the skeleton was matched to (map and manifold). */
  scheme?: string;
  sigmaRoot?: number;
  sigmaAngle?: number;
  cutoffHz?: number;
  /** map: share of joint observations discounted as outliers. */
  outlierShare?: number;
  computeMs: number;
}

export interface CleanupResult {
  motion: Motion & { contacts: Uint8Array };
  stats: CleanupStats;
}

const OPTION_RANGES = { sigmaRoot: [0.001, 1, 'metres'], sigmaAngle: [0.001, 1.5, 'radians'], cutoffHz: [0.5, 14, 'Hz'] } as const;

/** Checks clean-up options (the API and the worker both do); throws with a short reason naming the option. */
export function checkCleanupOptions(options: unknown): CleanupOptions {
  if (typeof options !== 'object' || options === null || Array.isArray(options)) throw new Error(`denoise: options must be an object like { method: 'map' }, got ${describeValue(options)}`);
  const o = options as Record<string, unknown>;
  for (const key of Object.keys(o)) {
    if (key !== 'method' && !(key in OPTION_RANGES)) throw new Error(`denoise: unknown option "${key.slice(0, 40)}" (known: method, ${Object.keys(OPTION_RANGES).join(', ')})`);
  }
  if (!CLEANUP_METHODS.includes(o.method as CleanupMethod)) throw new Error(`denoise: method must be one of ${CLEANUP_METHODS.join(', ')}, got ${describeValue(o.method)}`);
  const out: CleanupOptions = { method: o.method as CleanupMethod };
  for (const [key, [lo, hi, unit]] of Object.entries(OPTION_RANGES)) {
    const v = o[key];
    if (v === undefined) continue;
    if (typeof v !== 'number' || !Number.isFinite(v) || v < lo || v > hi) throw new Error(`denoise: ${key} must be a number of ${unit} from ${lo} to ${hi}, got ${describeValue(v)}`);
    (out as unknown as Record<string, number>)[key] = v;
  }
  return out;
}

/** Robust σ of white noise on a signal from its second differences (median absolute deviation; Var(Δ²n) = 6σ²). */
function jitterSigma(values: ArrayLike<number>, width: number, columns: number[]): number {
  const frames = values.length / width;
  const d: number[] = [];
  for (const col of columns) {
    for (let f = 1; f + 1 < frames; f++) d.push(Math.abs(values[(f + 1) * width + col] - 2 * values[f * width + col] + values[(f - 1) * width + col]));
  }
  if (d.length === 0) return 0;
  d.sort((a, b) => a - b);
  return d[Math.floor(d.length / 2)] / 0.6745 / Math.sqrt(6);
}

/** The smallest σs the map filter assumes, so clean input is still followed closely but not copied frame by frame. */
const SIGMA_FLOOR = { root: 0.005, angle: 0.01 };

/**
 * Default observation σs for `map`, measured on the motion itself: the root's from the hips' track, and one per
 * joint from its rotation vector (a short segment's angle is noisier than a long one's for the same jitter).
 */
export function estimateSigmas(info: GeneratorInfo, features: Float32Array, canonicalPoints: Float32Array): { sigmaRoot: number; sigmaAngle: Float64Array } {
  const D = info.onnx.dim;
  const sigmaAngle = new Float64Array(D);
  for (let d = 4; d + 2 < D; d += 3) {
    const s = Math.max(SIGMA_FLOOR.angle, jitterSigma(features, D, [d, d + 1, d + 2]));
    sigmaAngle.fill(s, d, d + 3);
  }
  sigmaAngle[2] = sigmaAngle[4]; // the heading change, as the pelvis's tilt
  const J = info.skeleton.joints.length;
  return { sigmaAngle, sigmaRoot: Math.max(SIGMA_FLOOR.root, jitterSigma(canonicalPoints, J * 3, [0, 1, 2])) };
}

function median(values: ArrayLike<number>): number {
  const v = Array.from(values).sort((a, b) => a - b);
  return v[Math.floor(v.length / 2)];
}

/** What a canonical cleaner gets (at the model's fps) and gives back. */
export interface CanonicalInput {
  /** frames × 25 × 3 canonical points (canonical scale) and their world segment rotations (frames × 25 × 4). */
  points: Float32Array;
  rotations: Float32Array;
  fps: number;
}
export interface CanonicalCleaned {
  positions: Float32Array;
  /** frames × 2 contact bits before labelling (the model's). */
  bits: Uint8Array;
  stats?: Partial<CleanupStats>;
}

/** The `map` cleaner: MAP filtering under the generator (optimizer/denoise.ts), then decoding. */
export function mapCleaner(args: { step: StepFn; info: GeneratorInfo; mean: ArrayLike<number>; std: ArrayLike<number>; options: CleanupOptions; onProgress?: (fraction: number) => void }) {
  return async (input: CanonicalInput): Promise<CanonicalCleaned> => {
    const { info } = args;
    const encoded = encodeFeatures(info, input.points, input.rotations);
    const estimated = estimateSigmas(info, encoded.features, input.points);
    const settings: DenoiseSettings = { sigmaRoot: args.options.sigmaRoot ?? estimated.sigmaRoot, sigmaAngle: args.options.sigmaAngle ?? estimated.sigmaAngle };
    const K = CANONICAL_JOINTS.length;
    const frames = input.points.length / (K * 3);
    const ik = new CanonicalIK(info);
    const world = new Float32Array(K * 4);
    const D = info.onnx.dim;
    const heading = new Float32Array(frames);
    for (let f = 0; f < frames; f++) heading[f] = headingOf([input.rotations[f * K * 4], input.rotations[f * K * 4 + 1], input.rotations[f * K * 4 + 2], input.rotations[f * K * 4 + 3]]);
    const reobserve = (f: number, predicted: Float32Array, row: Float32Array) => {
      ik.solve(input.points, f * K * 3, world, 0, ik.localRotations(predicted));
      ik.angles(world, 0, heading[f], row);
    };
    const r = await denoiseFeatures({
      step: args.step,
      info,
      mean: args.mean,
      std: args.std,
      observed: encoded.features,
      start: encoded.start,
      settings,
      reobserve,
      onFrame: (f) => args.onProgress?.(f / frames),
    });
    const decoded = decodeFeatures(info, r.features, encoded.start);
    const sigmaAngle = typeof settings.sigmaAngle === 'number' ? settings.sigmaAngle : median(Array.from(settings.sigmaAngle).slice(4, D - 2));
    return { positions: decoded.positions, bits: decoded.contacts, stats: { sigmaRoot: settings.sigmaRoot, sigmaAngle, outlierShare: r.outlierShare } };
  };
}

/** The `manifold` cleaner: the canonical points projected through the denoising autoencoder (manifoldProjection.ts). */
export function manifoldCleaner(project: (positions: Float32Array) => Promise<{ positions: Float32Array; contacts: Uint8Array }>) {
  return async (input: CanonicalInput): Promise<CanonicalCleaned> => {
    const r = await project(input.points);
    return { positions: r.positions, bits: r.contacts };
  };
}

/**
 * Cleans `motion` with a canonical cleaner (map, manifold); see the file comment. Throws SkeletonMapError (naming the
 * missing joints) for a skeleton that cannot be mapped, before any model work.
 */
export async function cleanUpOnCanonical(
  info: GeneratorInfo,
  motion: Motion,
  method: CleanupMethod,
  clean: (input: CanonicalInput) => Promise<CanonicalCleaned>,
): Promise<CleanupResult> {
  const began = performance.now();
  const mapping = mapSkeleton(motion, legLength(info));
  const K = CANONICAL_JOINTS.length;
  const fps = info.fps;
  // Before: the imported motion's canonical points and segment rotations, at its own fps and at the model's.
  const beforePoints = toCanonical(motion, mapping);
  const beforeRotations = canonicalRotations(info, beforePoints);
  const frames = resampledFrames(motion.frames, motion.fps, fps);
  const points = resampleLinear(beforePoints, K * 3, motion.fps, fps, frames);
  // The models stand on y = 0; imported clips need not (CMU AMC floors sit a few centimetres off).
  const floor = floorHeight(points);
  for (let i = 1; i < points.length; i += 3) points[i] -= floor;
  const cleaned = await clean({ points, rotations: canonicalRotations(info, points), fps });
  const { skeleton } = info;
  const planted = plantFeet(cleaned.positions, cleaned.bits, skeleton.joints, skeleton.offsets, fps);
  for (let i = 1; i < planted.positions.length; i += 3) planted.positions[i] += floor;
  const afterRotations = canonicalRotations(info, planted.positions);
  // After: back at the imported motion's frame times.
  const afterPoints = resampleLinear(planted.positions, K * 3, fps, motion.fps, motion.frames);
  const after = { points: afterPoints, rotations: resampleQuaternions(afterRotations, K, fps, motion.fps, motion.frames) };
  const moved = fromCanonical(motion, mapping, { points: beforePoints, rotations: beforeRotations }, after);
  const contacts = resampleNearest(planted.contacts, 2, fps, motion.fps, motion.frames);
  return {
    motion: { ...moved, contacts },
    stats: { method, scheme: mapping.scheme, ...cleaned.stats, computeMs: performance.now() - began },
  };
}

/** The baseline: a zero-phase Butterworth low-pass on the imported joint positions; contacts by height and speed. */
export function lowpassCleanup(motion: Motion, options: CleanupOptions): CleanupResult {
  const began = performance.now();
  const cutoffHz = Math.min(options.cutoffHz ?? 6, motion.fps * 0.45);
  const filtered = lowpassMotion(motion, { cutoffHz });
  const contacts = detectContacts(filtered) ?? new Uint8Array(motion.frames * 2);
  return { motion: { ...filtered, contacts }, stats: { method: 'lowpass', cutoffHz, computeMs: performance.now() - began } };
}

/**
 * The floor under canonical points (frames × 25 × 3): the 10th percentile of the lowest foot point per frame,
 * averaged over 5 frames first so that jitter does not pull it down (a plain percentile of noisy heights sits
 * centimetres under the true floor).
 */
function floorHeight(points: Float32Array): number {
  const K = CANONICAL_JOINTS.length;
  const feet = ['LeftFoot', 'LeftToeBase', 'LeftToeBase_end', 'RightFoot', 'RightToeBase', 'RightToeBase_end'].map((n) => CANONICAL_JOINTS.indexOf(n as never));
  const frames = points.length / (K * 3);
  const lowest = Array.from({ length: frames }, (_, f) => Math.min(...feet.map((j) => points[(f * K + j) * 3 + 1])));
  const averaged = lowest.map((_, f) => {
    const window = lowest.slice(Math.max(0, f - 2), Math.min(frames, f + 3));
    return window.reduce((a, b) => a + b, 0) / window.length;
  });
  averaged.sort((a, b) => a - b);
  return averaged[Math.floor(frames * 0.1)] ?? 0;
}

/** Hip → knee → ankle length of the generator's skeleton. */
function legLength(info: GeneratorInfo): number {
  const { joints, offsets } = info.skeleton;
  const len = (name: string) => {
    const j = joints.indexOf(name);
    return Math.hypot(offsets[j * 3], offsets[j * 3 + 1], offsets[j * 3 + 2]);
  };
  return len('LeftLeg') + len('LeftFoot');
}
