// The latent ERD's runtime, independent of where it runs: the ERD step session (latent-erd.onnx), the
// autoencoder's unpadded decoder session (manifold-decoder.onnx) and streams of the online algorithm
// (web/model/latentStream.ts, the port of training/latent_erd/streaming.py). latentErd.worker.ts wraps it in
// messages; unit tests drive it directly with onnxruntime-web's Node build. The autoencoder's encoder session
// (manifold-encoder.onnx), loaded on first use, serves the `manifold` clean-up (projectManifold:
// manifoldProjection.ts).
//
// A stream emits one latent step (4 frames) at a time for a control; its frames are the decoded points
// placed in the world at the stream's root, fitted to the skeleton (web/motion/fitSkeleton.ts: exact bone
// lengths), and, unless the stream was made without the lock, contacts labelled on those frames from the
// decoded contact channels (> 0.5) with the feet's heights and speeds (web/motion/contactLabels.ts) and
// planted feet locked frame by frame (web/motion/footLock.ts PlantedFeet); without the lock the contacts
// are the decoded channels as they are. Frames are handed out in any
// chunk sizes (`take`): a step's frames not yet taken wait for the next chunk, so chunks join up exactly.
import type { InferenceSession, TensorConstructor } from 'onnxruntime-web';
import { randomControl, type Root } from '../../motion/control';
import { SkeletonFitter } from '../../motion/fitSkeleton';
import { PlantedFeet } from '../../motion/footLock';
import { latentSeedIndex, type LatentErdInfo, type LatentErdModel, type ManifoldInfo } from '../../model/latentErdInfo';
import { LatentStream, streamLayout, type LatentBackend, type StreamLayout } from '../../model/latentStream';
import { checkpoint } from '../worker/cancellation';
import { projectOnManifold, type ManifoldProjection } from '../autoencoder/manifoldProjection';
import type {
  LatentChunk,
  LatentErdInitResult,
  LatentGenerateParams,
  LatentParityInputs,
  LatentParityResult,
  LatentStepInputs,
  LatentStepOutputs,
  LatentStreamInfo,
  LatentStreamParams,
} from './latentErdProtocol';
import type { BenchmarkResult } from '../worker/protocol';
import { checkFrameCount, SessionCore, timeSteps } from '../worker/session';

/** The ERD step session (latent normalisation as its normalisation: the session base wants one). */
class ErdSession extends SessionCore<{ id: string; file: string; onnx: { inputs: string[]; outputs: string[] }; normalisation: { mean: number[]; std: number[] } }> {
  constructor(session: InferenceSession, private readonly erd: LatentErdInfo, Tensor: TensorConstructor, threads: number) {
    super(session, { id: erd.id, file: erd.file, onnx: { inputs: erd.inputs, outputs: erd.outputs }, normalisation: erd.latent_normalisation }, Tensor, threads);
  }

  async step(batch: number, z: Float32Array, control: Float32Array, h: Float32Array, c: Float32Array, signal?: AbortSignal): Promise<LatentStepOutputs> {
    const { latent, control_dim: C, layers: L, hidden: H } = this.erd;
    const read = await this.run({ z: [z, [batch, latent]], control: [control, [batch, C]], h: [h, [L, batch, H]], c: [c, [L, batch, H]] }, signal);
    return { z_next: read('z_next', batch * latent), h_out: read('h_out', L * batch * H), c_out: read('c_out', L * batch * H) };
  }
}

/** The unpadded decoder: latent (1, steps, latent) physical → rows (1, pooling × (steps − 2 radius), dim) normalised. */
class DecoderSession extends SessionCore<{ id: string; file: string; onnx: { inputs: string[]; outputs: string[] }; normalisation: { mean: number[]; std: number[] } }> {
  constructor(session: InferenceSession, private readonly manifold: ManifoldInfo, Tensor: TensorConstructor, threads: number) {
    super(session, { id: manifold.id, file: manifold.files.decoder, onnx: { inputs: ['latent'], outputs: ['rows'] }, normalisation: manifold.normalisation }, Tensor, threads);
  }

  async decode(steps: number, latent: Float32Array, signal?: AbortSignal): Promise<Float32Array> {
    const { latent: Z, pooling, radius } = this.manifold;
    const rows = this.manifold.rows.dim;
    if (steps <= 2 * radius) throw new Error(`the decoder needs more than ${2 * radius} latent steps, got ${steps}`);
    const read = await this.run({ latent: [latent, [1, steps, Z]] }, signal);
    return read('rows', pooling * (steps - 2 * radius) * rows);
  }
}

/** The encoder: rows (1, frames, dim) normalised → latent (1, frames / pooling, latent) physical, zero-padded at the ends as in training. */
class EncoderSession extends SessionCore<{ id: string; file: string; onnx: { inputs: string[]; outputs: string[] }; normalisation: { mean: number[]; std: number[] } }> {
  constructor(session: InferenceSession, private readonly manifold: ManifoldInfo, Tensor: TensorConstructor, threads: number) {
    super(session, { id: manifold.id, file: manifold.files.encoder, onnx: { inputs: ['rows'], outputs: ['latent'] }, normalisation: manifold.normalisation }, Tensor, threads);
  }

  async encode(frames: number, rows: Float32Array, signal?: AbortSignal): Promise<Float32Array> {
    const { latent: Z, pooling } = this.manifold;
    if (frames % pooling !== 0) throw new Error(`the encoder needs a multiple of ${pooling} frames, got ${frames}`);
    const read = await this.run({ rows: [rows, [1, frames, this.manifold.rows.dim]] }, signal);
    return read('latent', (frames / pooling) * Z);
  }
}

/** One stream: the online state, its control source, the fitter's and foot lock's state, frames not yet taken. */
export interface LatentErdStream {
  readonly params: LatentStreamParams;
  readonly seedIndex: number;
  readonly stream: LatentStream;
  /** Contact labels and the foot lock, or null for a stream made without the lock. */
  readonly feet: PlantedFeet | null;
  /** Frames taken so far. */
  frame: number;
  /** The per-frame control it follows when advanced without one (given, or random from the seed; frames × 3). */
  control: Float64Array;
  /** Whether `control` grows (random control) or ends (given: its last frame repeats). */
  endless: boolean;
  /** Emitted frames not yet taken, oldest first. */
  pending: Piece[];
}

/** One emitted latent step, as frames. */
interface Piece {
  frames: number;
  /** Frames of it already taken. */
  used: number;
  rows: Float32Array;
  predicted: Float32Array;
  positions: Float32Array;
  contacts: Uint8Array;
  roots: Float64Array;
  control: Float32Array;
  erdCalls: number;
}

export interface StreamOptions {
  /** Where the root starts (default the origin facing +z). */
  root?: Root;
  /** Look-ahead steps (default the model's). */
  lookahead?: number;
}

export class LatentErdCore {
  readonly erd: LatentErdInfo;
  readonly manifold: ManifoldInfo;
  readonly layout: StreamLayout;
  readonly threads: number;
  /** The skeleton of the frames: joints, parents, flat rest offsets. */
  readonly skeleton: { joints: string[]; parents: number[]; offsets: Float32Array };
  private readonly erdSession: ErdSession;
  private decoder: DecoderSession | undefined;
  private decoderLoading: Promise<DecoderSession> | undefined;
  private encoder: EncoderSession | undefined;
  private encoderLoading: Promise<EncoderSession> | undefined;
  private readonly fitter: SkeletonFitter;

  /**
   * `session` runs latent-erd.onnx; `loadDecoder` gives manifold-decoder.onnx's session (called by `check`,
   * once); `loadEncoder` gives manifold-encoder.onnx's (called by the first projectManifold). `Tensor` must
   * come from the same onnxruntime module as the sessions.
   */
  constructor(
    session: InferenceSession,
    model: LatentErdModel,
    private readonly Tensor: TensorConstructor,
    threads = 1,
    private readonly loadDecoder: () => Promise<InferenceSession>,
    private readonly loadEncoder?: () => Promise<InferenceSession>,
  ) {
    this.erd = model.erd;
    this.manifold = model.manifold;
    this.threads = threads;
    this.erdSession = new ErdSession(session, model.erd, Tensor, threads);
    this.layout = streamLayout(model.erd, model.manifold);
    const sk = model.manifold.skeleton;
    this.skeleton = { joints: sk.joints, parents: sk.parents, offsets: Float32Array.from(sk.offsets.flat()) };
    this.fitter = new SkeletonFitter(this.skeleton);
  }

  get fps(): number {
    return this.erd.fps;
  }

  /** Loads the decoder (first call), then one ERD step and one decoder window from zeros: sizes that disagree with the JSON fail here. */
  async check(): Promise<void> {
    const { latent, control_dim: C, layers: L, hidden: H, radius } = this.erd;
    await this.erdSession.step(1, new Float32Array(latent), new Float32Array(C), new Float32Array(L * H), new Float32Array(L * H));
    const decoder = await this.decoderSession();
    await decoder.decode(2 * radius + 1, new Float32Array((2 * radius + 1) * latent));
  }

  private decoderSession(): Promise<DecoderSession> {
    if (this.decoder) return Promise.resolve(this.decoder);
    this.decoderLoading ??= this.loadDecoder().then(
      (session) => (this.decoder = new DecoderSession(session, this.manifold, this.Tensor, this.threads)),
      (err: unknown) => {
        this.decoderLoading = undefined;
        throw err;
      },
    );
    return this.decoderLoading;
  }

  private encoderSession(): Promise<EncoderSession> {
    if (this.encoder) return Promise.resolve(this.encoder);
    const load = this.loadEncoder;
    if (!load) return Promise.reject(new Error('the latent ERD core was made without the manifold encoder'));
    this.encoderLoading ??= load().then(
      (session) => (this.encoder = new EncoderSession(session, this.manifold, this.Tensor, this.threads)),
      (err: unknown) => {
        this.encoderLoading = undefined;
        throw err;
      },
    );
    return this.encoderLoading;
  }

  async release(): Promise<void> {
    const decoder = this.decoderLoading;
    const encoder = this.encoderLoading;
    this.decoderLoading = undefined;
    this.decoder = undefined;
    this.encoderLoading = undefined;
    this.encoder = undefined;
    await decoder?.then((d) => d.release(), () => undefined);
    await encoder?.then((e) => e.release(), () => undefined);
    await this.erdSession.release();
  }

  describe(loadMs: number): LatentErdInitResult {
    const erd = this.erd;
    return {
      ok: true,
      threads: this.threads,
      loadMs,
      id: erd.id,
      fps: erd.fps,
      joints: this.skeleton.joints,
      parents: this.skeleton.parents,
      offsets: Array.from(this.skeleton.offsets),
      pooling: erd.pooling,
      radius: erd.radius,
      lookahead: erd.lookahead,
      seeds: erd.seeds.map((s) => ({ name: s.name, category: s.category })),
      ...(erd.control_range ? { controlRange: erd.control_range } : {}),
    };
  }

  /** The networks for one stream (batch 1). */
  private backend(): LatentBackend {
    const decoder = this.decoder;
    if (!decoder) throw new Error('the latent ERD decoder is not loaded: call check() first');
    const steps = 2 * this.erd.radius + 1;
    return {
      step: async (z, control, h, c) => {
        const o = await this.erdSession.step(1, z, control, h, c);
        return { z: o.z_next, h: o.h_out, c: o.c_out };
      },
      decode: (window) => decoder.decode(steps, window),
    };
  }

  /**
   * A new stream on the seed state `params.seed` picks (seed mod the seeds, of `params.gait`'s category when
   * given), warmed up on it. Stops (making no stream) when `signal` aborts.
   */
  async createStream(params: LatentStreamParams, signal?: AbortSignal, options: StreamOptions = {}): Promise<LatentErdStream> {
    const seedIndex = latentSeedIndex(this.erd, checkStreamSeed(params.seed), params.gait);
    const lookahead = options.lookahead ?? this.erd.lookahead;
    const stream = await LatentStream.create(this.backend(), this.layout, this.erd.seeds[seedIndex], lookahead, options.root, look(signal));
    const given = params.control !== undefined;
    const control = given ? Float64Array.from(params.control!) : new Float64Array(0);
    if (given && (control.length === 0 || control.length % 3 !== 0)) throw new Error(`control must hold [forward, sideways, turn] triples, got ${control.length} values`);
    const feet = params.footLock === false ? null : new PlantedFeet(this.skeleton.joints, this.skeleton.offsets, this.erd.fps);
    return { params, seedIndex, stream, feet, frame: 0, control, endless: !given, pending: [] };
  }

  streamInfo(s: LatentErdStream): LatentStreamInfo {
    return { seedIndex: s.seedIndex, seedName: this.erd.seeds[s.seedIndex].name };
  }

  /**
   * Emits the stream's next latent step for `control` (pooling × 3 physical, flattened); `future` gives the
   * expected controls of the steps after it (else the look-ahead repeats `control`). Its frames wait in the
   * stream until taken. Stops at the next network call once `signal` aborts.
   */
  async emit(s: LatentErdStream, control: ArrayLike<number>, future?: ArrayLike<number>[], signal?: AbortSignal): Promise<void> {
    const { pooling, joints } = this.layout;
    const calls = s.stream.erdCalls;
    const out = await s.stream.step(control, future, look(signal));
    const predicted = Float32Array.from(out.positions);
    const positions = this.fitter.fit(predicted).positions;
    const contacts = out.contacts;
    if (s.feet) {
      const n = joints * 3;
      const bits = new Uint8Array(2);
      for (let f = 0; f < pooling; f++) {
        const pose = positions.subarray(f * n, (f + 1) * n);
        const labels = contacts.subarray(f * 2, f * 2 + 2);
        bits.set(labels);
        s.feet.step(pose, bits, labels);
      }
    }
    s.pending.push({
      frames: pooling,
      used: 0,
      rows: Float32Array.from(out.rows),
      predicted,
      positions,
      contacts,
      roots: out.roots,
      control: Float32Array.from(control),
      erdCalls: s.stream.erdCalls - calls,
    });
  }

  /** Frames emitted and not yet taken. */
  pendingFrames(s: LatentErdStream): number {
    return s.pending.reduce((n, p) => n + p.frames - p.used, 0);
  }

  /** The next `frames` emitted frames (emitted before: see `emit`) as a chunk. */
  take(s: LatentErdStream, frames: number, computeMs = 0): LatentChunk {
    if (frames > this.pendingFrames(s)) throw new Error(`take: ${frames} frames asked, ${this.pendingFrames(s)} emitted`);
    const { joints, rowDim } = this.layout;
    const n = joints * 3;
    const chunk: LatentChunk = {
      frames,
      rows: new Float32Array(frames * rowDim),
      predicted: new Float32Array(frames * n),
      positions: new Float32Array(frames * n),
      contacts: new Uint8Array(frames * 2),
      roots: new Float64Array(frames * 3),
      rootHeading: new Float32Array(frames),
      control: new Float32Array(frames * 3),
      seedIndex: s.seedIndex,
      startFrame: s.frame,
      erdCalls: 0,
      decodeCalls: 0,
      computeMs,
    };
    let at = 0;
    while (at < frames) {
      const p = s.pending[0];
      const k = Math.min(p.frames - p.used, frames - at);
      if (p.used === 0) {
        chunk.erdCalls += p.erdCalls;
        chunk.decodeCalls++;
      }
      const copy = <T extends Float32Array | Float64Array | Uint8Array>(src: T, dst: T, width: number) => dst.set(src.subarray(p.used * width, (p.used + k) * width), at * width);
      copy(p.rows, chunk.rows, rowDim);
      copy(p.predicted, chunk.predicted, n);
      copy(p.positions, chunk.positions, n);
      copy(p.contacts, chunk.contacts, 2);
      copy(p.roots, chunk.roots, 3);
      copy(p.control, chunk.control, 3);
      p.used += k;
      at += k;
      if (p.used === p.frames) s.pending.shift();
    }
    for (let f = 0; f < frames; f++) chunk.rootHeading[f] = chunk.roots[f * 3 + 2];
    s.frame += frames;
    return chunk;
  }

  /**
   * The stream's next `frames` frames along its own control (given, or the random control from its seed);
   * the look-ahead sees the control's next steps unless the stream says `knownFuture: false`.
   */
  async advance(s: LatentErdStream, frames: number, signal?: AbortSignal): Promise<LatentChunk> {
    checkFrameCount(frames);
    const started = performance.now();
    while (this.pendingFrames(s) < frames) {
      const step = s.stream.steps;
      const future: Float64Array[] = [];
      if (s.params.knownFuture !== false) {
        for (let k = 1; k <= s.stream.lookahead; k++) {
          const next = this.stepControl(s, step + k, false);
          if (!next) break;
          future.push(next);
        }
      }
      await this.emit(s, this.stepControl(s, step, true)!, future, signal);
    }
    return this.take(s, frames, performance.now() - started);
  }

  /**
   * Latent step `step`'s control (pooling frames × 3) from the stream's control: random control grows as
   * needed; a given one ends, and a step past its end is undefined, or with `pad` its frames past the end
   * repeat the last given frame (the step holding the last frames).
   */
  private stepControl(s: LatentErdStream, step: number, pad: boolean): Float64Array | undefined {
    const { pooling, fps } = this.layout;
    const end = (step + 1) * pooling;
    if (s.endless && s.control.length < end * 3) s.control = randomControl(s.params.seed, Math.max(end, 2 * (s.control.length / 3), 256), fps);
    const have = s.control.length / 3;
    if (end > have && !pad) return undefined;
    const out = new Float64Array(pooling * 3);
    for (let t = 0; t < pooling; t++) {
      const f = Math.min(step * pooling + t, have - 1);
      out.set(s.control.subarray(f * 3, f * 3 + 3), t * 3);
    }
    return out;
  }

  /** `frames` frames of a new stream (see LatentStreamParams); stops when `signal` aborts. */
  async generate(params: LatentGenerateParams, signal?: AbortSignal, options: StreamOptions = {}): Promise<LatentChunk> {
    const { frames, ...streamParams } = params;
    checkFrameCount(frames);
    if (streamParams.control !== undefined && streamParams.control.length < frames * 3) {
      throw new Error(`control has ${streamParams.control.length / 3} frames; it needs at least ${frames}`);
    }
    const started = performance.now();
    const s = await this.createStream(streamParams, signal, options);
    const chunk = await this.advance(s, frames, signal);
    chunk.computeMs = performance.now() - started;
    return chunk;
  }

  /**
   * The `manifold` clean-up: canonical world positions (frames × joints × 3, at the model's fps) and optional
   * contacts (frames × 2) projected through the autoencoder in overlapping windows (manifoldProjection.ts).
   * Loads the encoder on first use; stops at the next network call once `signal` aborts.
   */
  async projectManifold(positions: Float32Array, contacts: Uint8Array | undefined, signal?: AbortSignal, progress?: (fraction: number) => void): Promise<ManifoldProjection> {
    const [encoder, decoder] = await Promise.all([this.encoderSession(), this.decoderSession()]);
    return projectOnManifold({
      encode: (rows, frames) => encoder.encode(frames, rows, signal),
      decode: (latent, steps) => decoder.decode(steps, latent, signal),
      manifold: this.manifold,
      positions,
      ...(contacts === undefined ? {} : { contacts }),
      fps: this.erd.fps,
      onWindow: (done, windows) => progress?.(done / windows),
    });
  }

  /** Times `steps` raw ERD step calls at `batch` streams, each feeding its output and state back. */
  benchmark(batch: number, steps: number): Promise<BenchmarkResult> {
    return timeSteps(batch, steps, this.threads, () => {
      const { latent, control_dim: C, layers: L, hidden: H } = this.erd;
      let z: Float32Array = new Float32Array(batch * latent);
      const control = new Float32Array(batch * C);
      let h: Float32Array = new Float32Array(L * batch * H);
      let c: Float32Array = new Float32Array(L * batch * H);
      return async () => {
        ({ z_next: z, h_out: h, c_out: c } = await this.erdSession.step(batch, z, control, h, c));
      };
    });
  }

  /** One raw ERD step and/or one decoder call on the given inputs (tests/fixtures/latent_erd_reference.json's `step.inputs`, `decode`). */
  async parity(inputs: LatentParityInputs): Promise<LatentParityResult> {
    const out: LatentParityResult = {};
    const { latent, control_dim: C, layers: L, hidden: H } = this.erd;
    if (inputs?.step) {
      const batch = inputs.step.batch;
      if (!Number.isInteger(batch) || batch < 1) throw new Error(`parity needs step inputs { batch, z, control, h, c }, got batch ${String(batch)}`);
      const { z, control, h, c } = Object.fromEntries((['z', 'control', 'h', 'c'] as const).map((k) => [k, Float32Array.from(inputs.step![k] ?? [])])) as Record<keyof Omit<LatentStepInputs, 'batch'>, Float32Array>;
      if (z.length !== batch * latent || control.length !== batch * C || h.length !== L * batch * H || c.length !== L * batch * H) {
        throw new Error(
          `parity step inputs do not fit batch ${batch}: z has ${z.length} values (expected ${batch * latent}), control ${control.length} (expected ${batch * C}), ` +
            `h ${h.length} and c ${c.length} (expected ${L * batch * H})`,
        );
      }
      out.step = await this.erdSession.step(batch, z, control, h, c);
    }
    if (inputs?.decode) {
      const { steps } = inputs.decode;
      const window = Float32Array.from(inputs.decode.latent ?? []);
      if (!Number.isInteger(steps) || window.length !== steps * latent) throw new Error(`parity decode inputs: ${window.length} values for ${String(steps)} latent steps of ${latent}`);
      out.decode = await (await this.decoderSession()).decode(steps, window);
    }
    if (!out.step && !out.decode) throw new Error('parity needs { step } and/or { decode } inputs');
    return out;
  }
}

/** A cancellation checkpoint before every network call, when there is a signal. */
function look(signal: AbortSignal | undefined): (() => Promise<void> | undefined) | undefined {
  return signal ? () => checkpoint(signal) : undefined;
}

function checkStreamSeed(seed: unknown): number {
  if (typeof seed !== 'number' || !Number.isInteger(seed) || seed < 0 || seed > 0xffffffff) throw new RangeError(`seed must be an integer from 0 to 4294967295, got ${String(seed)}`);
  return seed;
}
