// Main-thread handle on the latent ERD's worker: promise methods (ModelClient; requests matched to replies
// by id: WorkerClient), and the control requests (followPath, live control, simulateControl).
import type { CleanupResult } from '../cleanup/cleanup';
import type { DenoiseParams } from '../cleanup/cleanupRequests';
import type { Motion } from '../../motion/types';
import type {
  LatentChunk,
  LatentControlChunk,
  LatentControlStartParams,
  LatentControlTarget,
  LatentErdInitResult,
  LatentFollowPathChunk,
  LatentFollowPathParams,
  LatentParityInputs,
  LatentParityResult,
  LatentSimulateControlParams,
  LatentSimulatedControlChunk,
  LatentStreamInfo,
  LatentStreamParams,
} from './latentErdProtocol';
import { ModelClient, modelFiles, type ModelFileOptions, type ProgressOptions, type RequestOptions } from '../worker/workerClient';

export type { LatentErdInitResult, LatentFollowPathParams, LatentParityInputs, LatentParityResult, LatentSimulateControlParams, LatentStreamInfo, LatentStreamParams };

/**
 * Emitted frames as a Motion (fitted, foot-locked positions and the decoded contacts), with the ERD's extras:
 * the decoded points before the fit (`predicted`), the rows, the roots and headings, the control each frame was
 * emitted for, the seed, `startFrame`, and the calls and time it took.
 */
export type LatentMotion = Motion & Omit<LatentChunk, 'frames' | 'positions'>;

export type LatentFollowedPath = LatentMotion & Pick<LatentFollowPathChunk, 'stats' | 'path'>;
export type LatentControlledMotion = LatentMotion & Pick<LatentControlChunk, 'speed' | 'heading'>;
export type LatentSimulatedControl = LatentMotion &
  Pick<LatentSimulatedControlChunk, 'speed' | 'heading' | 'targetSpeed' | 'targetHeading' | 'computeMsPerFrame' | 'batchMs' | 'batchFrames'>;

/** Left out: models/latent-erd.onnx and models/latent-erd.json (which names manifold.json). */
export type LatentErdClientOptions = ModelFileOptions;

export class LatentErdClient extends ModelClient<LatentStreamParams, LatentErdInitResult, LatentChunk, LatentStreamInfo, LatentParityResult, LatentParityInputs, LatentMotion> {
  constructor(options: LatentErdClientOptions = {}) {
    super(new Worker(new URL('./latentErd.worker.ts', import.meta.url), { type: 'module', name: 'latent-erd' }), 'latent-erd', modelFiles('latent-erd', options));
  }

  /** One raw ERD step and/or one decoder call (tests/fixtures/latent_erd_reference.json's `step.inputs` and `decode`). */
  parity(inputs: LatentParityInputs): Promise<LatentParityResult> {
    return this.parityRequest(inputs);
  }

  /** Follows a ground path in closed loop (one control per latent step); `onProgress` hears the share of the path done. */
  /** Motion clean-up with `manifold` (cleanup.ts) in the worker; `onProgress` hears the share done; `signal` cancels it. */
  denoise(params: DenoiseParams, options: ProgressOptions = {}): Promise<CleanupResult> {
    return this.request<CleanupResult>('denoise', { ...params }, options);
  }

  async followPath(params: LatentFollowPathParams, options: ProgressOptions = {}): Promise<LatentFollowedPath> {
    const chunk = await this.request<LatentFollowPathChunk>('followPath', { ...params }, options);
    return { ...this.toMotion(chunk), stats: chunk.stats, path: chunk.path };
  }

  /** Starts (or replaces) the live-control stream at the origin, facing +z. */
  controlStart(params: LatentControlStartParams, options: RequestOptions = {}): Promise<LatentStreamInfo> {
    return this.request<LatentStreamInfo>('controlStart', { ...params }, options);
  }

  /** The live stream's next `frames` frames (1…12), every latent step steered toward `target`. Runs whole once started (as `pull`). */
  async controlPull(frames: number, target: LatentControlTarget, options: RequestOptions = {}): Promise<LatentControlledMotion> {
    const chunk = await this.request<LatentControlChunk>('controlPull', { frames, ...target }, options);
    return { ...this.toMotion(chunk), speed: chunk.speed, heading: chunk.heading };
  }

  /** The live loop driven by a schedule of targets instead of a person. */
  async simulateControl(params: LatentSimulateControlParams, options: ProgressOptions = {}): Promise<LatentSimulatedControl> {
    const c = await this.request<LatentSimulatedControlChunk>('simulateControl', { ...params }, options);
    const { speed, heading, targetSpeed, targetHeading, computeMsPerFrame, batchMs, batchFrames } = c;
    return { ...this.toMotion(c), speed, heading, targetSpeed, targetHeading, computeMsPerFrame, batchMs, batchFrames };
  }

  protected toMotion(chunk: LatentChunk): LatentMotion {
    return this.chunkMotion(chunk);
  }

}
