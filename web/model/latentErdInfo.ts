// The latent ERD's two description files, written by the training side: public/models/latent-erd.json
// (python -m training.latent_erd.export: the ERD step's signature, latent normalisation, look-ahead,
// seeds) and the motion autoencoder's public/models/manifold.json (python -m training.autoencoder.export:
// the skeleton, the 80-value row layout and its normalisation, the decoder file). Each parse checks what
// the runtime relies on and names the file and the first bad field; `checkLatentErdPair` checks that the
// two belong together. Also the checks of the latent ERD's request options that the page API and the
// worker share (the per-frame control signal, the seed's seed state).
import { describeValue } from '../motion/describe';
import { checkNoHoles } from '../motion/validate';
import { MAX_FRAMES } from '../motion/text';
import { modelInfoFormat, type FieldChecks } from './modelInfo';

export const LATENT_ERD_INPUTS = ['z', 'control', 'h', 'c'] as const;
export const LATENT_ERD_OUTPUTS = ['z_next', 'h_out', 'c_out'] as const;
export const DECODER_INPUTS = ['latent'] as const;
export const DECODER_OUTPUTS = ['rows'] as const;

export interface LatentErdSeed {
  /** "walk 06_01", "run 16_36". */
  name: string;
  /** "walk" or "run". */
  category: string;
  file?: string;
  /** P latent steps (normalised), P × latent. */
  latents: number[][];
  /** Their step controls (normalised), P × control_dim: the 4 frames' [forward, sideways, turn] flattened. */
  controls: number[][];
}

export interface LatentErdInfo {
  id: string;
  kind: string;
  /** The ERD step's ONNX file, relative to the JSON. */
  file: string;
  /** The autoencoder's JSON (manifold.json), relative to this one. */
  manifold: string;
  fps: number;
  /** Frames per latent step (4). */
  pooling: number;
  /** Latent steps on each side of a step that its decoded frames depend on (9). */
  radius: number;
  /** ERD steps guessed ahead for the decoder's future context (3). */
  lookahead: number;
  latent: number;
  /** pooling × 3: one step's control. */
  control_dim: number;
  hidden: number;
  layers: number;
  inputs: string[];
  outputs: string[];
  latent_normalisation: { mean: number[]; std: number[] };
  /** 1st and 99th percentiles of the training control, per channel. */
  control_range?: Record<'forward' | 'sideways' | 'turn', [number, number]>;
  seeds: LatentErdSeed[];
  parity_max_abs?: number;
  report?: Record<string, unknown>;
}

/** How a manifold row is laid out (the autoencoder's and the VAE-LSTM's files alike). */
export interface ManifoldRowsInfo {
  dim: number;
  /** [start, end) of the joint positions (root facing frame: x left, y up, z forward), the control and the contacts. */
  positions: [number, number];
  control: [number, number];
  contacts: [number, number];
  joints: string[];
}

export interface ManifoldInfo {
  id: string;
  kind: string;
  fps: number;
  pooling: number;
  radius: number;
  kernel?: number;
  latent: number;
  files: { encoder: string; decoder: string };
  skeleton: {
    joints: string[];
    parents: number[];
    /** Rest offsets, joints × [x, y, z] (metres). */
    offsets: number[][];
  };
  rows: ManifoldRowsInfo;
  normalisation: { mean: number[]; std: number[] };
  report?: Record<string, unknown>;
}

const erdFormat = modelInfoFormat<LatentErdInfo>('LatentErdInfoError', 'latent-erd.json', (check, root) => {
  const { fail, obj, posInt, numbers } = check;
  if (typeof root.file !== 'string' || !root.file) fail('file must name the ERD step ONNX file');
  if (typeof root.manifold !== 'string' || !root.manifold) fail('manifold must name the autoencoder JSON (manifold.json)');
  check.names(root.inputs, 'inputs', LATENT_ERD_INPUTS);
  check.names(root.outputs, 'outputs', LATENT_ERD_OUTPUTS);
  const pooling = posInt(root.pooling, 'pooling');
  posInt(root.radius, 'radius');
  const lookahead = check.num(root.lookahead, 'lookahead');
  if (!Number.isInteger(lookahead) || lookahead < 0) fail(`lookahead must be an integer ≥ 0, got ${lookahead}`);
  const latent = posInt(root.latent, 'latent');
  const controlDim = posInt(root.control_dim, 'control_dim');
  if (controlDim !== pooling * 3) fail(`control_dim is ${controlDim} but ${pooling} frames of [forward, sideways, turn] need ${pooling * 3}`);
  posInt(root.hidden, 'hidden');
  posInt(root.layers, 'layers');
  const norm = obj(root.latent_normalisation, 'latent_normalisation');
  numbers(norm.mean, 'latent_normalisation.mean', latent);
  const std = numbers(norm.std, 'latent_normalisation.std', latent);
  const badStd = std.findIndex((s) => s <= 0);
  if (badStd >= 0) fail(`latent_normalisation.std[${badStd}] = ${std[badStd]} must be positive`);
  if (!Array.isArray(root.seeds) || root.seeds.length === 0) fail('seeds must be a non-empty array');
  let steps = -1;
  (root.seeds as unknown[]).forEach((s, i) => {
    const seed = obj(s, `seeds[${i}]`);
    if (typeof seed.name !== 'string') fail(`seeds[${i}].name must be a string`);
    if (typeof seed.category !== 'string') fail(`seeds[${i}].category must be a string ("walk" or "run")`);
    if (!Array.isArray(seed.latents) || seed.latents.length === 0) fail(`seeds[${i}].latents must be a non-empty array of latent steps`);
    const P = (seed.latents as unknown[]).length;
    if (steps >= 0 && P !== steps) fail(`seeds[${i}] has ${P} latent steps, seeds[0] has ${steps}`);
    steps = P;
    if (!Array.isArray(seed.controls) || seed.controls.length !== P) fail(`seeds[${i}].controls must hold ${P} step controls, one per latent step`);
    (seed.latents as unknown[]).forEach((z, k) => numbers(z, `seeds[${i}].latents[${k}]`, latent));
    (seed.controls as unknown[]).forEach((c, k) => numbers(c, `seeds[${i}].controls[${k}]`, controlDim));
  });
});

const manifoldFormat = modelInfoFormat<ManifoldInfo>('ManifoldInfoError', 'manifold.json', (check, root) => {
  const { fail, obj, posInt, numbers, strings } = check;
  posInt(root.pooling, 'pooling');
  posInt(root.radius, 'radius');
  posInt(root.latent, 'latent');
  const files = obj(root.files, 'files');
  if (typeof files.decoder !== 'string' || !files.decoder) fail('files.decoder must name the decoder ONNX file');
  const skeleton = obj(root.skeleton, 'skeleton');
  const joints = strings(skeleton.joints, 'skeleton.joints');
  const J = joints.length;
  if (J === 0) fail('skeleton.joints is empty');
  const parents = numbers(skeleton.parents, 'skeleton.parents', J);
  parents.forEach((p, j) => {
    if (j === 0 ? p !== -1 : !Number.isInteger(p) || p < 0 || p >= j) fail(`skeleton.parents[${j}] = ${p}: the root must be first (-1) and parents must precede children`);
  });
  if (!Array.isArray(skeleton.offsets) || skeleton.offsets.length !== J) fail(`skeleton.offsets must hold ${J} [x, y, z] offsets`);
  (skeleton.offsets as unknown[]).forEach((o, j) => numbers(o, `skeleton.offsets[${j}]`, 3));
  check.normalisation(root.normalisation, checkRowLayout(check, root.rows, joints));
});

/**
 * The 80-value row layout of manifold.json and vae-lstm.json (`rows`: dim, the [start, end) of the joint
 * positions, control and contacts, the joints in the skeleton's order); returns the row's dim.
 */
export function checkRowLayout(check: FieldChecks, value: unknown, joints: readonly string[]): number {
  const rows = check.obj(value, 'rows');
  const dim = check.posInt(rows.dim, 'rows.dim');
  const range = (name: 'positions' | 'control' | 'contacts', size: number) => {
    const [a, b] = check.numbers(rows[name], `rows.${name}`, 2);
    if (!(Number.isInteger(a) && Number.isInteger(b) && a >= 0 && b <= dim && b - a === size)) check.fail(`rows.${name} is [${a}, ${b}], expected ${size} channels within the ${dim}-value row`);
  };
  range('positions', 3 * joints.length);
  range('control', 3);
  range('contacts', 2);
  if (check.strings(rows.joints, 'rows.joints').join() !== joints.join()) check.fail('rows.joints must list skeleton.joints in the same order');
  return dim;
}

export const LatentErdInfoError = erdFormat.InfoError;
export const ManifoldInfoError = manifoldFormat.InfoError;
/** Checks a parsed latent-erd.json; throws LatentErdInfoError naming the file and the first bad field. */
export const parseLatentErdInfo = erdFormat.parse;
export const loadLatentErdInfo = erdFormat.load;
/** Checks a parsed manifold.json; throws ManifoldInfoError naming the file and the first bad field. */
export const parseManifoldInfo = manifoldFormat.parse;
export const loadManifoldInfo = manifoldFormat.load;

/** Throws a LatentErdInfoError (naming both files) unless the ERD and the autoencoder fit together. */
export function checkLatentErdPair(erd: LatentErdInfo, manifold: ManifoldInfo, erdSource = 'latent-erd.json', manifoldSource = 'manifold.json'): void {
  const mismatch = (field: string, a: unknown, b: unknown) => {
    if (a !== b) throw new LatentErdInfoError(erdSource, `${field} is ${String(a)} but ${manifoldSource} has ${String(b)}: the two were not exported together`);
  };
  mismatch('fps', erd.fps, manifold.fps);
  mismatch('pooling', erd.pooling, manifold.pooling);
  mismatch('radius', erd.radius, manifold.radius);
  mismatch('latent', erd.latent, manifold.latent);
}

/** The ERD and its autoencoder, as the worker loads them. */
export interface LatentErdModel {
  erd: LatentErdInfo;
  manifold: ManifoldInfo;
  /** The decoder ONNX file's URL (manifold.json's files.decoder, relative to it). */
  decoderUrl: string;
  /** The encoder ONNX file's URL (manifold.json's files.encoder, relative to it): the `manifold` clean-up. */
  encoderUrl?: string;
}

/** Fetches latent-erd.json, then the manifold.json it names, and checks both and their pair. */
export async function loadLatentErdModel(url: string): Promise<LatentErdModel> {
  const erd = await loadLatentErdInfo(url);
  const manifoldUrl = new URL(erd.manifold, url).href;
  const manifold = await loadManifoldInfo(manifoldUrl);
  checkLatentErdPair(erd, manifold, url, manifoldUrl);
  return {
    erd,
    manifold,
    decoderUrl: new URL(manifold.files.decoder, manifoldUrl).href,
    ...(typeof manifold.files.encoder === 'string' && manifold.files.encoder ? { encoderUrl: new URL(manifold.files.encoder, manifoldUrl).href } : {}),
  };
}

/** Index into `seeds` of `seed`'s seed state: seed mod the count, among the `category` ones when given ("walk", "run"). */
export function latentSeedIndex(info: Pick<LatentErdInfo, 'seeds'>, seed: number, category?: string): number {
  const pool = info.seeds.flatMap((s, i) => (category === undefined || s.category === category ? [i] : []));
  if (!pool.length) throw new Error(`the latent ERD has no "${category}" seeds (it has ${info.seeds.map((s) => s.name).join(', ')})`);
  return pool[(seed >>> 0) % pool.length];
}

/**
 * Bounds of a control value the page accepts (the training data's 1st–99th percentiles are about
 * −0.2…3.2 m/s forward, ±0.5 m/s sideways, ±2.8 rad/s turn: latent-erd.json control_range).
 */
export const MAX_CONTROL_SPEED = 5;
export const MAX_CONTROL_TURN = 2 * Math.PI;

/**
 * Checks a per-frame control signal: an array of at least `frames` (and at most MAX_FRAMES) triples
 * [forward m/s, sideways m/s, turn rad/s], each finite, forward and sideways within ±MAX_CONTROL_SPEED and
 * turn within ±MAX_CONTROL_TURN. Returns it flattened (length × 3).
 */
export function checkControlSignal(control: unknown, frames: number, name = 'control'): Float64Array {
  const shape = `[forward m/s, sideways m/s, turn rad/s]`;
  if (!Array.isArray(control)) throw new TypeError(`${name} must be an array of ${shape} triples, one per frame, got ${describeValue(control)}`);
  if (control.length < frames) throw new RangeError(`${name} has ${control.length} frames; it needs at least one per frame (${frames})`);
  if (control.length > MAX_FRAMES) throw new RangeError(`${name} has ${control.length} frames; at most ${MAX_FRAMES} are accepted`);
  checkNoHoles(control, name);
  const out = new Float64Array(control.length * 3);
  for (let f = 0; f < control.length; f++) {
    const c = control[f] as unknown;
    if (Array.isArray(c)) checkNoHoles(c, `${name}[${f}]`);
    if (!Array.isArray(c) || c.length !== 3 || !c.every((v) => typeof v === 'number' && Number.isFinite(v))) {
      throw new TypeError(`${name}[${f}] must be a triple of finite numbers ${shape}, got ${describeValue(c)}`);
    }
    const [fwd, side, turn] = c as number[];
    if (Math.abs(fwd) > MAX_CONTROL_SPEED || Math.abs(side) > MAX_CONTROL_SPEED || Math.abs(turn) > MAX_CONTROL_TURN) {
      throw new RangeError(
        `${name}[${f}] ${describeValue(c)} is out of range: forward and sideways within ±${MAX_CONTROL_SPEED} m/s, turn within ±${+MAX_CONTROL_TURN.toFixed(2)} rad/s`,
      );
    }
    out.set(c as number[], f * 3);
  }
  return out;
}
