// The dance models' step loop (the acLSTM models and dance packs), independent of where it runs: an
// onnxruntime session, the feature decoder and the skeleton fit. dance.worker.ts wraps it in messages;
// unit tests drive it directly with onnxruntime-web's Node build. The loop is training/aclstm/shipped.py's:
// h = c = 0, the seed motion's frames are fed one by one (normalised), then each output is one new
// frame and is fed back as the next input. That feedback happens inside the graph (an ONNX Loop), so one
// call makes up to STEPS_PER_CALL frames. No randomness: the same style and seed give the same dance, however
// the frames are split into calls.
// A sampled model (`head: "mdn"`, issue 42) draws each frame from its mixture head inside the graph (the phrase rule of
// training/aclstm/phrase_sampling.py) and filters it for display. Each stream then carries the sampler's state, the
// filter's state and its own seeded random numbers (Rng(seed): D normals for the first wander, then per frame one
// uniform and D normals, in that order), so the same style and seed still give the same dance however the frames
// are split into calls. The page draws the filtered `display`; `ys` is what is fed back.
import type { InferenceSession, TensorConstructor } from 'onnxruntime-web';
import { SkeletonFitter } from '../../motion/fitSkeleton';
import { PlantedFeet } from '../../motion/footLock';
import { decodeDance, type DanceRoot } from './danceDecode';
import { isSampledDance, seedsOfStyle, type DanceInfo } from './danceModel';
import type {
  DanceChunk,
  DanceGenerateParams,
  DanceInitResult,
  DanceMdnFeeds,
  DanceMdnStepOutputs,
  DanceParityResult,
  DanceStepInputs,
  DanceStepOutputs,
  DanceStreamInfo,
  DanceStreamParams,
} from './danceProtocol';
import type { BenchmarkResult } from '../worker/protocol';
import { denormalise, Rng, type RandomSource } from '../../model/sampler';
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
  /** A sampled (mdn) model's sampler; undefined for a deterministic model. */
  sampler?: DanceSampler;
}

/** One sampled stream's randomness and the graph's carried sampler and filter state (batch 1). */
export interface DanceSampler {
  /** Seeded with the stream's seed; drawn in a fixed order (drawStepRandoms), so call splits do not matter. */
  readonly rng: Rng;
  held: BigInt64Array;
  age: BigInt64Array;
  wander: Float32Array;
  filt: Float32Array;
}

/** The largest float32 below 1: a uniform that float32 would round up to 1 is fed as this (the graph wants [0, 1)). */
const BELOW_ONE = 1 - 2 ** -24;

/**
 * The random numbers of `steps` sampled steps of one row, drawn from `rng` step by step: the step's uniform, then its
 * `dim` normals. Drawing per step (not all uniforms first) keeps a stream's numbers independent of how its frames are
 * split into calls.
 */
export function drawStepRandoms(rng: RandomSource, steps: number, dim: number): { uniforms: Float32Array; normals: Float32Array } {
  const uniforms = new Float32Array(steps);
  const normals = new Float32Array(steps * dim);
  for (let k = 0; k < steps; k++) {
    uniforms[k] = rng.uniform();
    if (uniforms[k] >= 1) uniforms[k] = BELOW_ONE;
    for (let d = 0; d < dim; d++) normals[k * dim + d] = rng.normal();
  }
  return { uniforms, normals };
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
  /** Mixture components of a sampled model (0 for a deterministic one). */
  private readonly K: number;
  /** True for a sampled (mdn) model. */
  readonly sampled: boolean;

  /** `Tensor` must come from the same onnxruntime module as the session. */
  constructor(session: InferenceSession, info: DanceInfo, Tensor: TensorConstructor, threads = 1) {
    super(session, info, Tensor, threads);
    ({ layers: this.L, hidden: this.H, dim: this.D } = info.onnx);
    this.S = info.styles.length;
    this.J = info.skeleton.joints.length;
    this.sampled = isSampledDance(info);
    this.K = this.sampled ? info.components! : 0;
    this.fitter = new SkeletonFitter({ joints: info.skeleton.joints, parents: info.skeleton.parents, offsets: Float32Array.from(info.skeleton.offsets) });
  }

  /** One step at batch 1 from zeros: a model whose sizes disagree with the JSON fails here, not mid-dance. */
  async check(): Promise<void> {
    const { L, H, D, S } = this;
    if (this.sampled) await this.mdnStep(1, new Float32Array(D), new Float32Array(S), new Float32Array(L * H), new Float32Array(L * H), 1, this.idleFeeds([0], 1));
    else await this.step(1, new Float32Array(D), new Float32Array(S), new Float32Array(L * H), new Float32Array(L * H), 1);
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
      sampled: this.sampled,
    };
  }

  /**
   * One raw session call of `steps` steps: x (B×D normalised), style (B×S one-hot), h and c (layers×B×H); ys holds
   * steps × B × D output frames. With `signal`, a cancellation checkpoint first.
   */
  async step(batch: number, x: Float32Array, style: Float32Array, h: Float32Array, c: Float32Array, steps: number, signal?: AbortSignal): Promise<DanceStepOutputs> {
    const { L, H, D, S } = this;
    if (this.sampled) throw new Error(`model "${this.info.id}" samples its frames (head "mdn"): its calls need the sampler's inputs (mdnStep)`);
    const read = await this.run(
      { x: [x, [batch, D]], style: [style, [batch, S]], h: [h, [L, batch, H]], c: [c, [L, batch, H]], steps: [BigInt64Array.of(BigInt(steps)), [1]] },
      signal,
    );
    return { ys: read('ys', steps * batch * D), h_out: read('h_out', L * batch * H), c_out: read('c_out', L * batch * H) };
  }

  /**
   * One raw call of a sampled (mdn) model: step's inputs plus the sampler's (`feeds`, B rows, `steps` steps of random
   * numbers); ys holds the sampled frames (fed back), display the filtered ones (drawn).
   */
  async mdnStep(
    batch: number,
    x: Float32Array,
    style: Float32Array,
    h: Float32Array,
    c: Float32Array,
    steps: number,
    feeds: DanceMdnFeeds,
    signal?: AbortSignal,
  ): Promise<DanceMdnStepOutputs> {
    const { L, H, D, S, K } = this;
    if (!this.sampled) throw new Error(`model "${this.info.id}" has no sampler (no head "mdn"): use step`);
    const B = batch;
    const read = await this.run(
      {
        x: [x, [B, D]],
        style: [style, [B, S]],
        h: [h, [L, B, H]],
        c: [c, [L, B, H]],
        steps: [BigInt64Array.of(BigInt(steps)), [1]],
        held: [feeds.held, [B]],
        age: [feeds.age, [B]],
        wander: [feeds.wander, [B, D]],
        temperature: [feeds.temperature, [B]],
        rho: [feeds.rho, [B]],
        threshold: [feeds.threshold, [B]],
        max_hold: [feeds.max_hold, [B]],
        min_hold: [feeds.min_hold, [B]],
        uniforms: [feeds.uniforms, [steps, B]],
        normals: [feeds.normals, [steps, B, D]],
        filt: [feeds.filt, [B, 4, D]],
        filter_b: [feeds.filter_b, [B, 3]],
        filter_a: [feeds.filter_a, [B, 2]],
      },
      signal,
    );
    return {
      ys: read('ys', steps * B * D),
      display: read('display', steps * B * D),
      h_out: read('h_out', L * B * H),
      c_out: read('c_out', L * B * H),
      held_out: read.int64('held_out', B),
      age_out: read.int64('age_out', B),
      wander_out: read('wander_out', B * D),
      filt_out: read('filt_out', B * 4 * D),
      weights: read('weights', steps * B * K),
    };
  }

  /**
   * Feeds of a sampled call for rows of the given style indices with no sampler history: the styles' settings and
   * filters, nothing held, zero wander and filter state, uniforms ½ and zero normals (the seed warm-up, whose
   * outputs other than h and c are thrown away; check; benchmark).
   */
  private idleFeeds(styleIndices: number[], steps: number): DanceMdnFeeds {
    const B = styleIndices.length;
    const { D } = this;
    const { params, filter } = this.info.sampling!;
    const feeds: DanceMdnFeeds = {
      held: new BigInt64Array(B).fill(-1n),
      age: new BigInt64Array(B),
      wander: new Float32Array(B * D),
      temperature: new Float32Array(B),
      rho: new Float32Array(B),
      threshold: new Float32Array(B),
      max_hold: new BigInt64Array(B),
      min_hold: new BigInt64Array(B),
      uniforms: new Float32Array(steps * B).fill(0.5),
      normals: new Float32Array(steps * B * D),
      filt: new Float32Array(B * 4 * D),
      filter_b: new Float32Array(B * 3),
      filter_a: new Float32Array(B * 2),
    };
    styleIndices.forEach((s, b) => {
      const name = this.info.styles[s];
      const p = params[name], f = filter[name];
      feeds.temperature[b] = p.temperature;
      feeds.rho[b] = p.rho;
      feeds.threshold[b] = p.threshold;
      feeds.max_hold[b] = BigInt(p.max_hold);
      feeds.min_hold[b] = BigInt(p.min_hold);
      feeds.filter_b.set(f.b, b * 3);
      feeds.filter_a.set(f.a.slice(1), b * 2);
    });
    return feeds;
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
    const styleIndex = this.info.styles.indexOf(params.style);
    const style = new Float32Array(S);
    style[styleIndex] = 1;
    let h: Float32Array = new Float32Array(L * H);
    let c: Float32Array = new Float32Array(L * H);
    let x: Float32Array = new Float32Array(D);
    const normalised = this.info.seeds[seedIndex].frames.map((frame) => {
      const input = new Float32Array(D);
      for (let d = 0; d < D; d++) input[d] = (frame[d] - this.mean[d]) / this.std[d];
      return input;
    });
    const { joints, offsets } = this.info.skeleton;
    const feet = new PlantedFeet(joints, offsets, this.info.fps, { groundHeight: DANCE_TOE_GROUND_HEIGHT });
    const streamParams = { style: params.style, seed: params.seed };
    if (this.sampled) {
      // The seed frames but the last go in one by one, only h and c kept; the last is the first sampled call's input,
      // so frame 0 is drawn from the mixture that follows the whole seed by a fresh sampler (phrase_sampling.py's
      // phrase_rollout). The filter starts at rest on the last seed frame.
      for (const input of normalised.slice(0, -1)) {
        ({ h_out: h, c_out: c } = await this.mdnStep(1, input, style, h, c, 1, this.idleFeeds([styleIndex], 1), signal));
      }
      x = normalised[normalised.length - 1];
      const rng = new Rng(params.seed);
      const wander = new Float32Array(D);
      for (let d = 0; d < D; d++) wander[d] = rng.normal();
      const filt = new Float32Array(4 * D);
      for (let i = 0; i < 4; i++) filt.set(x, i * D);
      const sampler: DanceSampler = { rng, held: BigInt64Array.of(-1n), age: BigInt64Array.of(0n), wander, filt };
      return { params: streamParams, seedIndex, style, x, h, c, root: { x: 0, z: 0 }, frame: 0, feet, sampler };
    }
    for (const input of normalised) ({ ys: x, h_out: h, c_out: c } = await this.step(1, input, style, h, c, 1, signal));
    return { params: streamParams, seedIndex, style, x, h, c, root: { x: 0, z: 0 }, frame: 0, feet };
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
    if (stream.sampler) await this.advanceSampled(stream, stream.sampler, features, signal);
    else for (let t = 0; t < frames; ) {
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

  /**
   * A sampled stream's next frames (features.length / D of them) into `features`: each call's input is the pending
   * frame, its ys are the next frames (the last one the next input), its display (filtered) what is drawn.
   */
  private async advanceSampled(stream: DanceStream, sampler: DanceSampler, features: Float32Array<ArrayBuffer>, signal?: AbortSignal): Promise<void> {
    const { D } = this;
    const frames = features.length / D;
    const styleIndex = this.info.styles.indexOf(stream.params.style);
    for (let t = 0; t < frames; ) {
      const steps = Math.min(STEPS_PER_CALL, frames - t);
      const feeds = this.idleFeeds([styleIndex], steps);
      Object.assign(feeds, drawStepRandoms(sampler.rng, steps, D), { held: sampler.held, age: sampler.age, wander: sampler.wander, filt: sampler.filt });
      const out = await this.mdnStep(1, stream.x, stream.style, stream.h, stream.c, steps, feeds, signal);
      for (let k = 0; k < steps; k++, t++) {
        const row = features.subarray(t * D, (t + 1) * D);
        denormalise(out.display.subarray(k * D, (k + 1) * D), this.mean, this.std, row);
        if (!row.every(Number.isFinite)) throw new Error(`the model produced a non-finite value at frame ${stream.frame + t}`);
      }
      stream.x = out.ys.slice((steps - 1) * D);
      stream.h = out.h_out;
      stream.c = out.c_out;
      sampler.held = out.held_out;
      sampler.age = out.age_out;
      sampler.wander = out.wander_out;
      sampler.filt = out.filt_out;
    }
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
      if (this.sampled) {
        // The sampler's state fed back too; fixed random numbers (drawing them is not the graph's cost).
        const feeds = this.idleFeeds(Array.from({ length: batch }, (_, b) => b % S), perCall);
        return async () => {
          const out = await this.mdnStep(batch, x, style, h, c, perCall, feeds);
          ({ h_out: h, c_out: c } = out);
          Object.assign(feeds, { held: out.held_out, age: out.age_out, wander: out.wander_out, filt: out.filt_out });
          x = out.ys.slice((perCall - 1) * batch * D);
        };
      }
      return async () => {
        const out = await this.step(batch, x, style, h, c, perCall);
        ({ h_out: h, c_out: c } = out);
        x = out.ys.slice((perCall - 1) * batch * D);
      };
    }, perCall);
  }

  /**
   * One raw call on the given inputs (tests/fixtures/aclstm_reference.json's `step.inputs` and `steps.inputs`; a sampled
   * model's also need the sampler's, DanceMdnFeeds' fields as plain numbers).
   */
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
    if (!this.sampled) return { outputs: await this.step(batch, x, style, h, c, steps) };
    const sizes: Record<keyof DanceMdnFeeds, number> = {
      held: batch, age: batch, wander: batch * D, temperature: batch, rho: batch, threshold: batch, max_hold: batch, min_hold: batch,
      uniforms: steps * batch, normals: steps * batch * D, filt: batch * 4 * D, filter_b: batch * 3, filter_a: batch * 2,
    };
    const ints = new Set<keyof DanceMdnFeeds>(['held', 'age', 'max_hold', 'min_hold']);
    const feeds = {} as Record<keyof DanceMdnFeeds, Float32Array | BigInt64Array>;
    for (const [name, size] of Object.entries(sizes) as [keyof DanceMdnFeeds, number][]) {
      const values = Array.from(inputs[name] ?? []);
      if (values.length !== size) throw new Error(`parity input ${name} has ${values.length} values, expected ${size} (batch ${batch}, ${steps} steps) for a sampled model`);
      if (ints.has(name) && !values.every(Number.isInteger)) throw new Error(`parity input ${name} must hold integers`);
      feeds[name] = ints.has(name) ? BigInt64Array.from(values, (v) => BigInt(v)) : Float32Array.from(values);
    }
    return { outputs: await this.mdnStep(batch, x, style, h, c, steps, feeds as unknown as DanceMdnFeeds) };
  }
}
