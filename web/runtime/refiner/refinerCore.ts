// The refiner R (Wang, Chai, Xia §4.2) streamed right behind the generator, as refiner.json "usage" says:
// per generated chunk, R gets the generator's raw frames (normalised, contacts snapped as fed back), their
// root-frame end-effector positions and those of the frame before, and its own LSTM state, all in one call
// (R is causal, so this is what per-frame steps give, without a session call per frame); the refined frames are
// decoded (contact on when its physical value is above the threshold) and the foot lock (footLock.ts) cleans
// the decoded positions. The generator itself is always fed its own raw frames. Independent of where it runs,
// like GeneratorCore: the generator worker wraps it, unit tests drive it with onnxruntime-web's Node build.
import type { InferenceSession, TensorConstructor } from 'onnxruntime-web';
import { PlantedFeet } from '../../motion/footLock';
import { decodeFeatures, type RootStart } from '../../model/featureDecode';
import type { GeneratorInfo } from '../../model/generatorInfo';
import type { RefinedFrames, RefinerStepInputs, RefinerStepOutputs } from '../generator/protocol';
import { checkRefinerPairing, footLockSettings, type RefinerInfo } from './refinerModel';
import { denormalise } from '../../model/sampler';
import { SessionCore } from '../worker/session';

/** One refined stream: R's state, the previous raw frame's end effectors, the refined root and the foot lock. */
export interface RefinerStream {
  h: Float32Array;
  c: Float32Array;
  endsPrev: Float32Array;
  /** Where the refined character stands after the last refined frame (it decodes its own root channels). */
  root: RootStart;
  /** Contacts labelled on the refined frames, and the lock on them. */
  feet: PlantedFeet;
}

export class RefinerCore extends SessionCore<RefinerInfo> {
  readonly generator: GeneratorInfo;
  private readonly H: number;
  private readonly D: number;
  private readonly E3: number;
  private readonly endJoints: number[];

  /** `generator` is the loaded generator's JSON (the refiner must fit it); `Tensor` must come from the session's onnxruntime module. */
  constructor(session: InferenceSession, info: RefinerInfo, generator: GeneratorInfo, Tensor: TensorConstructor, threads = 1) {
    super(session, info, Tensor, threads);
    checkRefinerPairing(info, generator);
    this.generator = generator;
    ({ hidden: this.H, dim: this.D, ends: this.E3 } = info.onnx);
    this.endJoints = info.end_effectors.joints;
  }

  /** One step from a zero state: a model whose sizes disagree with its JSON fails at load time. */
  async check(): Promise<void> {
    const { H, D, E3 } = this;
    await this.step(1, 1, new Float32Array(D), new Float32Array(E3), new Float32Array(E3), new Float32Array(H), new Float32Array(H));
  }

  /** One raw session call over T frames per stream: x (B×T×D normalised), ends (B×T×3E metres), ends_prev (B×3E), h and c (1×B×H). */
  async step(batch: number, frames: number, x: Float32Array, ends: Float32Array, endsPrev: Float32Array, h: Float32Array, c: Float32Array): Promise<RefinerStepOutputs> {
    const { H, D, E3 } = this;
    const read = await this.run({
      x: [x, [batch, frames, D]],
      ends: [ends, [batch, frames, E3]],
      ends_prev: [endsPrev, [batch, E3]],
      h: [h, [1, batch, H]],
      c: [c, [1, batch, H]],
    });
    return { x_refined: read('x_refined', batch * frames * D), h_out: read('h_out', batch * H), c_out: read('c_out', batch * H) };
  }

  /**
   * Root-frame end-effector positions (frames × 3E, metres) of physical generator frames (frames × D):
   * q = R_y(−yaw)(p − (root x, 0, root z)), i.e. the frame decoded with no step and no heading
   * (refiner.json end_effectors.frame). Computed from the features, not from world positions, so it stays
   * exact however far the character has walked.
   */
  endEffectors(physical: Float32Array): Float32Array {
    const { D, E3 } = this;
    if (physical.length % D !== 0) throw new Error(`endEffectors: ${physical.length} values is not a whole number of ${D}-value frames`);
    const frames = physical.length / D;
    const still = Float32Array.from(physical);
    for (let f = 0; f < frames; f++) still[f * D] = still[f * D + 1] = still[f * D + 2] = 0; // dtx, dtz, dry
    const { positions } = decodeFeatures(this.generator, still);
    const J = this.generator.skeleton.joints.length;
    const ends = new Float32Array(frames * E3);
    for (let f = 0; f < frames; f++) {
      this.endJoints.forEach((j, k) => ends.set(positions.subarray((f * J + j) * 3, (f * J + j) * 3 + 3), f * E3 + k * 3));
    }
    return ends;
  }

  /** A refined stream behind a generator stream whose first input frame (its seed frame) is `seedPhysical` (D values, physical). */
  createStream(seedPhysical: Float32Array): RefinerStream {
    const { H } = this;
    const { joints, offsets } = this.generator.skeleton;
    return {
      h: new Float32Array(H),
      c: new Float32Array(H),
      endsPrev: this.endEffectors(seedPhysical),
      root: { x: 0, z: 0, heading: 0 },
      feet: new PlantedFeet(joints, offsets, this.generator.fps, footLockSettings(this.info)),
    };
  }

  /**
   * Refines the generator's next frames: `normalised` as the generator fed them back (frames × D) and the
   * same in physical units. Returns the refined frames decoded and foot-locked, continuing the stream.
   */
  async refine(stream: RefinerStream, normalised: Float32Array, physical: Float32Array): Promise<RefinedFrames> {
    const { D, E3 } = this;
    const frames = normalised.length / D;
    if (!Number.isInteger(frames) || physical.length !== normalised.length) {
      throw new Error(`refine: ${normalised.length} normalised and ${physical.length} physical values are not the same whole number of ${D}-value frames`);
    }
    if (frames === 0) return { features: new Float32Array(0), positions: new Float32Array(0), contacts: new Uint8Array(0), rootHeading: new Float32Array(0) };
    const ends = this.endEffectors(physical);
    const out = await this.step(1, frames, normalised, ends, stream.endsPrev, stream.h, stream.c);
    const refined = out.x_refined;
    stream.h = out.h_out;
    stream.c = out.c_out;
    stream.endsPrev = ends.slice((frames - 1) * E3);
    const features = denormalise(refined, this.mean, this.std);
    const decoded = decodeFeatures(this.generator, features, stream.root);
    stream.root = decoded.end;
    const threshold = this.info.contact_threshold;
    const contacts = decoded.contacts;
    const positions = decoded.positions;
    const n = this.generator.skeleton.joints.length * 3;
    const bits = new Uint8Array(2);
    for (let f = 0; f < frames; f++) {
      for (let k = 0; k < 2; k++) bits[k] = features[f * D + D - 2 + k] > threshold ? 1 : 0;
      const pose = positions.subarray(f * n, (f + 1) * n);
      stream.feet.step(pose, bits, contacts.subarray(f * 2, f * 2 + 2));
    }
    return { features, positions, contacts, rootHeading: decoded.rootHeading };
  }

  /** One raw call on given inputs (the parity check against tests/fixtures/refiner_reference.json). */
  async parity(inputs: RefinerStepInputs): Promise<RefinerStepOutputs> {
    const { H, D, E3 } = this;
    const { batch, frames } = inputs;
    const x = Float32Array.from(inputs.x), ends = Float32Array.from(inputs.ends), endsPrev = Float32Array.from(inputs.ends_prev);
    const h = Float32Array.from(inputs.h), c = Float32Array.from(inputs.c);
    const n = batch * frames;
    if (!Number.isInteger(batch) || batch < 1 || !Number.isInteger(frames) || frames < 1 || x.length !== n * D || ends.length !== n * E3 || endsPrev.length !== batch * E3 || h.length !== batch * H || c.length !== batch * H) {
      throw new Error(
        `refiner parity inputs do not fit batch ${batch} × ${frames} frames: x ${x.length} (expected ${n * D}), ends ${ends.length} (expected ${n * E3}), ends_prev ${endsPrev.length} (expected ${batch * E3}), h ${h.length} and c ${c.length} (expected ${batch * H})`,
      );
    }
    return this.step(batch, frames, x, ends, endsPrev, h, c);
  }
}
