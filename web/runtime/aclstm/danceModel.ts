// The dance models' description files (public/models/aclstm.json and aclstm-vanilla.json, written by
// python -m training.aclstm.export): skeleton, ONNX step signature, feature layout, normalisation, the seed
// motions per style and the real pose change per style. `parseDanceInfo` checks everything the runtime
// relies on and names the first bad field.
import { modelInfoFormat } from '../../model/modelInfo';

export interface DanceInfo {
  id: string;
  kind: string;
  fps: number;
  /** ONNX file name, relative to the JSON. */
  file: string;
  description?: string;
  /** "auto-conditioned" (acLSTM) or "teacher-forced" (the vanilla baseline). */
  training_scheme?: string;
  /** Style names, in the order of the one-hot `style` input. */
  styles: string[];
  skeleton: {
    joints: string[];
    parents: number[];
    /** joints × 3, metres: each point's rest offset from its parent (world axes of the rest pose). */
    offsets: number[];
  };
  features: {
    /** 3 × joints: [root dx per frame, root height, root dz per frame, then point − root for points 1…]. */
    dim: number;
    seed_frames: number;
    layout?: string;
  };
  onnx: {
    inputs: string[]; // [x, style, h, c, steps]
    outputs: string[]; // [ys, h_out, c_out]
    opset?: number;
    layers: number;
    hidden: number;
    dim: number;
    styles: number;
  };
  normalisation: { mean: number[]; std: number[] };
  seeds: DanceSeed[];
  /** Median per-second pose change of the real held-out clips of each style, m/s. */
  real_pose_change: Record<string, number>;
}

export interface DanceSeed {
  style: string;
  name: string;
  file?: string;
  start_seconds?: number;
  /** `seed_frames` feature rows in physical units; the seed's root ends at x = z = 0. */
  frames: number[][];
}

/** One call runs `steps` steps, each output frame fed back inside the graph: ys is steps × batch × dim. */
export const DANCE_INPUTS = ['x', 'style', 'h', 'c', 'steps'] as const;
export const DANCE_OUTPUTS = ['ys', 'h_out', 'c_out'] as const;

const format = modelInfoFormat<DanceInfo>('DanceInfoError', 'aclstm.json', (check, root) => {
  const { fail, obj, posInt, numbers, strings } = check;
  const styles = strings(root.styles, 'styles');
  if (styles.length === 0 || new Set(styles).size !== styles.length) fail('styles must be a non-empty list of distinct names');
  const J = check.skeleton(root.skeleton);

  const onnx = obj(root.onnx, 'onnx');
  check.names(onnx.inputs, 'onnx.inputs', DANCE_INPUTS);
  check.names(onnx.outputs, 'onnx.outputs', DANCE_OUTPUTS);
  posInt(onnx.layers, 'onnx.layers');
  posInt(onnx.hidden, 'onnx.hidden');
  const D = posInt(onnx.dim, 'onnx.dim');
  if (D !== 3 * J) fail(`onnx.dim is ${D} but ${J} skeleton points need ${3 * J} features`);
  if (posInt(onnx.styles, 'onnx.styles') !== styles.length) fail(`onnx.styles is ${String(onnx.styles)} but there are ${styles.length} styles`);

  const features = obj(root.features, 'features');
  if (posInt(features.dim, 'features.dim') !== D) fail(`features.dim is ${String(features.dim)}, expected ${D}`);
  const seedFrames = posInt(features.seed_frames, 'features.seed_frames');
  check.normalisation(root.normalisation, D);

  if (!Array.isArray(root.seeds) || root.seeds.length === 0) fail('seeds must be a non-empty array');
  (root.seeds as unknown[]).forEach((s, i) => {
    const seed = obj(s, `seeds[${i}]`);
    if (typeof seed.name !== 'string') fail(`seeds[${i}].name must be a string`);
    if (typeof seed.style !== 'string' || !styles.includes(seed.style)) fail(`seeds[${i}].style must be one of ${styles.join(', ')}, got ${String(seed.style)}`);
    if (!Array.isArray(seed.frames) || seed.frames.length !== seedFrames) fail(`seeds[${i}].frames must hold ${seedFrames} frames`);
    (seed.frames as unknown[]).forEach((f, k) => numbers(f, `seeds[${i}].frames[${k}]`, D));
  });
  const seeds = root.seeds as DanceSeed[];
  const change = obj(root.real_pose_change, 'real_pose_change');
  for (const style of styles) {
    if (!seeds.some((s) => s.style === style)) fail(`no seed motion for style "${style}"`);
    check.positive(change[style], `real_pose_change.${style}`);
  }
});

export const DanceInfoError = format.InfoError;
/** Checks a parsed dance model JSON; throws DanceInfoError naming the first bad field. */
export const parseDanceInfo = format.parse;
/** Fetches and checks a dance model JSON. */
export const loadDanceInfo = format.load;

/** Indices into `info.seeds` of one style's seed motions, in file order. */
export function seedsOfStyle(info: DanceInfo, style: string): number[] {
  const out: number[] = [];
  info.seeds.forEach((s, i) => {
    if (s.style === style) out.push(i);
  });
  return out;
}
