// The dance models' description files (public/models/aclstm.json and aclstm-mdn.json, written by
// python -m training.aclstm.export): skeleton, ONNX step signature, feature layout, normalisation, the seed
// motions per style and the real pose change per style. `parseDanceInfo` checks everything the runtime
// relies on and names the first bad field. A sampled model (issue 42: `head: "mdn"`, a mixture-density head with
// phrase-scale sampling in the graph) adds `components`, the `sampling` block (the phrase rule's settings and the
// output filter, per style) and the sampler's inputs and outputs (DANCE_MDN_INPUTS, DANCE_MDN_OUTPUTS); a model
// without `head` is read exactly as before.
import { modelInfoFormat, type FieldChecks } from '../../model/modelInfo';

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
  /** "mdn": a sampled model (the mixture head's phrase sampler and the output filter run in the graph); absent: deterministic. */
  head?: 'mdn';
  /** Mixture components K of an mdn head (the `weights` output is steps × B × K). */
  components?: number;
  /** An mdn model's sampling settings per style (training/aclstm/phrase_sampling.py; chosen on held-out windows). */
  sampling?: DanceSampling;
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

/** The phrase rule's settings of one style (training/aclstm/phrase_sampling.py PhraseParams). */
export interface PhraseParams {
  /** The held component's σ times this. */
  temperature: number;
  /** Frames: redraw at least this often. */
  max_hold: number;
  /** AR(1) coefficient of the within-component normals, in [0, 1). */
  rho: number;
  /** Redraw when the held component's weight falls below this; components under it are never drawn. */
  threshold: number;
  /** Frames: no redraw before this (except the first draw). */
  min_hold: number;
}

/** One style's causal biquad low-pass on the sampled frames (normalised units): y = b·[x, x₁, x₂] − a₁y₁ − a₂y₂. */
export interface DanceFilter {
  cutoff_hz: number;
  b: [number, number, number];
  /** [1, a₁, a₂]. */
  a: [number, number, number];
}

export interface DanceSampling {
  rule: 'phrase';
  params: Record<string, PhraseParams>;
  filter: Record<string, DanceFilter>;
}

/** One call runs `steps` steps, each output frame fed back inside the graph: ys is steps × batch × dim. */
export const DANCE_INPUTS = ['x', 'style', 'h', 'c', 'steps'] as const;
export const DANCE_OUTPUTS = ['ys', 'h_out', 'c_out'] as const;
/**
 * A sampled (mdn) model's graph (/tmp interface of issue 42): the deterministic inputs plus the sampler's state, the
 * per-row phrase settings, the step's random numbers and the output filter; `display` is `ys` filtered (drawn, never
 * fed back). Checked as sets: the order in the JSON does not matter, feeds go by name.
 */
export const DANCE_MDN_INPUTS = [
  ...DANCE_INPUTS,
  'held', 'age', 'wander', 'temperature', 'rho', 'threshold', 'max_hold', 'min_hold', 'uniforms', 'normals', 'filt', 'filter_b', 'filter_a',
] as const;
export const DANCE_MDN_OUTPUTS = ['ys', 'display', 'h_out', 'c_out', 'held_out', 'age_out', 'wander_out', 'filt_out', 'weights'] as const;

/** True for a model whose frames are sampled (mixture head, phrase sampler): its dance depends on the seed's random draws. */
export const isSampledDance = (info: DanceInfo): boolean => info.head === 'mdn';

const format = modelInfoFormat<DanceInfo>('DanceInfoError', 'aclstm.json', (check, root) => {
  const { fail, obj, posInt, numbers, strings } = check;
  const styles = strings(root.styles, 'styles');
  if (styles.length === 0 || new Set(styles).size !== styles.length) fail('styles must be a non-empty list of distinct names');
  const J = check.skeleton(root.skeleton);

  if (root.head !== undefined && root.head !== 'mdn') fail(`head must be "mdn" or left out, got ${JSON.stringify(root.head)}`);
  const mdn = root.head === 'mdn';
  if (!mdn) {
    for (const key of ['components', 'sampling'] as const) if (root[key] !== undefined) fail(`${key} is only read with head "mdn", and there is no head`);
  }
  const onnx = obj(root.onnx, 'onnx');
  if (onnx.head !== undefined && (onnx.head === 'mdn') !== mdn) fail(`onnx.head is ${JSON.stringify(onnx.head)} but the file's head is ${mdn ? '"mdn"' : 'not "mdn"'}`);
  if (mdn) {
    nameSet(check, onnx.inputs, 'onnx.inputs', DANCE_MDN_INPUTS);
    nameSet(check, onnx.outputs, 'onnx.outputs', DANCE_MDN_OUTPUTS);
  } else {
    check.names(onnx.inputs, 'onnx.inputs', DANCE_INPUTS);
    check.names(onnx.outputs, 'onnx.outputs', DANCE_OUTPUTS);
  }
  posInt(onnx.layers, 'onnx.layers');
  posInt(onnx.hidden, 'onnx.hidden');
  const D = posInt(onnx.dim, 'onnx.dim');
  if (D !== 3 * J) fail(`onnx.dim is ${D} but ${J} skeleton points need ${3 * J} features`);
  if (posInt(onnx.styles, 'onnx.styles') !== styles.length) fail(`onnx.styles is ${String(onnx.styles)} but there are ${styles.length} styles`);

  const features = obj(root.features, 'features');
  if (posInt(features.dim, 'features.dim') !== D) fail(`features.dim is ${String(features.dim)}, expected ${D}`);
  const seedFrames = posInt(features.seed_frames, 'features.seed_frames');
  check.normalisation(root.normalisation, D);
  if (mdn) {
    if (posInt(root.components, 'components') < 2) fail(`components must be at least 2 for head "mdn", got ${String(root.components)}`);
    if (onnx.components !== undefined && onnx.components !== root.components) fail(`onnx.components is ${String(onnx.components)} but components is ${String(root.components)}`);
    checkSampling(check, root.sampling, styles, root.fps as number);
  }

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

/** A list of names holding each of `expected` once, in any order. */
function nameSet(check: FieldChecks, value: unknown, path: string, expected: readonly string[]): void {
  const got = check.strings(value, path);
  const missing = expected.filter((n) => !got.includes(n));
  const extra = got.filter((n) => !expected.includes(n));
  if (missing.length || extra.length || got.length !== expected.length) {
    check.fail(`${path} is [${got}], expected [${expected}] in any order${missing.length ? ` (missing ${missing.join(', ')})` : ''}${extra.length ? ` (unknown ${extra.join(', ')})` : ''}`);
  }
}

/** The `sampling` block of an mdn model: the phrase rule, and settings and a stable low-pass for every style. */
function checkSampling(check: FieldChecks, value: unknown, styles: string[], fps: number): void {
  const { fail, obj, num, numbers } = check;
  const sampling = obj(value, 'sampling');
  if (sampling.rule !== 'phrase') fail(`sampling.rule must be "phrase", got ${JSON.stringify(sampling.rule)}`);
  const params = obj(sampling.params, 'sampling.params');
  const filter = obj(sampling.filter, 'sampling.filter');
  for (const [what, block] of [['params', params], ['filter', filter]] as const) {
    const extra = Object.keys(block).find((k) => !styles.includes(k));
    if (extra !== undefined) fail(`sampling.${what} has "${extra}", which is not a style (styles: ${styles.join(', ')})`);
  }
  const count = (v: unknown, path: string, min: number) => {
    const n = num(v, path);
    return Number.isInteger(n) && n >= min ? n : fail(`${path} must be an integer ≥ ${min}, got ${n}`);
  };
  for (const style of styles) {
    const p = obj(params[style], `sampling.params.${style}`);
    const at = (k: string) => `sampling.params.${style}.${k}`;
    const t = num(p.temperature, at('temperature'));
    if (t < 0) fail(`${at('temperature')} must be ≥ 0, got ${t}`);
    const rho = num(p.rho, at('rho'));
    if (!(rho >= 0 && rho < 1)) fail(`${at('rho')} must be from 0 up to (not including) 1, got ${rho}`);
    const threshold = num(p.threshold, at('threshold'));
    if (!(threshold >= 0 && threshold < 1)) fail(`${at('threshold')} must be from 0 up to (not including) 1, got ${threshold}`);
    const maxHold = count(p.max_hold, at('max_hold'), 1);
    const minHold = count(p.min_hold, at('min_hold'), 0);
    if (minHold > maxHold) fail(`${at('min_hold')} (${minHold}) must not exceed max_hold (${maxHold})`);

    const f = obj(filter[style], `sampling.filter.${style}`);
    const fat = (k: string) => `sampling.filter.${style}.${k}`;
    const cutoff = num(f.cutoff_hz, fat('cutoff_hz'));
    if (!(cutoff > 0 && cutoff < fps / 2)) fail(`${fat('cutoff_hz')} must be above 0 and below half the frame rate (${fps / 2} Hz), got ${cutoff}`);
    numbers(f.b, fat('b'), 3);
    const [a0, a1, a2] = numbers(f.a, fat('a'), 3);
    if (a0 !== 1) fail(`${fat('a')}[0] must be 1 (the coefficients are normalised), got ${a0}`);
    // The biquad's poles lie inside the unit circle (stability triangle): otherwise the drawn frames would grow without bound.
    if (!(Math.abs(a2) < 1 && Math.abs(a1) < 1 + a2)) fail(`${fat('a')} = [${f.a}] is not a stable filter (need |a2| < 1 and |a1| < 1 + a2)`);
  }
}

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
