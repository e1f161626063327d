// The refiner's description file (public/models/refiner.json, written by python -m training.refiner.export): the
// ONNX step signature, the end effectors it reads, the normalisation (the generator's) and the foot-lock
// settings. `parseRefinerInfo` checks everything the runtime relies on and names the first bad field;
// `checkRefinerPairing` checks that it fits the loaded generator.
import { FOOT_LOCK_DEFAULTS, type FootLockSettings } from '../../motion/footLock';
import type { GeneratorInfo } from '../../model/generatorInfo';
import { modelInfoFormat } from '../../model/modelInfo';

export interface RefinerInfo {
  id: string;
  kind: string;
  fps: number;
  /** ONNX file name, relative to the JSON. */
  file: string;
  description?: string;
  /** The generator whose frames it refines ("generator"). */
  pairs_with: string;
  onnx: {
    inputs: string[]; // [x, ends, ends_prev, h, c]
    outputs: string[]; // [x_refined, h_out, c_out]
    opset?: number;
    hidden: number;
    dim: number;
    /** 3 × the number of end effectors. */
    ends: number;
  };
  end_effectors: {
    names: string[];
    /** Generator skeleton joint index of each name. */
    joints: number[];
    frame?: string;
  };
  usage?: string;
  normalisation: { mean: number[]; std: number[] };
  /** A refined contact is on when its physical value is above this. */
  contact_threshold: number;
  footlock: {
    toe_ground_height: number;
    blend_in_frames: number;
    blend_out_frames: number;
    reach: number;
  };
}

export const REFINER_INPUTS = ['x', 'ends', 'ends_prev', 'h', 'c'] as const;
export const REFINER_OUTPUTS = ['x_refined', 'h_out', 'c_out'] as const;

const format = modelInfoFormat<RefinerInfo>('RefinerInfoError', 'refiner.json', (check, root) => {
  const { fail, obj, num, posInt, positive, numbers, strings } = check;
  if (root.kind !== 'refiner') fail(`kind must be "refiner", got ${JSON.stringify(root.kind)}`);
  if (typeof root.file !== 'string' || root.file === '') fail('file must name the ONNX file');
  if (typeof root.pairs_with !== 'string') fail('pairs_with must name the generator model');

  const onnx = obj(root.onnx, 'onnx');
  check.names(onnx.inputs, 'onnx.inputs', REFINER_INPUTS);
  check.names(onnx.outputs, 'onnx.outputs', REFINER_OUTPUTS);
  posInt(onnx.hidden, 'onnx.hidden');
  const D = posInt(onnx.dim, 'onnx.dim');
  const E3 = posInt(onnx.ends, 'onnx.ends');

  const ends = obj(root.end_effectors, 'end_effectors');
  const names = strings(ends.names, 'end_effectors.names');
  if (names.length === 0 || 3 * names.length !== E3) fail(`end_effectors.names has ${names.length} names but onnx.ends is ${E3} (3 per end effector)`);
  numbers(ends.joints, 'end_effectors.joints', names.length).forEach((j, i) => {
    if (!Number.isInteger(j) || j < 0) fail(`end_effectors.joints[${i}] = ${j} is not a joint index`);
  });

  check.normalisation(root.normalisation, D);
  const threshold = num(root.contact_threshold, 'contact_threshold');
  if (threshold <= 0 || threshold >= 1) fail(`contact_threshold must be between 0 and 1, got ${threshold}`);

  const lock = obj(root.footlock, 'footlock');
  num(lock.toe_ground_height, 'footlock.toe_ground_height');
  const blendIn = num(lock.blend_in_frames, 'footlock.blend_in_frames');
  if (!Number.isInteger(blendIn) || blendIn < 0) fail(`footlock.blend_in_frames must be an integer ≥ 0, got ${blendIn}`);
  posInt(lock.blend_out_frames, 'footlock.blend_out_frames');
  const reach = positive(lock.reach, 'footlock.reach');
  if (reach > 1) fail(`footlock.reach must be at most 1, got ${reach}`);
});

export const RefinerInfoError = format.InfoError;
/** Checks a parsed refiner JSON; throws RefinerInfoError naming the first bad field. */
export const parseRefinerInfo = format.parse;
/** Fetches and checks the refiner JSON. */
export const loadRefinerInfo = format.load;

/** The foot-lock settings of the refiner's JSON (the pole bias is not in it: footlock.py's). */
export function footLockSettings(info: RefinerInfo): FootLockSettings {
  const l = info.footlock;
  return { groundHeight: l.toe_ground_height, blendIn: l.blend_in_frames, blendOut: l.blend_out_frames, reach: l.reach, poleBias: FOOT_LOCK_DEFAULTS.poleBias };
}

/** Throws (naming the mismatch) unless the refiner was made for this generator: same frame layout, normalisation and end-effector joints. */
export function checkRefinerPairing(refiner: RefinerInfo, generator: GeneratorInfo, source = 'refiner.json'): void {
  const fail = (message: string): never => {
    throw new RefinerInfoError(source, `does not fit the generator: ${message}`);
  };
  if (refiner.onnx.dim !== generator.onnx.dim) fail(`onnx.dim is ${refiner.onnx.dim}, the generator's frames have ${generator.onnx.dim} values`);
  if (refiner.fps !== generator.fps) fail(`fps is ${refiner.fps}, the generator's ${generator.fps}`);
  const norm = (a: number[], b: number[]) => a.reduce((worst, v, i) => Math.max(worst, Math.abs(v - b[i]) / Math.max(1, Math.abs(b[i]))), 0);
  const diff = Math.max(norm(refiner.normalisation.mean, generator.normalisation.mean), norm(refiner.normalisation.std, generator.normalisation.std));
  if (diff > 1e-5) fail(`its normalisation differs from the generator's (by up to ${diff.toPrecision(3)})`);
  const joints = generator.skeleton.joints;
  refiner.end_effectors.names.forEach((name, i) => {
    const j = refiner.end_effectors.joints[i];
    if (joints[j] !== name) fail(`end_effectors.joints[${i}] = ${j} is "${joints[j] ?? 'no joint'}" in the generator's skeleton, not "${name}"`);
  });
}
