// The locomotion generator's description file (public/models/generator.json, written by
// training/export_generator.py): skeleton, ONNX step signature, feature layout, normalisation and
// seed states. `parseGeneratorInfo` checks everything the runtime relies on, so a mismatched or
// truncated file fails at load time with a message saying which field is wrong.

export interface GeneratorInfo {
  id: string;
  kind: string;
  fps: number;
  /** ONNX file name, relative to the JSON. */
  file: string;
  description?: string;
  skeleton: {
    joints: string[];
    parents: number[];
    /** joints × 3, metres, each joint's rest offset in its parent's frame. */
    offsets: number[];
  };
  onnx: {
    inputs: string[]; // [x, h, c]
    outputs: string[]; // [weights, mu, sigma, h_out, c_out]
    opset?: number;
    layers: number;
    hidden: number;
    mixtures: number;
    dim: number;
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
}

export interface GeneratorSeed {
  name: string;
  category?: string;
  /** First input frame, normalised (dim values). */
  x: number[];
  /** LSTM state, layers × hidden, layer-major. */
  h: number[];
  c: number[];
}

export const EXPECTED_INPUTS = ['x', 'h', 'c'] as const;
export const EXPECTED_OUTPUTS = ['weights', 'mu', 'sigma', 'h_out', 'c_out'] as const;

/** Index of the first joint rotation vector in a feature row (after dtx, dtz, dry, ty, tilt xyz). */
export const JOINT_FEATURES_START = 7;

export class GeneratorInfoError extends Error {
  constructor(source: string, message: string) {
    super(`${source}: ${message}`);
    this.name = 'GeneratorInfoError';
  }
}

/** Fetches and checks the generator JSON. */
export async function loadGeneratorInfo(url: string | URL): Promise<GeneratorInfo> {
  const source = String(url);
  let response: Response;
  try {
    response = await fetch(url);
  } catch (err) {
    throw new GeneratorInfoError(source, `could not fetch (${err instanceof Error ? err.message : String(err)})`);
  }
  if (!response.ok) throw new GeneratorInfoError(source, `HTTP ${response.status} ${response.statusText}`);
  let raw: unknown;
  try {
    raw = await response.json();
  } catch (err) {
    throw new GeneratorInfoError(source, `not valid JSON (${err instanceof Error ? err.message : String(err)})`);
  }
  return parseGeneratorInfo(raw, source);
}

/** Checks a parsed generator JSON; throws GeneratorInfoError naming the first bad field. */
export function parseGeneratorInfo(raw: unknown, source = 'generator.json'): GeneratorInfo {
  const fail = (message: string): never => {
    throw new GeneratorInfoError(source, message);
  };
  const obj = (value: unknown, path: string): Record<string, unknown> =>
    typeof value === 'object' && value !== null && !Array.isArray(value) ? (value as Record<string, unknown>) : fail(`${path} must be an object`);
  const num = (value: unknown, path: string): number => (typeof value === 'number' && Number.isFinite(value) ? value : fail(`${path} must be a finite number`));
  const posInt = (value: unknown, path: string): number => {
    const n = num(value, path);
    return Number.isInteger(n) && n > 0 ? n : fail(`${path} must be a positive integer, got ${n}`);
  };
  const numbers = (value: unknown, path: string, length?: number): number[] => {
    if (!Array.isArray(value)) return fail(`${path} must be an array of numbers`);
    if (length !== undefined && value.length !== length) fail(`${path} has ${value.length} values, expected ${length}`);
    const bad = value.findIndex((v) => typeof v !== 'number' || !Number.isFinite(v));
    if (bad >= 0) fail(`${path}[${bad}] is not a finite number`);
    return value as number[];
  };
  const strings = (value: unknown, path: string): string[] =>
    Array.isArray(value) && value.every((v) => typeof v === 'string') ? (value as string[]) : fail(`${path} must be an array of strings`);

  const root = obj(raw, 'the file');
  const fps = num(root.fps, 'fps');
  if (fps <= 0) fail(`fps must be positive, got ${fps}`);

  const skeleton = obj(root.skeleton, 'skeleton');
  const joints = strings(skeleton.joints, 'skeleton.joints');
  const J = joints.length;
  if (J === 0) fail('skeleton.joints is empty');
  const parents = numbers(skeleton.parents, 'skeleton.parents', J);
  parents.forEach((p, j) => {
    if (j === 0 ? p !== -1 : !Number.isInteger(p) || p < 0 || p >= j) fail(`skeleton.parents[${j}] = ${p}: the root must be first (-1) and parents must precede children`);
  });
  numbers(skeleton.offsets, 'skeleton.offsets', J * 3);

  const onnx = obj(root.onnx, 'onnx');
  const inputs = strings(onnx.inputs, 'onnx.inputs');
  const outputs = strings(onnx.outputs, 'onnx.outputs');
  if (inputs.join() !== EXPECTED_INPUTS.join()) fail(`onnx.inputs is [${inputs}], expected [${EXPECTED_INPUTS}]`);
  if (outputs.join() !== EXPECTED_OUTPUTS.join()) fail(`onnx.outputs is [${outputs}], expected [${EXPECTED_OUTPUTS}]`);
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

  const norm = obj(root.normalisation, 'normalisation');
  numbers(norm.mean, 'normalisation.mean', D);
  const std = numbers(norm.std, 'normalisation.std', D);
  const badStd = std.findIndex((s) => s <= 0);
  if (badStd >= 0) fail(`normalisation.std[${badStd}] = ${std[badStd]} must be positive`);

  if (!Array.isArray(root.seeds) || root.seeds.length === 0) fail('seeds must be a non-empty array');
  (root.seeds as unknown[]).forEach((s, i) => {
    const seed = obj(s, `seeds[${i}]`);
    if (typeof seed.name !== 'string') fail(`seeds[${i}].name must be a string`);
    numbers(seed.x, `seeds[${i}].x`, D);
    numbers(seed.h, `seeds[${i}].h`, layers * hidden);
    numbers(seed.c, `seeds[${i}].c`, layers * hidden);
  });

  return raw as GeneratorInfo;
}
