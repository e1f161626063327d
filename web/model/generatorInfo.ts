// The locomotion generator's description file (public/models/generator.json, written by
// python -m training.generator.export): skeleton, ONNX step signature, feature layout, normalisation and
// seed states. `parseGeneratorInfo` checks everything the runtime relies on, so a mismatched or
// truncated file fails at load time with a message saying which field is wrong.

import { modelInfoFormat } from './modelInfo';

export interface GeneratorInfo {
  id: string;
  kind: string;
  fps: number;
  /** A user's pack (python -m training.own): its card's measurements; `real.sliding_low_foot` is its held-out clips' sliding, m/s. */
  pack?: { measures?: { real?: { sliding_low_foot?: number } } };
  /** ONNX file name, relative to the JSON. */
  file: string;
  /**
   * A style-conditioned generator (python -m training.style_generator.export, issue 39): its style names in the order of
   * the step's `style` input, the first the default. The step then takes a fourth input, style (B × styles weights: a
   * one-hot, or a convex combination of one-hots that blends the styles' embeddings). Absent: no style input.
   */
  styles?: string[];
  /** The terms the model comes under (a style generator: CC BY-NC 4.0, non-commercial) and what it was trained on. */
  licence?: string;
  /** With `styles`: each style's real held-out foot sliding (lowest foot point, m/s), the readout's reference. */
  held_out_sliding?: Record<string, number>;
  data?: string;
  description?: string;
  skeleton: {
    joints: string[];
    parents: number[];
    /** joints × 3, metres, each joint's rest offset in its parent's frame. */
    offsets: number[];
  };
  onnx: {
    inputs: string[]; // [x, h, c], or [x, h, c, style] with `styles`
    outputs: string[]; // [weights, mu, sigma, h_out, c_out]
    opset?: number;
    layers: number;
    hidden: number;
    mixtures: number;
    dim: number;
    /** With `styles`: how many (the style input's width) and each style's embedding size. */
    styles?: number;
    style_dim?: number;
  };
  features: {
    names: string[];
    /** Skeleton joints with a rotation vector in the features, in feature order. */
    joints: number[];
    /** Skeleton joints that always sit at their reference rotation. */
    fixed_joints: number[];
    layout?: string;
    /** One quaternion (x, y, z, w) per skeleton joint; [0] is the root tilt's reference. */
    references: number[][];
  };
  normalisation: { mean: number[]; std: number[] };
  seeds: GeneratorSeed[];
  /** How the page draws from the mixture; absent = fresh normals every frame. */
  sampling?: { noise_correlation: number };
}

/** ρ of the normals the generator's draws hold over frames (sampler.ts HeldNoise); 0 = fresh every frame. */
export function noiseCorrelation(info: GeneratorInfo): number {
  return info.sampling?.noise_correlation ?? 0;
}

export interface GeneratorSeed {
  name: string;
  category?: string;
  /** With `styles`: the style this seed's state was estimated under (one of `styles`). */
  style?: string;
  /** First input frame, normalised (dim values). */
  x: number[];
  /** LSTM state, layers × hidden, layer-major. */
  h: number[];
  c: number[];
}

export const EXPECTED_INPUTS = ['x', 'h', 'c'] as const;
/** A style generator's step inputs. */
export const STYLED_INPUTS = ['x', 'h', 'c', 'style'] as const;
export const EXPECTED_OUTPUTS = ['weights', 'mu', 'sigma', 'h_out', 'c_out'] as const;

/** The ONNX step's inputs, flattened: x (B×D), h and c (layers×B×H); a style generator's also style (B×styles). */
export interface StepInputs {
  batch: number;
  x: ArrayLike<number>;
  h: ArrayLike<number>;
  c: ArrayLike<number>;
  style?: ArrayLike<number>;
}

/** The style names of a style generator; [] for a generator without a style input. */
export function styleNames(info: GeneratorInfo): string[] {
  return info.styles ?? [];
}

/** How far a blend's weights may sum away from 1 (they are float32 on the way to the step). */
const BLEND_SUM_TOLERANCE = 1e-4;

/**
 * The style input for one row: a style's name gives its one-hot; weights (one per style, each ≥ 0, summing to 1) blend
 * the styles' embeddings, as the page does over a second when the style is switched; undefined gives the first style.
 * Throws for a model without styles, an unknown name or weights that are not a convex combination.
 */
export function styleVector(info: GeneratorInfo, style?: string | ArrayLike<number>): Float32Array {
  const styles = styleNames(info);
  if (!styles.length) throw new Error(`the model "${info.id}" has no styles`);
  const out = new Float32Array(styles.length);
  if (style === undefined) {
    out[0] = 1;
  } else if (typeof style === 'string') {
    const k = styles.indexOf(style);
    if (k < 0) throw new Error(`unknown style "${style}" for the model "${info.id}": it has ${styles.join(', ')}`);
    out[k] = 1;
  } else {
    if (style.length !== styles.length) throw new Error(`a style blend needs ${styles.length} weights (${styles.join(', ')}), got ${style.length}`);
    let sum = 0;
    for (let k = 0; k < styles.length; k++) {
      const w = style[k];
      if (typeof w !== 'number' || !Number.isFinite(w) || w < 0) throw new Error(`style weight ${k} (${styles[k]}) must be a finite number ≥ 0, got ${String(w)}`);
      out[k] = w;
      sum += w;
    }
    if (Math.abs(sum - 1) > BLEND_SUM_TOLERANCE) throw new Error(`style weights must sum to 1, got ${sum}`);
  }
  return out;
}

/** The seed states of `style` (all seeds for a model without styles, or with `style` undefined: the first style's). */
export function styleSeeds(info: GeneratorInfo, style?: string): number[] {
  const styles = styleNames(info);
  const all = info.seeds.map((_, i) => i);
  if (!styles.length) {
    if (style !== undefined) throw new Error(`the model "${info.id}" has no styles`);
    return all;
  }
  const name = style ?? styles[0];
  if (!styles.includes(name)) throw new Error(`unknown style "${name}" for the model "${info.id}": it has ${styles.join(', ')}`);
  return all.filter((i) => info.seeds[i].style === name);
}

export interface StepOutputs {
  weights: Float32Array;
  mu: Float32Array;
  sigma: Float32Array;
  h_out: Float32Array;
  c_out: Float32Array;
}

/** Index of the first joint rotation vector in a feature row (after dtx, dtz, dry, ty, tilt xyz). */
export const JOINT_FEATURES_START = 7;

const format = modelInfoFormat<GeneratorInfo>('GeneratorInfoError', 'generator.json', (check, root) => {
  const { fail, obj, posInt, numbers, strings } = check;
  const J = check.skeleton(root.skeleton);

  let styleCount = 0;
  if (root.styles !== undefined) {
    const styles = strings(root.styles, 'styles');
    if (styles.length === 0) fail('styles must name at least one style');
    if (new Set(styles).size !== styles.length) fail(`styles has a name twice: [${styles}]`);
    styleCount = styles.length;
  }
  if (root.held_out_sliding !== undefined) {
    const sliding = obj(root.held_out_sliding, 'held_out_sliding');
    const styles = (root.styles as string[] | undefined) ?? [];
    for (const [style, v] of Object.entries(sliding)) {
      if (!styles.includes(style)) fail(`held_out_sliding names "${style}", which is not one of styles`);
      if (typeof v !== 'number' || !Number.isFinite(v) || v < 0) fail(`held_out_sliding.${style} must be a finite number ≥ 0, got ${String(v)}`);
    }
  }
  for (const key of ['licence', 'data'] as const) {
    if (root[key] !== undefined && (typeof root[key] !== 'string' || !(root[key] as string).trim())) fail(`${key} must be a non-empty string`);
  }

  const onnx = obj(root.onnx, 'onnx');
  check.names(onnx.inputs, 'onnx.inputs', styleCount ? STYLED_INPUTS : EXPECTED_INPUTS);
  if (styleCount && onnx.styles !== undefined && onnx.styles !== styleCount) fail(`onnx.styles is ${String(onnx.styles)} but styles names ${styleCount}`);
  check.names(onnx.outputs, 'onnx.outputs', EXPECTED_OUTPUTS);
  const layers = posInt(onnx.layers, 'onnx.layers');
  const hidden = posInt(onnx.hidden, 'onnx.hidden');
  posInt(onnx.mixtures, 'onnx.mixtures');
  const D = posInt(onnx.dim, 'onnx.dim');

  const features = obj(root.features, 'features');
  const featureJoints = numbers(features.joints, 'features.joints');
  const fixed = numbers(features.fixed_joints, 'features.fixed_joints');
  const expectedDim = JOINT_FEATURES_START + 3 * featureJoints.length + 2;
  if (D !== expectedDim) fail(`onnx.dim is ${D} but the layout with ${featureJoints.length} feature joints needs ${expectedDim}`);
  const names = strings(features.names, 'features.names');
  if (names.length !== D) fail(`features.names has ${names.length} names, expected ${D}`);
  for (const [path, list] of [['features.joints', featureJoints], ['features.fixed_joints', fixed]] as const) {
    list.forEach((j, i) => {
      if (!Number.isInteger(j) || j <= 0 || j >= J) fail(`${path}[${i}] = ${j} is not a non-root joint index (1..${J - 1})`);
    });
  }
  const covered = new Set([...featureJoints, ...fixed]);
  if (covered.size !== featureJoints.length + fixed.length || covered.size !== J - 1) {
    fail('features.joints and features.fixed_joints must together list every non-root joint exactly once');
  }
  if (!Array.isArray(features.references) || features.references.length !== J) fail(`features.references must hold ${J} quaternions`);
  (features.references as unknown[]).forEach((q, j) => {
    const v = numbers(q, `features.references[${j}]`, 4);
    const n = Math.hypot(v[0], v[1], v[2], v[3]);
    if (Math.abs(n - 1) > 1e-3) fail(`features.references[${j}] is not a unit quaternion (norm ${n})`);
  });

  check.normalisation(root.normalisation, D);

  if (!Array.isArray(root.seeds) || root.seeds.length === 0) fail('seeds must be a non-empty array');
  (root.seeds as unknown[]).forEach((s, i) => {
    const seed = obj(s, `seeds[${i}]`);
    if (typeof seed.name !== 'string') fail(`seeds[${i}].name must be a string`);
    numbers(seed.x, `seeds[${i}].x`, D);
    numbers(seed.h, `seeds[${i}].h`, layers * hidden);
    numbers(seed.c, `seeds[${i}].c`, layers * hidden);
    if (styleCount && !(root.styles as string[]).includes(seed.style as string)) {
      fail(`seeds[${i}].style must be one of the styles (${(root.styles as string[]).join(', ')}), got ${String(seed.style)}`);
    }
  });
  for (const style of styleCount ? (root.styles as string[]) : []) {
    if (!(root.seeds as { style?: unknown }[]).some((s) => s.style === style)) fail(`no seed state of style "${style}"`);
  }

  if (root.sampling !== undefined) {
    const c = obj(root.sampling, 'sampling').noise_correlation;
    if (typeof c !== 'number' || !(c >= 0 && c < 1)) fail(`sampling.noise_correlation must be a number from 0 up to (not including) 1, got ${String(c)}`);
  }
});

export const GeneratorInfoError = format.InfoError;
/** Checks a parsed generator JSON; throws GeneratorInfoError naming the first bad field. */
export const parseGeneratorInfo = format.parse;
/** Fetches and checks the generator JSON. */
export const loadGeneratorInfo = format.load;
