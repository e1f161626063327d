// The dance models' step loop (acLSTM and its vanilla baseline), independent of where it runs: an
// onnxruntime session, the feature decoder and the skeleton fit. dance.worker.ts wraps it in messages;
// unit tests drive it directly with onnxruntime-web's Node build. The loop is training/aclstm/shipped.py's:
// h = c = 0, the seed motion's frames are fed one by one (normalised), then each output is one new
// frame and is fed back as the next input. That feedback happens inside the graph (an ONNX Loop), so one
// call makes up to STEPS_PER_CALL frames. No randomness: the same style and seed give the same dance, however
// the frames are split into calls.
import type { InferenceSession, TensorConstructor } from 'onnxruntime-web';
import { SkeletonFitter } from '../../motion/fitSkeleton';
import { PlantedFeet } from '../../motion/footLock';
import { decodeDance, type DanceRoot } from './danceDecode';
import { seedsOfStyle, type DanceInfo } from './danceModel';
import type { DanceChunk, DanceGenerateParams, DanceInitResult, DanceParityResult, DanceStepInputs, DanceStepOutputs, DanceStreamInfo, DanceStreamParams } from './danceProtocol';
import type { BenchmarkResult } from '../worker/protocol';
import { denormalise } from '../../model/sampler';
import { checkFrameCount, SessionCore, timeSteps } from '../worker/session';

/** One dance: the next network input, the LSTM state, and where the root stands. */
export interface DanceStream {
  readonly params: DanceStreamParams;
  readonly seedIndex: number;
  readonly style: Float32Array;
  /** The next input (normalised): the last output. */
  x: Float32Array;
  h: Float32Array;
  c: Float32Array;
  root: DanceRoot;
  frame: number;
  /** Contacts labelled on the fitted frames (height and speed alone: the model has no contact bits) and the lock on them. */
  feet: PlantedFeet;
}

/**
 * Height (m) a planted dance foot's toe tip is brought to: the median height of the lowest foot point of slow
 * (< 0.3 m/s) feet within 4 cm of the floor in the held-out real dance clips (salsa and indian 0.012, martial 0.02).
 */
export const DANCE_TOE_GROUND_HEIGHT = 0.012;

/**
 * Most steps one session call runs. A call's fixed cost (feeds, copies into wasm, scheduling) is paid once per
 * call instead of once per frame; 16-64 measured alike, and a 32-step call (about 10 ms in Chromium on the 2-core
 * test machine) keeps cancellation prompt (docs/bench.md).
 */
export const STEPS_PER_CALL = 32;

export class DanceCore extends SessionCore<DanceInfo> {
  private readonly fitter: SkeletonFitter;
  private readonly L: number;
  private readonly H: number;
  private readonly D: number;
  private readonly S: number;
  private readonly J: number;

  /** `Tensor` must come from the same onnxruntime module as the session. */
  constructor(session: InferenceSession, info: DanceInfo, Tensor: TensorConstructor, threads = 1) {
    super(session, info, Tensor, threads);
    ({ layers: this.L, hidden: this.H, dim: this.D } = info.onnx);
    this.S = info.styles.length;
    this.J = info.skeleton.joints.length;
    this.fitter = new SkeletonFitter({ joints: info.skeleton.joints, parents: info.skeleton.parents, offsets: Float32Array.from(info.skeleton.offsets) });
  }

  /** One step at batch 1 from zeros: a model whose sizes disagree with the JSON fails here, not mid-dance. */
  async check(): Promise<void> {
    const { L, H, D, S } = this;
    await this.step(1, new Float32Array(D), new Float32Array(S), new Float32Array(L * H), new Float32Array(L * H), 1);
  }

  describe(loadMs: number): DanceInitResult {
    const info = this.info;
    return {
      ok: true,
      threads: this.threads,
      loadMs,
      id: info.id,
      fps: info.fps,
      joints: info.skeleton.joints,
      parents: info.skeleton.parents,
      offsets: info.skeleton.offsets,
      styles: info.styles,
      seeds: info.seeds.map((s) => ({ style: s.style, name: s.name })),
      realPoseChange: info.real_pose_change,
      trainingScheme: info.training_scheme ?? 'unknown',
    };
  }

  /**
   * One raw session call of `steps` steps: x (B×D normalised), style (B×S one-hot), h and c (layers×B×H); ys holds
   * steps × B × D output frames. With `signal`, a cancellation checkpoint first.
   */
  async step(batch: number, x: Float32Array, style: Float32Array, h: Float32Array, c: Float32Array, steps: number, signal?: AbortSignal): Promise<DanceStepOutputs> {
    const { L, H, D, S } = this;
    const read = await this.run(
      { x: [x, [batch, D]], style: [style, [batch, S]], h: [h, [L, batch, H]], c: [c, [L, batch, H]], steps: [BigInt64Array.of(BigInt(steps)), [1]] },
      signal,
    );
    return { ys: read('ys', steps * batch * D), h_out: read('h_out', L * batch * H), c_out: read('c_out', L * batch * H) };
  }

  /** Index into info.seeds of the seed motion for `style` and `seed` (seed mod the style's seed count). */
  seedIndex(style: string, seed: number): number {
    if (!this.info.styles.includes(style)) throw new Error(`unknown style "${style}" (styles: ${this.info.styles.join(', ')})`);
    if (!Number.isInteger(seed) || seed < 0) throw new Error(`seed must be an integer ≥ 0, got ${seed}`);
    const list = seedsOfStyle(this.info, style);
    return list[seed % list.length];
  }

  /**
   * A new dance: zero state, warmed up on the seed motion; its root stands at the origin, where the seed
   * ends. Stops (making no stream) when `signal` aborts.
   */
  async createStream(params: DanceStreamParams, signal?: AbortSignal): Promise<DanceStream> {
    const seedIndex = this.seedIndex(params.style, params.seed);
    const { L, H, D, S } = this;
    const style = new Float32Array(S);
    style[this.info.styles.indexOf(params.style)] = 1;
    let h: Float32Array = new Float32Array(L * H);
    let c: Float32Array = new Float32Array(L * H);
    let x: Float32Array = new Float32Array(D);
    for (const frame of this.info.seeds[seedIndex].frames) {
      const input = new Float32Array(D);
      for (let d = 0; d < D; d++) input[d] = (frame[d] - this.mean[d]) / this.std[d];
      ({ ys: x, h_out: h, c_out: c } = await this.step(1, input, style, h, c, 1, signal));
    }
    const { joints, offsets } = this.info.skeleton;
    const feet = new PlantedFeet(joints, offsets, this.info.fps, { groundHeight: DANCE_TOE_GROUND_HEIGHT });
    return { params: { style: params.style, seed: params.seed }, seedIndex, style, x, h, c, root: { x: 0, z: 0 }, frame: 0, feet };
  }

  streamInfo(stream: DanceStream): DanceStreamInfo {
    return { style: stream.params.style, seedIndex: stream.seedIndex, seedName: this.info.seeds[stream.seedIndex].name };
  }

  /**
   * The stream's next `frames` frames: decoded, fitted to the skeleton, contacts labelled and planted feet locked
   * (footLock.ts PlantedFeet), continuing its root path. With
   * `signal` it stops at the step where the signal is seen aborted, the stream part-advanced: pass it only
   * for a throwaway stream.
   */
  async advance(stream: DanceStream, frames: number, signal?: AbortSignal): Promise<DanceChunk> {
    checkFrameCount(frames);
    const { D } = this;
    const features = new Float32Array(frames * D);
    for (let t = 0; t < frames; ) {
      // Frame t is the pending input; the call's first steps − 1 outputs are frames t + 1 …, its last the next input.
      const steps = Math.min(STEPS_PER_CALL, frames - t);
      const out = await this.step(1, stream.x, stream.style, stream.h, stream.c, steps, signal);
      for (let k = 0; k < steps; k++, t++) {
        const row = features.subarray(t * D, (t + 1) * D);
        denormalise(k === 0 ? stream.x : out.ys.subarray((k - 1) * D, k * D), this.mean, this.std, row);
        if (!row.every(Number.isFinite)) throw new Error(`the model produced a non-finite value at frame ${stream.frame + t}`);
      }
      stream.x = out.ys.slice((steps - 1) * D);
      stream.h = out.h_out;
      stream.c = out.c_out;
    }
    const decoded = decodeDance(features, this.J, stream.root);
    const positions = this.fitter.fit(decoded.positions).positions;
    const contacts = new Uint8Array(frames * 2);
    const n = this.J * 3, noBits = [0, 0];
    for (let t = 0; t < frames; t++) stream.feet.step(positions.subarray(t * n, (t + 1) * n), noBits, contacts.subarray(t * 2, t * 2 + 2));
    const chunk: DanceChunk = {
      frames,
      features,
      predicted: decoded.positions,
      positions,
      contacts,
      seedIndex: stream.seedIndex,
      startFrame: stream.frame,
    };
    stream.root = decoded.end;
    stream.frame += frames;
    return chunk;
  }

  /** `frames` frames of a new dance; stops when `signal` aborts (cancellation.ts). */
  async generate(params: DanceGenerateParams, signal?: AbortSignal): Promise<DanceChunk> {
    const { frames, ...streamParams } = params;
    checkFrameCount(frames);
    return this.advance(await this.createStream(streamParams, signal), frames, signal);
  }

  /**
   * Times `steps` raw steps at `batch` rows, each feeding its output and state back (the dance loop), in calls of
   * `perCall` steps (1: one call per step, as before the Loop graph).
   */
  benchmark(batch: number, steps: number, perCall = STEPS_PER_CALL): Promise<BenchmarkResult> {
    return timeSteps(batch, steps, this.threads, () => {
      const { L, H, D, S } = this;
      let x: Float32Array = new Float32Array(batch * D);
      const style = new Float32Array(batch * S);
      for (let b = 0; b < batch; b++) style[b * S + (b % S)] = 1;
      let h: Float32Array = new Float32Array(L * batch * H);
      let c: Float32Array = new Float32Array(L * batch * H);
      return async () => {
        const out = await this.step(batch, x, style, h, c, perCall);
        ({ h_out: h, c_out: c } = out);
        x = out.ys.slice((perCall - 1) * batch * D);
      };
    }, perCall);
  }

  /** One raw call on the given inputs (tests/fixtures/aclstm_reference.json's `step.inputs` and `steps.inputs`). */
  async parity(inputs: DanceStepInputs): Promise<DanceParityResult> {
    const { L, H, D, S } = this;
    const batch = inputs?.batch;
    if (!Number.isInteger(batch) || batch < 1) throw new Error(`parity needs inputs { batch, x, style, h, c }, got batch ${String(batch)}`);
    const steps = inputs.steps ?? 1;
    if (!Number.isInteger(steps) || steps < 1 || steps > 10_000) throw new Error(`parity steps must be an integer from 1 to 10000, got ${String(steps)}`);
    const x = Float32Array.from(inputs.x ?? []);
    const style = Float32Array.from(inputs.style ?? []);
    const h = Float32Array.from(inputs.h ?? []);
    const c = Float32Array.from(inputs.c ?? []);
    if (x.length !== batch * D || style.length !== batch * S || h.length !== L * batch * H || c.length !== L * batch * H) {
      throw new Error(
        `parity inputs do not fit batch ${batch}: x has ${x.length} values (expected ${batch * D}), style ${style.length} (expected ${batch * S}), ` +
          `h ${h.length} and c ${c.length} (expected ${L * batch * H})`,
      );
    }
    return { outputs: await this.step(batch, x, style, h, c, steps) };
  }
}
