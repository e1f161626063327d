// The VAE-LSTM's runtime, independent of where it runs (vaeLstm.worker.ts wraps it in messages; unit tests
// drive it with onnxruntime-web's Node build). It makes a whole motion for a whole control signal in one go
// (Habibie et al., Algorithm 1; training/vae_lstm/generation.py):
//   1. the control signal (frames × [forward, sideways, turn], padded to a multiple of 4 frames by repeating
//      the last) is normalised and encoded in one call (vae-lstm-control.onnx);
//   2. the prior sample is drawn by the seed (Rng, so the same seed gives the same motion; priorLatents): z1
//      (from the posteriors of training starts when the model's sampling has a z1_prior), and when the model's
//      `sampling` is "steps" a latent per step, or given;
//   3. the cell runs chunk after chunk of chunk_steps steps (vae-lstm.onnx: the state goes in and out), on its
//      own state from z1 (Algorithm 1) or in teacher mode on the per-step latents; its states form the canvas;
//   4. the canvas is decoded in one call (vae-lstm-decoder.onnx) into rows: joint positions in the root's
//      facing frame, the decoded control and the contact channels;
//   (the cell reads the control with the stride's sway a drawn path lacks added, vaeLstmStride.ts)
//   5. the root moves by the control signal that was asked for (integrateControl), not by the decoded one,
//      so the motion goes exactly where it was sent; the points are placed at it, fitted to the skeleton,
//      and the feet are planted (contact labels from the decoded channels, then the lock: footLock.ts).
import type { InferenceSession, TensorConstructor } from 'onnxruntime-web';
import { integrateControl, randomControl, type Root } from '../../motion/control';
import { SkeletonFitter } from '../../motion/fitSkeleton';
import { plantFeet } from '../../motion/footLock';
import { Rng } from '../../model/sampler';
import { withStride } from '../../model/vaeLstmStride';
import { VAE_LSTM_GRAPHS, type VaeLstmGraph, type VaeLstmInfo, type VaeLstmModel, type Z1Prior } from '../../model/vaeLstmInfo';
import type { BenchmarkResult } from '../worker/protocol';
import { checkFrameCount, SessionCore, timeSteps } from '../worker/session';
import type { VaeLstmChunk, VaeLstmGenerateParams, VaeLstmInitResult, VaeLstmParityInputs, VaeLstmParityResult } from './vaeLstmProtocol';

type GraphInfo = { id: string; file: string; onnx: { inputs: string[]; outputs: string[] }; normalisation: { mean: number[]; std: number[] } };

/** One of the four graphs: a session with its input and output names checked at load. */
class GraphSession extends SessionCore<GraphInfo> {
  constructor(session: InferenceSession, info: VaeLstmInfo, graph: VaeLstmGraph, Tensor: TensorConstructor, threads: number) {
    super(session, { id: info.id, file: info.files[graph], onnx: { inputs: [...VAE_LSTM_GRAPHS[graph].inputs], outputs: [...VAE_LSTM_GRAPHS[graph].outputs] }, normalisation: info.normalisation }, Tensor, threads);
  }

  call(feeds: Record<string, [Float32Array, number[]]>, signal?: AbortSignal): Promise<(name: string, size: number) => Float32Array> {
    return this.run(feeds, signal);
  }
}

/**
 * What the cell's free mode reads besides its state (training/vae_lstm/generation.py free_latents): for a model
 * whose sampling is "z1" with a `mix` (trained with z1 in every step's content), z1 repeated over `steps` and that
 * mix; else nothing (Algorithm 1).
 */
export function freeLatents(z1: Float32Array, steps: number, sampling: VaeLstmInfo['sampling']): { zs: Float32Array; mix: number } | undefined {
  const mix = sampling.mode === 'z1' ? sampling.mix ?? 0 : 0;
  if (!(mix > 0)) return undefined;
  const zs = new Float32Array(steps * z1.length);
  for (let t = 0; t < steps; t++) zs.set(z1, t * z1.length);
  return { zs, mix };
}

/**
 * A seed's prior draws (training/vae_lstm/generation.py prior_latents, the same numbers): z1, `latent` draws
 * of N(0, 1) from the page's Rng — or with `z1Prior` one uniform picking mean k = floor(u·K), then means[k] + sigma ·
 * `latent` normals (draw_z1) — and with `steps` the per-step latents (steps × latent): z1 first, then
 * rho · previous + sqrt(1 − rho²) · a new draw, in the same stream.
 */
export function priorLatents(seed: number, latent: number, steps = 0, rho = 0, z1Prior?: Z1Prior): { z1: Float32Array; zs?: Float32Array } {
  const rng = new Rng(seed);
  const z1 = new Float32Array(latent);
  if (z1Prior) {
    const K = z1Prior.means.length;
    const mean = z1Prior.means[Math.min(Math.floor(rng.uniform() * K), K - 1)];
    for (let i = 0; i < latent; i++) z1[i] = mean[i] + z1Prior.sigma[i] * rng.normal();
  } else {
    for (let i = 0; i < latent; i++) z1[i] = rng.normal();
  }
  if (!steps) return { z1 };
  const zs = new Float32Array(steps * latent);
  zs.set(z1);
  const keep = rho, fresh = Math.sqrt(1 - rho * rho);
  for (let t = 1; t < steps; t++) {
    for (let i = 0; i < latent; i++) zs[t * latent + i] = keep * zs[(t - 1) * latent + i] + fresh * rng.normal();
  }
  return { z1, zs };
}

export interface GenerateOptions {
  /** Where the root starts (default the origin facing +z). */
  root?: Root;
  /** z1 itself (latent values) instead of a draw from the seed (then Algorithm 1, or teacher mode on `zs`). */
  z1?: ArrayLike<number>;
  /** With `z1`: per-step latents (steps × latent) for teacher mode. */
  zs?: ArrayLike<number>;
}

export class VaeLstmCore {
  readonly info: VaeLstmInfo;
  readonly threads: number;
  readonly skeleton: { joints: string[]; parents: number[]; offsets: Float32Array };
  private readonly graphs: Partial<Record<VaeLstmGraph, GraphSession>> = {};
  private readonly urls: VaeLstmModel['urls'];
  private loading: Promise<void> | undefined;
  private readonly fitter: SkeletonFitter;

  /**
   * `session` runs the cell graph (vae-lstm.onnx); `loadGraph` gives the other three graphs' sessions (called
   * by `check`, once each). `Tensor` must come from the same onnxruntime module as the sessions.
   */
  constructor(
    session: InferenceSession,
    model: VaeLstmModel,
    private readonly Tensor: TensorConstructor,
    threads: number,
    private readonly loadGraph: (graph: Exclude<VaeLstmGraph, 'cell'>, url: string) => Promise<InferenceSession>,
  ) {
    this.info = model.info;
    this.threads = threads;
    this.graphs.cell = new GraphSession(session, model.info, 'cell', Tensor, threads);
    this.urls = model.urls;
    const sk = model.info.skeleton;
    this.skeleton = { joints: sk.joints, parents: sk.parents, offsets: Float32Array.from(sk.offsets) };
    this.fitter = new SkeletonFitter(this.skeleton);
  }

  get fps(): number {
    return this.info.fps;
  }

  /** Loads the other graphs (first call), then makes 8 frames from zeros: sizes that disagree with the JSON fail here. */
  async check(): Promise<void> {
    this.loading ??= (async () => {
      for (const graph of ['control', 'decoder', 'inference'] as const) {
        this.graphs[graph] = new GraphSession(await this.loadGraph(graph, this.urls[graph]), this.info, graph, this.Tensor, this.threads);
      }
    })().catch((err: unknown) => {
      this.loading = undefined;
      throw err;
    });
    await this.loading;
    await this.rowsFor(new Float64Array(8 * 3), new Float32Array(this.info.latent), new Float32Array(2 * this.info.latent));
  }

  async release(): Promise<void> {
    for (const g of Object.values(this.graphs)) await g?.release();
  }

  describe(loadMs: number): VaeLstmInitResult {
    const i = this.info;
    return {
      ok: true, threads: this.threads, loadMs, id: i.id, fps: i.fps, joints: this.skeleton.joints, parents: this.skeleton.parents,
      offsets: Array.from(this.skeleton.offsets), latent: i.latent, pooling: i.pooling, chunkSteps: i.chunk_steps, window: i.window,
    };
  }

  private graph(name: VaeLstmGraph): GraphSession {
    const g = this.graphs[name];
    if (!g) throw new Error(`the VAE-LSTM ${name} graph is not loaded: call check() first`);
    return g;
  }

  /** Control encodings (steps × control_features) of a physical control (frames × 3, frames a multiple of 4), batch 1. */
  async encodeControl(control: ArrayLike<number>, signal?: AbortSignal): Promise<Float32Array> {
    const { rows, normalisation, pooling, control_features: F } = this.info;
    const frames = control.length / 3;
    const c0 = rows.control[0];
    const x = new Float32Array(frames * 3);
    for (let i = 0; i < x.length; i++) x[i] = (control[i] - normalisation.mean[c0 + (i % 3)]) / normalisation.std[c0 + (i % 3)];
    const read = await this.graph('control').call({ control: [x, [1, frames, 3]] }, signal);
    return read('hc', (frames / pooling) * F);
  }

  /**
   * The canvas (steps × latent) over control encodings (steps × control_features) from `state`, chunk by chunk:
   * on its own state (Algorithm 1), or with `zs` (steps × latent) each step's content mix · z_t + (1 − mix) · the
   * previous state (mix default 1: teacher mode on those latents).
   */
  async runCell(hc: Float32Array, state: Float32Array, zs?: Float32Array, signal?: AbortSignal, mix = 1): Promise<{ canvas: Float32Array; state: Float32Array; calls: number }> {
    const { chunk_steps: K, latent: Z, control_features: F } = this.info;
    const steps = hc.length / F;
    if (zs && zs.length < steps * Z) throw new Error(`zs has ${zs.length / Z} steps; the control needs ${steps}`);
    const canvas = new Float32Array(steps * Z);
    const share = Float32Array.of(zs ? mix : 0);
    let calls = 0;
    for (let at = 0; at < steps; at += K) {
      const part = new Float32Array(K * F);
      const z = new Float32Array(K * Z);
      for (let k = 0; k < K; k++) {
        const src = Math.min(at + k, steps - 1); // the last chunk repeats the last step
        part.set(hc.subarray(src * F, (src + 1) * F), k * F);
        if (zs) z.set(zs.subarray(src * Z, (src + 1) * Z), k * Z);
      }
      const read = await this.graph('cell').call({ hc: [part, [1, K, F]], state: [state, [1, Z]], z: [z, [1, K, Z]], mix: [share, [1]] }, signal);
      const out = read('canvas', K * Z);
      canvas.set(out.subarray(0, Math.min(K, steps - at) * Z), at * Z);
      // The state after the last real step (the padded steps only fill the chunk).
      state = Math.min(K, steps - at) === K ? read('state_out', Z) : out.slice((steps - at - 1) * Z, (steps - at) * Z);
      calls++;
    }
    return { canvas, state, calls };
  }

  /** Normalised rows (4 × steps × dim) of a canvas. */
  async decode(canvas: Float32Array, signal?: AbortSignal): Promise<Float32Array> {
    const { latent: Z, pooling, rows } = this.info;
    const steps = canvas.length / Z;
    const read = await this.graph('decoder').call({ canvas: [canvas, [1, steps, Z]] }, signal);
    return read('rows', pooling * steps * rows.dim);
  }

  /**
   * Physical rows (frames × dim) for a physical control (frames × 3) from z1 (teacher mode on `zs` when given; else
   * the free mode, with z1 in every step when the model's sampling has a `mix`), and the cell calls made.
   */
  async rowsFor(control: ArrayLike<number>, z1: Float32Array, zs?: Float32Array, signal?: AbortSignal): Promise<{ rows: Float64Array; cellCalls: number }> {
    const { pooling, rows: layout, normalisation } = this.info;
    const frames = control.length / 3;
    const padded = new Float64Array(Math.ceil(frames / pooling) * pooling * 3);
    padded.set(control);
    for (let f = frames; f < padded.length / 3; f++) padded.set(padded.subarray((frames - 1) * 3, frames * 3), f * 3);
    const hc = await this.encodeControl(padded, signal);
    const free = zs ? undefined : freeLatents(z1, hc.length / this.info.control_features, this.info.sampling);
    const { canvas, calls } = await this.runCell(hc, z1, zs ?? free?.zs, signal, free?.mix);
    const normalised = await this.decode(canvas, signal);
    const D = layout.dim;
    const rows = new Float64Array(frames * D);
    for (let i = 0; i < rows.length; i++) rows[i] = normalised[i] * normalisation.std[i % D] + normalisation.mean[i % D];
    if (!rows.every(Number.isFinite)) throw new Error('the VAE-LSTM produced a non-finite value');
    return { rows, cellCalls: calls };
  }

  /** `frames` frames for the control signal (given, or random from the seed) from z1 (given, or drawn from the seed). */
  async generate(params: VaeLstmGenerateParams, signal?: AbortSignal, options: GenerateOptions = {}): Promise<VaeLstmChunk> {
    const started = performance.now();
    const { frames, seed } = params;
    checkFrameCount(frames);
    const { fps, latent, rows: layout } = this.info;
    let control: Float64Array;
    if (params.control === undefined) control = randomControl(seed, frames, fps);
    else {
      if (params.control.length < frames * 3) throw new Error(`control has ${Math.floor(params.control.length / 3)} frames; it needs at least ${frames}`);
      control = Float64Array.from(params.control).subarray(0, frames * 3);
    }
    const steps = Math.ceil(frames / this.info.pooling);
    const sampling = this.info.sampling;
    const drawn = options.z1 ? { z1: Float32Array.from(options.z1), zs: options.zs ? Float32Array.from(options.zs) : undefined }
      : sampling.mode === 'steps' ? priorLatents(seed, latent, steps, sampling.rho) : priorLatents(seed, latent, 0, 0, sampling.z1_prior);
    const { z1, zs } = drawn;
    if (z1.length !== latent) throw new Error(`z1 has ${z1.length} values, the model's latent has ${latent}`);
    // The model reads the control with the stride a drawn path lacks (vaeLstmStride.ts); the root moves by the control.
    const read = this.info.stride && params.stride !== false ? withStride(control, fps, this.info.stride, seed) : control;
    const { rows, cellCalls } = await this.rowsFor(read, z1, zs, signal);
    const J = this.skeleton.joints.length;
    const { xz, heading } = integrateControl(control, fps, options.root);
    const predicted = new Float32Array(frames * J * 3);
    const bits = new Uint8Array(frames * 2);
    const roots = new Float64Array(frames * 3);
    const p0 = layout.positions[0], c0 = layout.contacts[0], D = layout.dim;
    for (let f = 0; f < frames; f++) {
      const ch = Math.cos(heading[f]), sh = Math.sin(heading[f]);
      const x = xz[f * 2], z = xz[f * 2 + 1];
      for (let j = 0; j < J; j++) {
        const r = f * D + p0 + j * 3;
        const lx = rows[r], ly = rows[r + 1], lz = rows[r + 2];
        const o = (f * J + j) * 3;
        predicted[o] = ch * lx + sh * lz + x;
        predicted[o + 1] = ly;
        predicted[o + 2] = -sh * lx + ch * lz + z;
      }
      bits[f * 2] = rows[f * D + c0] > 0.5 ? 1 : 0;
      bits[f * 2 + 1] = rows[f * D + c0 + 1] > 0.5 ? 1 : 0;
      roots.set([x, z, heading[f]], f * 3);
    }
    const fitted = this.fitter.fit(predicted).positions;
    const shown = params.footLock === false ? { positions: fitted, contacts: bits } : plantFeet(fitted, bits, this.skeleton.joints, this.skeleton.offsets, fps);
    const rootHeading = Float32Array.from(heading);
    return {
      frames, rows: Float32Array.from(rows), predicted, fitted, positions: shown.positions, contacts: shown.contacts, decodedContacts: bits,
      roots, rootHeading, control: Float32Array.from(control), z1, seed, cellCalls, computeMs: performance.now() - started,
    };
  }

  /** Times `steps` cell-chunk calls at `batch`, each feeding its state back. */
  benchmark(batch: number, steps: number): Promise<BenchmarkResult> {
    return timeSteps(batch, steps, this.threads, () => {
      const { chunk_steps: K, latent: Z, control_features: F } = this.info;
      const hc = new Float32Array(batch * K * F);
      let state: Float32Array = new Float32Array(batch * Z);
      const z = new Float32Array(batch * K * Z);
      const mix = Float32Array.of(0);
      return async () => {
        const read = await this.graph('cell').call({ hc: [hc, [batch, K, F]], state: [state, [batch, Z]], z: [z, [batch, K, Z]], mix: [mix, [1]] });
        state = read('state_out', batch * Z);
      };
    });
  }

  /** One call of each graph given (tests/fixtures/vae_lstm_reference.json's `graphs`), and/or a whole generation from z1. */
  async parity(inputs: VaeLstmParityInputs): Promise<VaeLstmParityResult> {
    const out: VaeLstmParityResult = {};
    for (const [graph, feeds] of Object.entries(inputs?.graphs ?? {}) as [VaeLstmGraph, Record<string, { dims: number[]; data: ArrayLike<number> }>][]) {
      const names = VAE_LSTM_GRAPHS[graph];
      if (!names) throw new Error(`parity: unknown graph "${graph}"`);
      const read = await this.graph(graph).call(Object.fromEntries(names.inputs.map((n) => {
        const f = feeds[n];
        if (!f) throw new Error(`parity: the ${graph} graph needs input "${n}"`);
        return [n, [Float32Array.from(f.data), f.dims]];
      })));
      const sizes = this.outputSizes(graph, feeds);
      out[graph] = Object.fromEntries(names.outputs.map((n) => [n, read(n, sizes[n])]));
    }
    if (inputs?.generate) {
      const { control, z1, zs } = inputs.generate;
      out.rows = (await this.rowsFor(control, Float32Array.from(z1), zs ? Float32Array.from(zs) : undefined)).rows;
    }
    return out;
  }

  private outputSizes(graph: VaeLstmGraph, feeds: Record<string, { dims: number[] }>): Record<string, number> {
    const { latent: Z, control_features: F, pooling, rows } = this.info;
    const d = (n: string) => feeds[n].dims;
    switch (graph) {
      case 'cell':
        return { canvas: d('hc')[0] * d('hc')[1] * Z, state_out: d('state')[0] * Z };
      case 'control':
        return { hc: d('control')[0] * (d('control')[1] / pooling) * F };
      case 'decoder':
        return { rows: d('canvas')[0] * d('canvas')[1] * pooling * rows.dim };
      case 'inference':
        return { mean: d('rows')[0] * (d('rows')[1] / pooling) * Z, log_var: d('rows')[0] * (d('rows')[1] / pooling) * Z };
    }
  }
}
