// The VAE-LSTM's description file, public/models/vae-lstm.json, written by `python -m training.vae_lstm.export`:
// its four ONNX graphs (the cell over one chunk of steps, the control encoder, the canvas decoder, the
// inference network) and their input and output names, the skeleton, the 80-value row layout and its
// normalisation. The parse checks what the runtime relies on and names the file and the first bad field.
import { checkRowLayout, type ManifoldRowsInfo } from './latentErdInfo';
import { modelInfoFormat } from './modelInfo';

export const VAE_LSTM_GRAPHS = {
  cell: { inputs: ['hc', 'state', 'z', 'mix'], outputs: ['canvas', 'state_out'] },
  control: { inputs: ['control'], outputs: ['hc'] },
  decoder: { inputs: ['canvas'], outputs: ['rows'] },
  inference: { inputs: ['rows'], outputs: ['mean', 'log_var'] },
} as const;

export type VaeLstmGraph = keyof typeof VAE_LSTM_GRAPHS;

/** The stride's sway a drawn path lacks, per speed band (training/vae_lstm/stride.py; vaeLstmStride.ts). */
export interface VaeLstmStride {
  phase_bins: number;
  bands: { speed: number; period_s: number; sway: number[][] }[];
}

/**
 * Where a prior sample's z1 comes from when not N(0, I) (training/vae_lstm/prior_bank.py): the posterior means of K
 * training starts and one sigma per latent dimension; z1 = means[k] + sigma · normals (priorLatents).
 */
export interface Z1Prior {
  kind: 'posteriors';
  means: number[][];
  sigma: number[];
}

export interface VaeLstmInfo {
  id: string;
  kind: string;
  /** The cell graph's ONNX file (the model's main file), relative to the JSON. */
  file: string;
  files: Record<VaeLstmGraph, string>;
  fps: number;
  /** Frames of the training window (120: 4 s). */
  window: number;
  /** Frames per step (4). */
  pooling: number;
  /** Steps the cell graph runs per call (30: one window). */
  chunk_steps: number;
  /** Size of the latent code and of the cell state. */
  latent: number;
  /** Size of the control encoding per step. */
  control_features: number;
  /** Initial frames the posterior reads (4), padded to seed_pad frames by repeating the last. */
  seed_frames: number;
  seed_pad: number;
  /**
   * How a seed's prior sample is drawn (training/vae_lstm/generation.py): "z1", one latent and the cell on its
   * own state (Algorithm 1; with `mix`, a model trained so, z1 is also that share of every step's content, in
   * starts from 4 frames too), or "steps", a latent per step in teacher mode, AR(1) with lag-one correlation rho.
   * With `z1_prior` z1 is drawn from the posteriors of training starts instead of N(0, I).
   */
  sampling: { mode: 'z1'; mix?: number; z1_prior?: Z1Prior } | { mode: 'steps'; rho: number };
  /** Added to a drawn control before the model reads it (absent: the control is read as given). */
  stride?: VaeLstmStride;
  onnx: Record<VaeLstmGraph, { inputs: string[]; outputs: string[] }>;
  skeleton: { joints: string[]; parents: number[]; offsets: number[] };
  rows: ManifoldRowsInfo;
  normalisation: { mean: number[]; std: number[] };
  parity_max_abs?: Record<string, number>;
  report?: Record<string, unknown>;
}

const format = modelInfoFormat<VaeLstmInfo>('VaeLstmInfoError', 'vae-lstm.json', (check, root) => {
  const { fail, obj, posInt } = check;
  const files = obj(root.files, 'files');
  const onnx = obj(root.onnx, 'onnx');
  for (const [graph, names] of Object.entries(VAE_LSTM_GRAPHS)) {
    if (typeof files[graph] !== 'string' || !files[graph]) fail(`files.${graph} must name the ${graph} ONNX file`);
    const io = obj(onnx[graph], `onnx.${graph}`);
    check.names(io.inputs, `onnx.${graph}.inputs`, names.inputs);
    check.names(io.outputs, `onnx.${graph}.outputs`, names.outputs);
  }
  if (root.file !== files.cell) fail(`file must be files.cell (${String(files.cell)}), got ${String(root.file)}`);
  const pooling = posInt(root.pooling, 'pooling');
  if (pooling !== 4) fail(`pooling must be 4 (two max-poolings of 2), got ${pooling}`);
  posInt(root.window, 'window');
  posInt(root.chunk_steps, 'chunk_steps');
  posInt(root.latent, 'latent');
  posInt(root.control_features, 'control_features');
  const seedFrames = posInt(root.seed_frames, 'seed_frames');
  if (posInt(root.seed_pad, 'seed_pad') < seedFrames) fail(`seed_pad must be at least seed_frames (${seedFrames})`);
  const sampling = obj(root.sampling, 'sampling');
  if (sampling.mode === 'steps') {
    const rho = check.num(sampling.rho, 'sampling.rho');
    if (!(rho >= 0 && rho < 1)) fail(`sampling.rho must be in [0, 1), got ${rho}`);
  } else if (sampling.mode !== 'z1') fail(`sampling.mode must be "z1" or "steps", got ${JSON.stringify(sampling.mode)}`);
  else {
    if (sampling.mix !== undefined) {
      const mix = check.num(sampling.mix, 'sampling.mix');
      if (!(mix >= 0 && mix < 1)) fail(`sampling.mix must be in [0, 1), got ${mix}`);
    }
    if (sampling.z1_prior !== undefined) checkZ1Prior(sampling.z1_prior, posInt(root.latent, 'latent'), fail);
  }
  if (root.stride !== undefined) checkStride(root.stride, fail);
  check.skeleton(root.skeleton);
  check.normalisation(root.normalisation, checkRowLayout(check, root.rows, (root.skeleton as { joints: string[] }).joints));
});

export const VaeLstmInfoError = format.InfoError;
/** Checks a parsed vae-lstm.json; throws VaeLstmInfoError naming the file and the first bad field. */
export const parseVaeLstmInfo = format.parse;
export const loadVaeLstmInfo = format.load;

/** The model as the worker loads it: its JSON and the URLs of its other three graphs. */
export interface VaeLstmModel {
  info: VaeLstmInfo;
  urls: Record<VaeLstmGraph, string>;
}

export async function loadVaeLstmModel(url: string): Promise<VaeLstmModel> {
  const info = await loadVaeLstmInfo(url);
  const urls = Object.fromEntries(Object.entries(info.files).map(([k, f]) => [k, new URL(f, url).href])) as Record<VaeLstmGraph, string>;
  return { info, urls };
}

function checkZ1Prior(value: unknown, latent: number, fail: (message: string) => never): void {
  const prior = value as Partial<Z1Prior> | null;
  if (typeof prior !== 'object' || prior === null || prior.kind !== 'posteriors') fail('sampling.z1_prior must be an object of kind "posteriors"');
  const finiteRow = (row: unknown): boolean => Array.isArray(row) && row.length === latent && row.every((v) => typeof v === 'number' && Number.isFinite(v));
  if (!Array.isArray(prior.means) || prior.means.length === 0 || !prior.means.every(finiteRow)) {
    fail(`sampling.z1_prior.means must be a non-empty list of rows of ${latent} finite numbers`);
  }
  if (!finiteRow(prior.sigma) || !prior.sigma!.every((v) => v >= 0)) fail(`sampling.z1_prior.sigma must be ${latent} numbers, none negative`);
}

function checkStride(value: unknown, fail: (message: string) => never): void {
  const stride = value as Partial<VaeLstmStride> | null;
  const bins = stride?.phase_bins;
  if (typeof stride !== 'object' || stride === null || !Number.isInteger(bins) || bins! < 2) fail('stride.phase_bins must be an integer of at least 2');
  const bands = stride.bands;
  if (!Array.isArray(bands) || bands.length === 0) fail('stride.bands must be a non-empty list');
  let last = -Infinity;
  bands.forEach((b, k) => {
    if (!(typeof b?.speed === 'number' && b.speed > last)) fail(`stride.bands[${k}].speed must be a number above the band before's`);
    last = b.speed;
    if (!(typeof b.period_s === 'number' && b.period_s > 0)) fail(`stride.bands[${k}].period_s must be a positive number`);
    const ok = Array.isArray(b.sway) && b.sway.length === bins && b.sway.every((row) => Array.isArray(row) && row.length === 3 && row.every((v) => typeof v === 'number' && Number.isFinite(v)));
    if (!ok) fail(`stride.bands[${k}].sway must be ${bins} rows of 3 finite numbers`);
  });
}
