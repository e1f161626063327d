// The generator's step loop, independent of where it runs: an onnxruntime session, the mixture sampler
// and the feature decoder. generator.worker.ts wraps it in messages; unit tests drive it directly with
// onnxruntime-web's Node build.
import type { InferenceSession, TensorConstructor } from 'onnxruntime-web';
import { decodeFeatures, type RootStart } from '../../model/featureDecode';
import { setStateRow } from '../../model/lstmState';
import { noiseCorrelation, styleNames, styleSeeds, styleVector, type GeneratorInfo, type StepInputs, type StepOutputs } from '../../model/generatorInfo';
import type { GeneratedChunk, GenerateParams, InitResult, ParityResult, StreamInfo, StreamParams } from './protocol';
import type { BenchmarkResult } from '../worker/protocol';
import type { RefinerCore, RefinerStream } from '../refiner/refinerCore';
import { StyleRamp, STYLE_SWITCH_FRAMES } from '../../model/styleRamp';
import { denormalise, Rng, sampleMixture, snapContacts, type HeldNoise } from '../../model/sampler';
import { checkFrameCount, SessionCore, timeSteps } from '../worker/session';

/** One generation stream: the LSTM input and state, the PRNG and where the root stands. */
export interface GeneratorStream {
  readonly params: StreamParams;
  readonly seedIndex: number;
  x: Float32Array;
  h: Float32Array;
  c: Float32Array;
  rng: Rng;
  /** The sampler's normals, held over frames (generator.json sampling.noise_correlation). */
  noise: HeldNoise;
  /** A style generator's style input for this stream (weights over info.styles: a one-hot, or a blend); undefined without styles. */
  style?: Float32Array;
  /** A style switch under way (switchStreamStyle): the style input of each stream frame. */
  ramp?: StyleRamp;
  root: RootStart;
  frame: number;
  /** With params.refine: the refiner's state behind this stream (made on the first advance). */
  refiner?: RefinerStream;
}

export interface GeneratorCoreOptions {
  /** Loads the refiner for `refine` streams (the worker fetches models/refiner.*); called once, again after a failure. */
  loadRefiner?: (generator: GeneratorCore) => Promise<RefinerCore>;
}

export class GeneratorCore extends SessionCore<GeneratorInfo> {
  private readonly L: number;
  private readonly H: number;
  private readonly M: number;
  private readonly D: number;
  /** The style input's width (info.styles.length); 0 for a generator without styles. */
  private readonly S: number;
  private readonly loadRefiner: GeneratorCoreOptions['loadRefiner'];
  private refinerLoading: Promise<RefinerCore> | undefined;

  /** `Tensor` must come from the same onnxruntime module as the session. */
  constructor(session: InferenceSession, info: GeneratorInfo, Tensor: TensorConstructor, threads = 1, options: GeneratorCoreOptions = {}) {
    super(session, info, Tensor, threads);
    ({ layers: this.L, hidden: this.H, mixtures: this.M, dim: this.D } = info.onnx);
    this.S = styleNames(info).length;
    this.loadRefiner = options.loadRefiner;
  }

  /** The refiner, loaded the first time a stream asks for it (a failed load is tried again next time). */
  refiner(): Promise<RefinerCore> {
    if (!this.loadRefiner) return Promise.reject(new Error('the refiner is not available here (no refiner loader)'));
    if (!this.refinerLoading) {
      const loading = this.loadRefiner(this);
      loading.catch(() => {
        if (this.refinerLoading === loading) this.refinerLoading = undefined;
      });
      this.refinerLoading = loading;
    }
    return this.refinerLoading;
  }

  override async release(): Promise<void> {
    const refiner = this.refinerLoading;
    this.refinerLoading = undefined;
    await refiner?.then((r) => r.release(), () => undefined);
    await super.release();
  }

  /** Runs one step on the first seed state: a model whose sizes disagree with the JSON fails here, not mid-stream. */
  async check(): Promise<void> {
    const { x, h, c } = this.batchInputs([0]);
    await this.step(1, x, h, c);
  }

  /** What the page needs to know about the loaded model (the worker's `init` reply). */
  describe(loadMs: number): InitResult {
    const info = this.info;
    return {
      ok: true,
      threads: this.threads,
      loadMs,
      fps: info.fps,
      joints: info.skeleton.joints,
      parents: info.skeleton.parents,
      dim: info.onnx.dim,
      seeds: info.seeds.map((s) => s.name),
      ...(info.styles ? { styles: [...info.styles] } : {}),
      ...(info.licence ? { licence: info.licence } : {}),
      ...(info.held_out_sliding ? { heldOutSlidingByStyle: { ...info.held_out_sliding } } : {}),
      ...(typeof info.pack?.measures?.real?.sliding_low_foot === 'number' ? { heldOutSliding: info.pack.measures.real.sliding_low_foot } : {}),
    };
  }

  /**
   * One raw session call: x (B×D normalised), h and c (layers×B×H); with `signal`, a cancellation checkpoint first.
   * A style generator's `style`: one row of weights over the styles for every row (S values) or one per row (B×S);
   * default the first style. A generator without styles refuses one.
   */
  async step(batch: number, x: Float32Array, h: Float32Array, c: Float32Array, signal?: AbortSignal, style?: ArrayLike<number>): Promise<StepOutputs> {
    const { L, H, M, D } = this;
    const inputs: Record<string, [Float32Array, number[]]> = { x: [x, [batch, D]], h: [h, [L, batch, H]], c: [c, [L, batch, H]] };
    if (this.S) inputs.style = [this.styleRows(batch, style), [batch, this.S]];
    else if (style !== undefined) throw new Error(`the model "${this.info.id}" has no style input`);
    const read = await this.run(inputs, signal);
    return {
      weights: read('weights', batch * M),
      mu: read('mu', batch * M * D),
      sigma: read('sigma', batch * M * D),
      h_out: read('h_out', L * batch * H),
      c_out: read('c_out', L * batch * H),
    };
  }

  /** The style input for `batch` rows: `style` as one row for all (S values) or per row (B×S); default the first style. */
  private styleRows(batch: number, style?: ArrayLike<number>): Float32Array {
    const S = this.S;
    const row = style === undefined ? styleVector(this.info) : style;
    if (row.length === batch * S) return row instanceof Float32Array ? row : Float32Array.from(row);
    if (row.length !== S) throw new Error(`the style input needs ${S} or ${batch * S} values, got ${row.length}`);
    const out = new Float32Array(batch * S);
    for (let b = 0; b < batch; b++) out.set(row, b * S);
    return out;
  }

  /** A style generator's style input for `style` (a name, or weights blending the styles; default the first style). */
  styleInput(style?: string | ArrayLike<number>): Float32Array | undefined {
    if (!this.S) {
      if (style !== undefined) throw new Error(`the model "${this.info.id}" has no styles`);
      return undefined;
    }
    return styleVector(this.info, style);
  }

  /** Changes a stream's style from its next frame on: a name, or weights (a blend, as a style switch passes through). */
  setStreamStyle(stream: GeneratorStream, style: string | ArrayLike<number>): void {
    if (!this.S) throw new Error(`the model "${this.info.id}" has no styles`);
    stream.style = styleVector(this.info, style);
    stream.ramp = undefined;
  }

  /**
   * Switches a stream to style `style` (a name) without a pop: from its next frame, the style input ramps from the
   * weights in force to the new style's one-hot over `frames` frames (styleRamp.ts; default one second), one
   * convex blend per frame. A switch during a switch carries on from the blend reached.
   */
  switchStreamStyle(stream: GeneratorStream, style: string, frames = STYLE_SWITCH_FRAMES): void {
    if (!this.S) throw new Error(`the model "${this.info.id}" has no styles`);
    if (typeof style !== 'string') throw new Error(`style must be a style's name, got ${String(style)}`);
    const target = styleVector(this.info, style);
    stream.ramp ??= new StyleRamp(stream.style ?? styleVector(this.info));
    stream.ramp.switchTo(target, stream.frame, frames);
    stream.params.style = style;
  }

  /** A new stream at the origin, heading 0, from its seed state (a style generator: one of its style's seeds by default). */
  createStream(params: StreamParams): GeneratorStream {
    if (typeof params.seed !== 'number' || !Number.isFinite(params.seed)) throw new Error(`seed must be a finite number, got ${params.seed}`);
    if (typeof params.temperature !== 'number' || !Number.isFinite(params.temperature) || params.temperature < 0) {
      throw new Error(`temperature must be a finite number ≥ 0, got ${params.temperature}`);
    }
    if (params.refine !== undefined && typeof params.refine !== 'boolean') throw new Error(`refine must be true or false, got ${String(params.refine)}`);
    if (params.style !== undefined && typeof params.style !== 'string') throw new Error(`style must be a style's name, got ${String(params.style)}`);
    const count = this.info.seeds.length;
    const seeds = styleSeeds(this.info, params.style); // every seed for a generator without styles
    const seedIndex = params.seedIndex ?? seeds[(params.seed >>> 0) % seeds.length];
    if (!Number.isInteger(seedIndex) || seedIndex < 0 || seedIndex >= count) {
      throw new Error(`seedIndex must be an integer from 0 to ${count - 1}, got ${params.seedIndex}`);
    }
    const seed = this.info.seeds[seedIndex];
    return {
      params: { ...params },
      seedIndex,
      x: Float32Array.from(seed.x),
      h: Float32Array.from(seed.h),
      c: Float32Array.from(seed.c),
      rng: new Rng(params.seed),
      noise: { correlation: noiseCorrelation(this.info) },
      ...(this.S ? { style: styleVector(this.info, params.style) } : {}),
      root: { x: 0, z: 0, heading: 0 },
      frame: 0,
    };
  }

  streamInfo(stream: GeneratorStream): StreamInfo {
    const style = stream.params.style ?? this.info.styles?.[0];
    return { seedIndex: stream.seedIndex, seedName: this.info.seeds[stream.seedIndex].name, ...(this.S && style ? { style } : {}) };
  }

  /**
   * Advances a stream by `frames` steps and decodes them, continuing its root trajectory; a `refine` stream
   * also runs the same frames through the refiner and the foot lock (`refined`). With `signal` it stops at
   * the step where the signal is seen aborted, the stream part-advanced: pass it only for a throwaway stream.
   */
  async advance(stream: GeneratorStream, frames: number, signal?: AbortSignal): Promise<GeneratedChunk> {
    checkFrameCount(frames);
    const { M, D } = this;
    let refiner: RefinerCore | undefined;
    if (stream.params.refine) {
      refiner = await this.refiner();
      // Made before the first frame: its previous frame is the seed frame (the generator's first input).
      stream.refiner ??= refiner.createStream(denormalise(stream.x, this.mean, this.std));
    }
    const features = new Float32Array(frames * D);
    // What the refiner reads: the frames exactly as fed back to the generator (normalised, contacts snapped).
    const fedBack = refiner ? new Float32Array(frames * D) : undefined;
    for (let t = 0; t < frames; t++) {
      if (stream.ramp) stream.style = stream.ramp.at(stream.frame + t);
      const out = await this.step(1, stream.x, stream.h, stream.c, signal, stream.style);
      const x = sampleMixture({ weights: out.weights, mu: out.mu, sigma: out.sigma, batch: 1, mixtures: M, dim: D }, stream.params.temperature, stream.rng, undefined, stream.noise);
      snapContacts(x, D, this.mean, this.std);
      denormalise(x, this.mean, this.std, features.subarray(t * D, (t + 1) * D));
      fedBack?.set(x, t * D);
      stream.x = x;
      stream.h = out.h_out;
      stream.c = out.c_out;
    }
    const decoded = decodeFeatures(this.info, features, stream.root);
    const chunk: GeneratedChunk = {
      frames,
      features,
      positions: decoded.positions,
      contacts: decoded.contacts,
      rootHeading: decoded.rootHeading,
      seedIndex: stream.seedIndex,
      startFrame: stream.frame,
    };
    if (refiner && fedBack) chunk.refined = await refiner.refine(stream.refiner!, fedBack, features);
    stream.root = decoded.end;
    stream.frame += frames;
    return chunk;
  }

  /** `frames` frames of a new stream; stops when `signal` aborts (cancellation.ts). */
  async generate(params: GenerateParams, signal?: AbortSignal): Promise<GeneratedChunk> {
    const { frames, ...streamParams } = params;
    return this.advance(this.createStream(streamParams), frames, signal);
  }

  /** Times `steps` raw session calls at `batch` rows, all starting from the first seed state. */
  benchmark(batch: number, steps: number): Promise<BenchmarkResult> {
    return timeSteps(batch, steps, this.threads, () => {
      const inputs = this.batchInputs(new Array<number>(batch).fill(0));
      let h: Float32Array = inputs.h;
      let c: Float32Array = inputs.c;
      return async () => {
        const out = await this.step(batch, inputs.x, h, c);
        h = out.h_out;
        c = out.c_out;
      };
    });
  }

  /**
   * One raw step; without inputs, the first and last seed states at batch 2 (the Python fixture's inputs), a style
   * generator's rows in their seeds' styles. A style generator's inputs may carry `style` (B×S; default the first style).
   */
  async parity(inputs?: StepInputs): Promise<ParityResult> {
    const { L, H, D, S } = this;
    let batch: number, x: Float32Array, h: Float32Array, c: Float32Array;
    let style: Float32Array | undefined;
    if (inputs) {
      batch = inputs.batch;
      x = Float32Array.from(inputs.x);
      h = Float32Array.from(inputs.h);
      c = Float32Array.from(inputs.c);
      if (!Number.isInteger(batch) || batch < 1 || x.length !== batch * D || h.length !== L * batch * H || c.length !== L * batch * H) {
        throw new Error(`parity inputs do not fit batch ${batch}: x has ${x.length} values (expected ${batch * D}), h ${h.length} and c ${c.length} (expected ${L * batch * H})`);
      }
      if (inputs.style !== undefined) {
        if (!S) throw new Error(`the model "${this.info.id}" has no style input`);
        if (inputs.style.length !== batch * S) throw new Error(`parity inputs do not fit batch ${batch}: style has ${inputs.style.length} values (expected ${batch * S})`);
        style = Float32Array.from(inputs.style);
      }
    } else {
      batch = 2;
      const rows = [0, this.info.seeds.length - 1];
      ({ x, h, c } = this.batchInputs(rows));
      if (S) {
        style = new Float32Array(batch * S);
        rows.forEach((s, b) => style!.set(styleVector(this.info, this.info.seeds[s].style), b * S));
      }
    }
    if (S) style ??= this.styleRows(batch);
    const outputs = await this.step(batch, x.slice(), h.slice(), c.slice(), undefined, style?.slice());
    return { inputs: { batch, x, h, c, ...(style ? { style } : {}) }, outputs };
  }

  /** Batch inputs whose row b starts from seed state seedIndices[b]. */
  private batchInputs(seedIndices: number[]) {
    const { L, H, D } = this;
    const B = seedIndices.length;
    const x = new Float32Array(B * D);
    const h = new Float32Array(L * B * H);
    const c = new Float32Array(L * B * H);
    seedIndices.forEach((s, b) => {
      const seed = this.info.seeds[s];
      x.set(seed.x, b * D);
      setStateRow(h, L, B, H, b, seed.h);
      setStateRow(c, L, B, H, b, seed.c);
    });
    return { x, h, c };
  }
}
