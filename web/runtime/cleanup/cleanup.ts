// Motion clean-up (issue 16): the pipeline every method shares, run inside a model worker.
//
//   imported motion (its own skeleton, any fps)
//     → canonical points by joint names (motion/skeletonMap), at the models' 30 fps (motion/resample)
//     → a canonical cleaner: `map` (MAP under the generator, optimizer/smoother) or `manifold` (the autoencoder)
//     → contacts labelled on the cleaned motion and planted feet pinned (motion/footPin)
//     → back onto the imported skeleton at its own fps, one length per bone: a bone that is a whole canonical
//       segment aims at its cleaned point; joints the canonical skeleton lacks (fingers, extra spine joints) ride
//       rigidly on the segment that carries them (skeletonMap.fromCanonical).
// `lowpass`, the baseline, filters the imported joint positions directly and labels contacts by height and speed.
import { decodeFeatures, integrateRoot, type RootStart } from '../../model/featureDecode';
import { canonicalRotations, encodeFeatures } from '../../model/featureEncode';
import type { GeneratorInfo } from '../../model/generatorInfo';
import { detectContacts } from '../../motion/contacts';
import { labelContacts } from '../../motion/contactLabels';
import { pinFeet } from '../../motion/footPin';
import { butterworthLowpass, filtfilt, lowpassMotion, lowpassRows } from '../../motion/lowpass';
import { resampleRobust, resampledFrames, resampleLinear, resampleNearest, resampleQuaternions } from '../../motion/resample';
import { CANONICAL_JOINTS, fromCanonical, mapSkeleton, medianBoneLengths, toCanonical } from '../../motion/skeletonMap';
import type { Motion } from '../../motion/types';
import { describeValue } from '../../motion/describe';
import { smoothFeatures } from '../../optimizer/smoother';
import type { StepFn } from '../../optimizer/rollout';
import { checkpoint } from '../worker/cancellation';

/**
 * A cancellation checkpoint between the stages of a clean-up (cancellation.ts): without `signal` nothing; else it
 * throws a CancelledError once the request is cancelled, first letting the worker read its messages every 20 ms
 * of work. The stages before the first model step and after the last take seconds on a long clip.
 */
async function pause(signal: AbortSignal | undefined): Promise<void> {
  const look = signal && checkpoint(signal);
  if (look) await look;
}

export const CLEANUP_METHODS = ['map', 'manifold', 'lowpass'] as const;
export type CleanupMethod = (typeof CLEANUP_METHODS)[number];

export interface CleanupOptions {
  method: CleanupMethod;
  /** map: σ of the root observation (m); default estimated from the motion's own jitter. */
  sigmaRoot?: number;
  /** map: σ of the other joints' observations as an angle (rad; a segment's end moves by it × the segment's length); default the measured jitter. */
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
  /** map: the jitter measured on the motion (m), used as the observation σ where none is given. */
  jitter?: number;
  /** map: share of joint observations discounted as outliers. */
  outlierShare?: number;
  computeMs: number;
}

export interface CleanupResult {
  motion: Motion & { contacts: Uint8Array };
  stats: CleanupStats;
}

const OPTION_RANGES = { sigmaRoot: [0.001, 1, 'metres'], sigmaAngle: [0.001, 1.5, 'radians'], cutoffHz: [0.5, 14, 'Hz'] } as const;

/** Frames of canonical rotations solved between two checkpoints (about 40 ms of work). */
const ROTATION_CHUNK = 128;

/** canonicalRotations in chunks of frames with a checkpoint between: every frame is solved on its own, so the result is the same. */
async function rotationsWithPauses(info: GeneratorInfo, points: Float32Array, signal: AbortSignal | undefined): Promise<Float32Array> {
  if (!signal) return canonicalRotations(info, points);
  const J = info.skeleton.parents.length;
  const frames = points.length / (J * 3);
  const out = new Float32Array(frames * J * 4);
  for (let f = 0; f < frames; f += ROTATION_CHUNK) {
    const end = Math.min(frames, f + ROTATION_CHUNK);
    out.set(canonicalRotations(info, points.subarray(f * J * 3, end * J * 3)), f * J * 4);
    await pause(signal);
  }
  return out;
}

/** Checks clean-up options (the API and the worker both do); throws with a short reason naming the option. */
export function checkCleanupOptions(options: unknown): CleanupOptions {
  if (typeof options !== 'object' || options === null || Array.isArray(options)) throw new Error(`options must be an object like { method: 'map' }, got ${describeValue(options)}`);
  const o = options as Record<string, unknown>;
  for (const key of Object.keys(o)) {
    if (key !== 'method' && !(key in OPTION_RANGES)) throw new Error(`unknown option "${key.slice(0, 40)}" (known: method, ${Object.keys(OPTION_RANGES).join(', ')})`);
  }
  if (!CLEANUP_METHODS.includes(o.method as CleanupMethod)) throw new Error(`method must be one of ${CLEANUP_METHODS.join(', ')}, got ${describeValue(o.method)}`);
  const out: CleanupOptions = { method: o.method as CleanupMethod };
  for (const [key, [lo, hi, unit]] of Object.entries(OPTION_RANGES)) {
    const v = o[key];
    if (v === undefined) continue;
    if (typeof v !== 'number' || !Number.isFinite(v) || v < lo || v > hi) throw new Error(`${key} must be a number of ${unit} from ${lo} to ${hi}, got ${describeValue(v)}`);
    (out as unknown as Record<string, number>)[key] = v;
  }
  return out;
}

/**
 * Frame rates clean-up takes (fps). Real capture lies well inside: CMU's 120, consumer suits 60–240, high-speed
 * optical systems up to 1000. Below 1 fps a "motion" is a slide show whose frames the 30 fps model steps cannot
 * bridge, and at 0.01 fps the resampling to 30 fps made millions of model frames (the worker busy for minutes, at
 * 1e-6 fps a 672,750,000,075-value array); above 1000 fps the resampling averages thousands of samples per frame.
 */
export const CLEANUP_FPS: readonly [number, number] = [1, 1000];
/** Longest motion clean-up takes (s): an hour, 108,000 model frames at 30 fps (each a model step, minutes of work already). */
export const MAX_CLEANUP_SECONDS = 3600;

/**
 * Checks that clean-up can handle `motion` (a validated Motion) in time and memory: its frame rate within CLEANUP_FPS
 * and its length within MAX_CLEANUP_SECONDS, so the frames at the model's rate stay bounded. The API and the worker
 * both check, before any model work; throws a short reason.
 */
export function checkCleanupMotion(motion: Pick<Motion, 'fps' | 'frames'>): void {
  const [lo, hi] = CLEANUP_FPS;
  const { fps, frames } = motion;
  if (!(fps >= lo && fps <= hi)) throw new RangeError(`the motion's frame rate must be from ${lo} to ${hi} fps for clean-up (capture is recorded within), got ${Number(fps.toPrecision(6))} fps`);
  const seconds = (frames - 1) / fps;
  if (seconds > MAX_CLEANUP_SECONDS) {
    throw new RangeError(`the motion lasts ${(seconds / 60).toFixed(1)} min; clean-up takes at most ${MAX_CLEANUP_SECONDS / 60} min (cut it into parts)`);
  }
}

/** Cut-off (Hz) of the root track's smoothing: keeps the hips' sway with each step, drops jitter. */
const ROOT_CUTOFF_HZ = 4;

/**
 * The observed root's ground track and heading after each frame (integrated from the encoded rows), with glitches
 * removed (a 5-frame running median) and jitter (a zero-phase low-pass): the root term of eq. 25, solved on its own.
 */
export function smoothRootTrack(features: Float32Array, start: RootStart, D: number, fps: number): { rootTrack: RootStart[]; start: RootStart } {
  const frames = features.length / D;
  const walker = { ...start };
  const xs = new Float64Array(frames), zs = new Float64Array(frames), hs = new Float64Array(frames);
  for (let f = 0; f < frames; f++) {
    integrateRoot(walker, features[f * D], features[f * D + 1], features[f * D + 2]);
    [xs[f], zs[f], hs[f]] = [walker.x, walker.z, walker.heading];
  }
  const sections = butterworthLowpass(belowNyquist(ROOT_CUTOFF_HZ, fps), fps);
  const smooth = (v: Float64Array) => (frames > 6 ? filtfilt(runningMedian(v, 2), sections) : v);
  const [x, z, h] = [smooth(xs), smooth(zs), smooth(hs)];
  const rootTrack = Array.from({ length: frames }, (_, f) => ({ x: x[f], z: z[f], heading: h[f] }));
  const next = frames > 1 ? 1 : 0;
  return { rootTrack, start: { x: 2 * x[0] - x[next], z: 2 * z[0] - z[next], heading: 2 * h[0] - h[next] } };
}

function runningMedian(v: Float64Array, radius: number): Float64Array {
  return v.map((_, i) => {
    const w = Array.from(v.subarray(Math.max(0, i - radius), Math.min(v.length, i + radius + 1))).sort((a, b) => a - b);
    return w[Math.floor(w.length / 2)];
  });
}

/** The motion's jitter (m): per canonical point from its second differences at the motion's own rate, the median. */
function medianJitter(points: Float32Array): number {
  const K = CANONICAL_JOINTS.length;
  const per = Array.from({ length: K }, (_, k) => jitterSigma(points, K * 3, [k * 3, k * 3 + 1, k * 3 + 2])).sort((a, b) => a - b);
  return per[Math.floor(K / 2)];
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

/** The smallest observation σ (m) the map smoother assumes, so clean input is followed closely but not copied frame by frame. */
const SIGMA_FLOOR = 0.003;

/** What a canonical cleaner gets (at the model's fps) and gives back. */
export interface CanonicalInput {
  /** frames × 25 × 3 canonical points (canonical scale, floor at y = 0) and their world segment rotations (frames × 25 × 4). */
  points: Float32Array;
  rotations: Float32Array;
  fps: number;
  /** The jitter of these points (m): measured at the motion's own frame rate (jitterSigma, median over the points), less the averaging down to the model's rate. */
  jitter: number;
  /** The same points' slow part: low-passed below `hz` (slowBandHz of its jitter, or less for a capture of few frames per second) at the motion's own rate (every captured sample), then brought to the model's. */
  slow: { points: Float32Array; hz: number };
  /** The points low-passed at STEADY_BAND_HZ at the motion's own rate, brought to the model's, and their remaining jitter (m): for bone lengths. */
  steady: { points: Float32Array; jitter: number };
}
export interface CanonicalCleaned {
  positions: Float32Array;
  /** frames × 2 contact bits before labelling (the model's). */
  bits: Uint8Array;
  stats?: Partial<CleanupStats>;
}

/**
 * The `map` cleaner: the MAP motion under the generator, by the extended Kalman smoother (optimizer/smoother.ts).
 * Observation σ per point: the measured jitter by default; `sigmaRoot` sets the hips', `sigmaAngle` the others' as
 * that angle times the segment's length (a rotation error δ of a segment moves its end by δ · length).
 */
export function mapCleaner(args: { step: StepFn; info: GeneratorInfo; mean: ArrayLike<number>; std: ArrayLike<number>; options: CleanupOptions; onProgress?: (fraction: number) => void; signal?: AbortSignal }) {
  return async (input: CanonicalInput): Promise<CanonicalCleaned> => {
    const { info, options, signal } = args;
    await pause(signal);
    const K = CANONICAL_JOINTS.length;
    const frames = input.points.length / (K * 3);
    const encoded = encodeFeatures(info, input.points, input.rotations);
    const jitter = Math.max(SIGMA_FLOOR, input.jitter);
    const offsets = segmentOffsets(info, input.steady.points, input.steady.jitter);
    await pause(signal);
    const sigma = Array.from({ length: K }, (_, k) => {
      if (k === 0) return options.sigmaRoot ?? jitter;
      if (options.sigmaAngle === undefined) return jitter;
      return Math.max(SIGMA_FLOOR, options.sigmaAngle * Math.hypot(offsets[k * 3], offsets[k * 3 + 1], offsets[k * 3 + 2]));
    });
    const { rootTrack, start } = smoothRootTrack(encoded.features, encoded.start, info.onnx.dim, input.fps);
    await pause(signal);
    const r = await smoothFeatures({
      pause: () => pause(signal),
      step: args.step, info, mean: args.mean, std: args.std,
      points: input.points, sigma, encoded: encoded.features, rootTrack, start, offsets,
      onFrame: (f) => args.onProgress?.(f / frames),
    });
    // Decoded on the clip's own segment lengths, so the cleaned points keep its proportions.
    const decoded = decodeFeatures(info, r.features, start, offsets);
    await pause(signal);
    return {
      positions: withSlowPart(decoded.positions, input.slow, input.fps),
      bits: decoded.contacts,
      stats: { sigmaRoot: sigma[0], ...(options.sigmaAngle === undefined ? { jitter } : { sigmaAngle: options.sigmaAngle }), outlierShare: r.outlierShare },
    };
  };
}

/**
 * Below the slow band the capture itself is the better estimate: averaged over every sample at the motion's own
 * rate, its noise there is small, while the smoother's prior (a generator that predicts held-out capture less
 * well than a constant-velocity guess) biases slow motion by centimetres (docs/models/cleanup.md). So `map` keeps
 * its own motion above the band and the data's below it: cleaned − slow(cleaned) + slow(data), a complementary
 * filter. Feet are pinned after this, on the sum.
 *
 * The crossover rises as the jitter falls: where the motion's spectrum meets the noise's. Motion whose acceleration
 * is roughly white has a position spectrum falling as f⁻⁴ against white noise of variance σ², so the crossover goes
 * as σ^(-1/2): 4 Hz at 3 cm (measured best there), about 7 Hz at 1 cm and 3 Hz at 5 cm, kept within 2-8 Hz.
 */
function slowBandHz(jitter: number): number {
  return Math.min(8, Math.max(2, 4 * Math.sqrt(0.03 / Math.max(jitter, 1e-6))));
}

/** A planted foot point within this horizontal distance (m) of its anchor is left as captured (pinFeet). */
const PIN_TOLERANCE = 0.005;

/**
 * Bone lengths (and the offsets of joints riding on a canonical segment) are measured on the capture low-passed at
 * this cut-off: averaging every sample leaves about a third of the jitter (noise bandwidth ≈ 2.05 × cut-off of the
 * zero-phase filter), where correcting the raw lengths for jitter alone shortened the short spine bones by up to half
 * at 5 cm jitter, which bent the whole upper body (the head 10–15 cm off).
 */
const STEADY_BAND_HZ = 6;

function withSlowPart(cleaned: Float32Array, slowData: { points: Float32Array; hz: number }, fps: number): Float32Array {
  const width = CANONICAL_JOINTS.length * 3;
  const slowCleaned = lowpassRows(cleaned, width, fps, { cutoffHz: belowNyquist(slowData.hz, fps) });
  return cleaned.map((v, i) => v - slowCleaned[i] + slowData.points[i]);
}

/** A filter's cut-off at `fps`: `hz`, or under the Nyquist frequency for a capture of few frames per second. */
function belowNyquist(hz: number, fps: number): number {
  return Math.min(hz, fps * 0.45);
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
  signal?: AbortSignal,
): Promise<CleanupResult> {
  // Reference frames before the capture (CMU BVH 07_12 and 09_10 start with the rest pose at the origin, metres
  // from where the capture begins) are kept as they are: cleaning smoothed the jump into the capture's first seconds.
  const start = referenceFramesBefore(motion);
  if (start === 0) return cleanCapture(info, motion, method, clean, signal);
  const J = motion.joints.length;
  const rest = { ...motion, frames: motion.frames - start, positions: motion.positions.slice(start * J * 3), contacts: undefined };
  const cleaned = await cleanCapture(info, rest, method, clean, signal);
  const positions = new Float32Array(motion.positions.length);
  positions.set(motion.positions.subarray(0, start * J * 3));
  positions.set(cleaned.motion.positions, start * J * 3);
  const contacts = new Uint8Array(motion.frames * 2);
  contacts.set(cleaned.motion.contacts, start * 2);
  return { motion: { ...cleaned.motion, frames: motion.frames, positions, contacts }, stats: cleaned.stats };
}

/** A root jump this long (m) between two frames is not motion: a reference frame before the capture. */
const REFERENCE_JUMP = 0.5;
/** Reference frames are looked for among the first this many frames. */
const MAX_REFERENCE_FRAMES = 10;

/**
 * How many frames at the start of `motion` are reference frames: the frame the root jumps into by more than
 * REFERENCE_JUMP within the first MAX_REFERENCE_FRAMES (and the first half of the motion); else 0.
 */
export function referenceFramesBefore(motion: Motion): number {
  const J = motion.joints.length;
  const P = motion.positions;
  const last = Math.min(MAX_REFERENCE_FRAMES, Math.floor(motion.frames / 2));
  for (let f = 1; f <= last; f++) {
    const a = (f - 1) * J * 3, b = f * J * 3;
    if (Math.hypot(P[b] - P[a], P[b + 1] - P[a + 1], P[b + 2] - P[a + 2]) > REFERENCE_JUMP) return f;
  }
  return 0;
}

async function cleanCapture(
  info: GeneratorInfo,
  motion: Motion,
  method: CleanupMethod,
  clean: (input: CanonicalInput) => Promise<CanonicalCleaned>,
  signal?: AbortSignal,
): Promise<CleanupResult> {
  const began = performance.now();
  await pause(signal);
  const mapping = mapSkeleton(motion, legLength(info));
  await pause(signal);
  const K = CANONICAL_JOINTS.length;
  const fps = info.fps;
  // Before: the imported motion's canonical points at its own fps and at the model's, and their segment rotations
  // (the IK runs at the model's fps; rotations at the motion's own are interpolated).
  const beforePoints = toCanonical(motion, mapping);
  await pause(signal);
  const frames = resampledFrames(motion.frames, motion.fps, fps);
  // Down to the model's rate with the dropped frames averaged in, their extremes left out (a 120 fps capture gives 30 fps
  // frames of about half the jitter, and a one-frame glitch is gone; the mean of 3 of 5 sorted values has about the
  // jitter of a mean of 4, a median of w that of a mean of 2w/π).
  const { values: points, window } = resampleRobust(beforePoints, K * 3, motion.fps, fps, frames);
  await pause(signal);
  // The models stand on y = 0; imported clips need not (CMU AMC floors sit a few centimetres off).
  const floor = floorHeight(points);
  for (let i = 1; i < points.length; i += 3) points[i] -= floor;
  const jitter = medianJitter(beforePoints);
  await pause(signal);
  const rotations = await rotationsWithPauses(info, points, signal);
  const beforeRotations = resampleQuaternions(rotations, K, fps, motion.fps, motion.frames);
  await pause(signal);
  const slowHz = belowNyquist(slowBandHz(jitter), motion.fps);
  const slow = { points: resampleLinear(lowpassRows(beforePoints, K * 3, motion.fps, { cutoffHz: slowHz }), K * 3, motion.fps, fps, frames), hz: slowHz };
  for (let i = 1; i < slow.points.length; i += 3) slow.points[i] -= floor;
  const steadyHz = belowNyquist(STEADY_BAND_HZ, motion.fps);
  const steadyMotion = lowpassMotion(motion, { cutoffHz: steadyHz });
  await pause(signal);
  const steadyJitter = jitter * Math.sqrt(Math.min(1, (2.05 * steadyHz) / motion.fps));
  const steadyBefore = toCanonical(steadyMotion, mapping);
  const steady = { points: resampleLinear(steadyBefore, K * 3, motion.fps, fps, frames), jitter: steadyJitter };
  await pause(signal);
  const cleaned = await clean({ points, rotations, fps, jitter: jitter / Math.sqrt(window >= 5 ? window - 1 : (2 * window) / Math.PI), slow, steady });
  const { skeleton } = info;
  // Contacts labelled on the cleaned motion (the model's bits with the feet's heights and speeds), planted feet pinned.
  const contacts30 = labelContacts(cleaned.positions, cleaned.bits, skeleton.joints, fps);
  const planted = { positions: pinFeet(cleaned.positions, contacts30, skeleton.joints, PIN_TOLERANCE), contacts: contacts30 };
  for (let i = 1; i < planted.positions.length; i += 3) planted.positions[i] += floor;
  const afterRotations = await rotationsWithPauses(info, planted.positions, signal);
  await pause(signal);
  // After: back at the imported motion's frame times.
  const afterPoints = resampleLinear(planted.positions, K * 3, fps, motion.fps, motion.frames);
  const after = { points: afterPoints, rotations: resampleQuaternions(afterRotations, K, fps, motion.fps, motion.frames) };
  await pause(signal);
  const moved = fromCanonical(steadyMotion, mapping, { points: steadyBefore, rotations: beforeRotations }, after, steadyJitter / mapping.scale);
  await pause(signal);
  const contacts = resampleNearest(planted.contacts, 2, fps, motion.fps, motion.frames);
  return {
    motion: { ...moved, contacts },
    stats: { method, scheme: mapping.scheme, ...cleaned.stats, computeMs: performance.now() - began },
  };
}

/** The baseline: a zero-phase Butterworth low-pass on the imported joint positions; contacts by height and speed. */
export function lowpassCleanup(motion: Motion, options: CleanupOptions): CleanupResult {
  const began = performance.now();
  const cutoffHz = belowNyquist(options.cutoffHz ?? 6, motion.fps);
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

/** The canonical offsets rescaled to the segment lengths of `points` (frames × 25 × 3) with `jitter` (m) taken out (medianBoneLengths). */
function segmentOffsets(info: GeneratorInfo, points: Float32Array, jitter: number): Float32Array {
  const { joints, parents, offsets } = info.skeleton;
  const lengths = medianBoneLengths({ fps: 1, frames: points.length / (joints.length * 3), joints, parents, positions: points }, jitter);
  const out = Float32Array.from(offsets);
  for (let j = 1; j < joints.length; j++) {
    const rest = Math.hypot(offsets[j * 3], offsets[j * 3 + 1], offsets[j * 3 + 2]);
    if (rest > 0) for (let a = 0; a < 3; a++) out[j * 3 + a] = (offsets[j * 3 + a] / rest) * lengths[j];
  }
  return out;
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
