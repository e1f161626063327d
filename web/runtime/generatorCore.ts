// The generator's step loop, independent of where it runs: an onnxruntime session, the mixture sampler
// and the feature decoder. generator.worker.ts wraps it in messages; unit tests drive it directly with
// onnxruntime-web's Node build.
import type { InferenceSession, Tensor, TensorConstructor } from 'onnxruntime-web';
import { decodeFeatures, type RootStart } from './featureDecode';
import type { GeneratorInfo } from './generatorModel';
import type { BenchmarkResult, GeneratedChunk, GenerateParams, ParityResult, StepInputs, StepOutputs, StreamInfo, StreamParams } from './protocol';
import { denormalise, Rng, sampleMixture, snapContacts } from './sampler';

export const MAX_FRAMES_PER_REQUEST = 100_000;
export const MAX_BENCHMARK_BATCH = 4096;

/** One generation stream: the LSTM input and state, the PRNG and where the root stands. */
export interface GeneratorStream {
  readonly params: StreamParams;
  readonly seedIndex: number;
  x: Float32Array;
  h: Float32Array;
  c: Float32Array;
  rng: Rng;
  root: RootStart;
  frame: number;
}

export class GeneratorCore {
  readonly info: GeneratorInfo;
  readonly threads: number;
  private readonly session: InferenceSession;
  private readonly Tensor: TensorConstructor;
  private readonly mean: Float32Array;
  private readonly std: Float32Array;
  private readonly L: number;
  private readonly H: number;
  private readonly M: number;
  private readonly D: number;

  /** `Tensor` must come from the same onnxruntime module as the session. */
  constructor(session: InferenceSession, info: GeneratorInfo, Tensor: TensorConstructor, threads = 1) {
    const missing = [
      ...info.onnx.inputs.filter((n) => !session.inputNames.includes(n)).map((n) => `input "${n}"`),
      ...info.onnx.outputs.filter((n) => !session.outputNames.includes(n)).map((n) => `output "${n}"`),
    ];
    if (missing.length) {
      throw new Error(`the model lacks ${missing.join(', ')} (it has inputs [${session.inputNames}], outputs [${session.outputNames}])`);
    }
    this.session = session;
    this.info = info;
    this.Tensor = Tensor;
    this.threads = threads;
    this.mean = Float32Array.from(info.normalisation.mean);
    this.std = Float32Array.from(info.normalisation.std);
    ({ layers: this.L, hidden: this.H, mixtures: this.M, dim: this.D } = info.onnx);
  }

  /** Runs one step on the first seed state: a model whose sizes disagree with the JSON fails here, not mid-stream. */
  async check(): Promise<void> {
    const { x, h, c } = this.batchInputs([0]);
    await this.step(1, x, h, c);
  }

  release(): Promise<void> {
    return this.session.release();
  }

  /** One raw session call: x (B×D normalised), h and c (layers×B×H). */
  async step(batch: number, x: Float32Array, h: Float32Array, c: Float32Array): Promise<StepOutputs> {
    const { L, H, M, D } = this;
    const out = await this.session.run({
      x: new this.Tensor('float32', x, [batch, D]),
      h: new this.Tensor('float32', h, [L, batch, H]),
      c: new this.Tensor('float32', c, [L, batch, H]),
    });
    const read = (name: string, size: number): Float32Array => {
      const tensor: Tensor | undefined = out[name];
      if (!tensor) throw new Error(`the model gave no output "${name}"`);
      if (!(tensor.data instanceof Float32Array)) throw new Error(`model output "${name}" is ${tensor.type}, expected float32`);
      if (tensor.data.length !== size) {
        throw new Error(`model output "${name}" has ${tensor.data.length} values (dims ${tensor.dims.join('×')}), expected ${size}; does generator.json match generator.onnx?`);
      }
      return tensor.data;
    };
    return {
      weights: read('weights', batch * M),
      mu: read('mu', batch * M * D),
      sigma: read('sigma', batch * M * D),
      h_out: read('h_out', L * batch * H),
      c_out: read('c_out', L * batch * H),
    };
  }

  /** A new stream at the origin, heading 0, from its seed state. */
  createStream(params: StreamParams): GeneratorStream {
    if (typeof params.seed !== 'number' || !Number.isFinite(params.seed)) throw new Error(`seed must be a finite number, got ${params.seed}`);
    if (typeof params.temperature !== 'number' || !Number.isFinite(params.temperature) || params.temperature < 0) {
      throw new Error(`temperature must be a finite number ≥ 0, got ${params.temperature}`);
    }
    const count = this.info.seeds.length;
    const seedIndex = params.seedIndex ?? (params.seed >>> 0) % count;
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
      root: { x: 0, z: 0, heading: 0 },
      frame: 0,
    };
  }

  streamInfo(stream: GeneratorStream): StreamInfo {
    return { seedIndex: stream.seedIndex, seedName: this.info.seeds[stream.seedIndex].name };
  }

  /** Advances a stream by `frames` steps and decodes them, continuing its root trajectory. */
  async advance(stream: GeneratorStream, frames: number): Promise<GeneratedChunk> {
    if (!Number.isInteger(frames) || frames < 1 || frames > MAX_FRAMES_PER_REQUEST) {
      throw new Error(`frames must be an integer from 1 to ${MAX_FRAMES_PER_REQUEST}, got ${frames}`);
    }
    const { M, D } = this;
    const features = new Float32Array(frames * D);
    for (let t = 0; t < frames; t++) {
      const out = await this.step(1, stream.x, stream.h, stream.c);
      const x = sampleMixture({ weights: out.weights, mu: out.mu, sigma: out.sigma, batch: 1, mixtures: M, dim: D }, stream.params.temperature, stream.rng);
      snapContacts(x, D, this.mean, this.std);
      denormalise(x, this.mean, this.std, features.subarray(t * D, (t + 1) * D));
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
    stream.root = decoded.end;
    stream.frame += frames;
    return chunk;
  }

  async generate(params: GenerateParams): Promise<GeneratedChunk> {
    const { frames, ...streamParams } = params;
    return this.advance(this.createStream(streamParams), frames);
  }

  /** Times `steps` raw session calls at `batch` rows, all starting from the first seed state. */
  async benchmark(batch: number, steps: number): Promise<BenchmarkResult> {
    if (!Number.isInteger(batch) || batch < 1 || batch > MAX_BENCHMARK_BATCH) throw new Error(`batch must be an integer from 1 to ${MAX_BENCHMARK_BATCH}, got ${batch}`);
    if (!Number.isInteger(steps) || steps < 1) throw new Error(`steps must be a positive integer, got ${steps}`);
    const inputs = this.batchInputs(new Array<number>(batch).fill(0));
    let h: Float32Array = inputs.h;
    let c: Float32Array = inputs.c;
    for (let i = 0; i < 3; i++) await this.step(batch, inputs.x, h, c); // warm-up
    const started = performance.now();
    for (let i = 0; i < steps; i++) {
      const out = await this.step(batch, inputs.x, h, c);
      h = out.h_out;
      c = out.c_out;
    }
    const ms = performance.now() - started;
    const stepsPerSecond = (steps * 1000) / ms;
    return { batch, steps, threads: this.threads, stepsPerSecond, msPerCall: ms / steps, particleStepsPerSecond: stepsPerSecond * batch };
  }

  /** One raw step; without inputs, the first and last seed states at batch 2 (the Python fixture's inputs). */
  async parity(inputs?: StepInputs): Promise<ParityResult> {
    const { L, H, D } = this;
    let batch: number, x: Float32Array, h: Float32Array, c: Float32Array;
    if (inputs) {
      batch = inputs.batch;
      x = Float32Array.from(inputs.x);
      h = Float32Array.from(inputs.h);
      c = Float32Array.from(inputs.c);
      if (!Number.isInteger(batch) || batch < 1 || x.length !== batch * D || h.length !== L * batch * H || c.length !== L * batch * H) {
        throw new Error(`parity inputs do not fit batch ${batch}: x has ${x.length} values (expected ${batch * D}), h ${h.length} and c ${c.length} (expected ${L * batch * H})`);
      }
    } else {
      batch = 2;
      ({ x, h, c } = this.batchInputs([0, this.info.seeds.length - 1]));
    }
    const outputs = await this.step(batch, x.slice(), h.slice(), c.slice());
    return { inputs: { batch, x, h, c }, outputs };
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
      for (let l = 0; l < L; l++) {
        h.set(seed.h.slice(l * H, (l + 1) * H), (l * B + b) * H);
        c.set(seed.c.slice(l * H, (l + 1) * H), (l * B + b) * H);
      }
    });
    return { x, h, c };
  }
}
