// Main-thread handle on the generator worker: promise methods (ModelClient; requests matched to
// replies by id: WorkerClient).
import type { CleanupResult } from '../cleanup/cleanup';
import type { DenoiseParams } from '../cleanup/cleanupRequests';
import type { StepInputs } from '../../model/generatorInfo';
import type { Motion } from '../../motion/types';
import type { ControlChunkReply, ControlStartParams, ControlTargetParams, FollowPathChunk, FollowPathParams, GeneratedChunk, GenerateParams, InitResult, ParityResult, RefinedFrames, RefinerParityResult, RefinerStepInputs, SimulateControlParams, SimulatedControlChunk, StreamInfo, StreamParams } from './protocol';
import type { BenchmarkResult } from '../worker/protocol';
import { sharedDownload } from '../worker/sharedDownloads';
import { ModelClient, modelFiles, type ModelFileOptions, type ProgressOptions, type RequestOptions } from '../worker/workerClient';

export type {
  BenchmarkResult,
  ControlStartParams,
  ControlTargetParams,
  FollowPathParams,
  GenerateParams,
  InitResult,
  ParityResult,
  RefinedFrames,
  RefinerParityResult,
  RefinerStepInputs,
  SimulateControlParams,
  StepInputs,
  StreamInfo,
  StreamParams,
};

/** A followed path: the motion, the path as followed (x, z pairs) and how well it was followed. */
export type FollowedPath = GeneratedMotion & Pick<FollowPathChunk, 'stats' | 'path'>;
/** A live-control batch: the motion plus achieved speed and heading per frame. */
export type ControlledMotion = GeneratedMotion & Pick<ControlChunkReply, 'speed' | 'heading' | 'computeMs'>;
export type SimulatedControl = GeneratedMotion &
  Pick<SimulatedControlChunk, 'speed' | 'heading' | 'targetSpeed' | 'targetHeading' | 'computeMs' | 'batchMs' | 'batchFrames'>;

/**
 * Generated frames as a Motion (the raw frames, with their contacts), with the chunk's extras: the feature rows,
 * headings, seed, `startFrame`, and with `refine` the same frames refined and foot-locked (`refined`).
 */
export type GeneratedMotion = Motion & Omit<GeneratedChunk, 'frames' | 'positions'>;

/** Left out: models/generator.onnx and models/generator.json. */
export type GeneratorClientOptions = ModelFileOptions;

export class GeneratorClient extends ModelClient<StreamParams, InitResult, GeneratedChunk, StreamInfo, ParityResult, StepInputs, GeneratedMotion> {
  constructor(options: GeneratorClientOptions = {}) {
    super(new Worker(new URL('./generator.worker.ts', import.meta.url), { type: 'module', name: 'generator' }), 'generator', modelFiles('generator', options));
  }

  /** Also the refiner's ONNX file (named in refiner.json beside the generator's JSON), for the first refined stream. */
  protected override prefetch(): void {
    super.prefetch();
    if (!URL.canParse('refiner.json', this.urls.infoUrl)) return; // a pack's blob: URL has no refiner beside it
    const refinerInfo = new URL('refiner.json', this.urls.infoUrl).href;
    fetch(refinerInfo)
      .then((r) => (r.ok ? (r.json() as Promise<{ file?: unknown }>) : null))
      .then((info) => {
        if (typeof info?.file === 'string') sharedDownload(new URL(info.file, refinerInfo).href).catch(() => undefined);
      })
      .catch(() => undefined);
  }

  /**
   * One raw ONNX step. Without inputs it uses the first and last seed states at batch 2, the inputs of
   * tests/fixtures/generator_reference.json's `step`.
   */
  parity(inputs?: StepInputs): Promise<ParityResult> {
    return this.parityRequest(inputs);
  }

  /**
   * One raw refiner step (the refiner is loaded in the worker on first use) and, with `frames` (physical
   * generator frames, frames × D), their root-frame end effectors: the inputs of tests/fixtures/refiner_reference.json.
   */
  refinerParity(inputs: RefinerStepInputs, frames?: ArrayLike<number>): Promise<RefinerParityResult> {
    return this.request<RefinerParityResult>('refinerParity', { inputs, ...(frames ? { frames: Array.from(frames) } : {}) });
  }

  /**
   * Follows a ground path (optimised in the worker); `onProgress` hears the share of the path done;
   * cancelled with `signal` (the optimiser stops at its next model step).
   */
  async followPath(params: FollowPathParams, options: ProgressOptions = {}): Promise<FollowedPath> {
    const chunk = await this.request<FollowPathChunk>('followPath', { ...params }, options);
    return { ...this.toMotion(chunk), stats: chunk.stats, path: chunk.path };
  }

  /**
   * A style generator's endless stream switches to `style` (one of InitResult.styles) from its next frame, blended over
   * about a second (GeneratorCore.switchStreamStyle): frames already pulled are unchanged. A `restart` starts in it.
   */
  switchStyle(style: string, options: RequestOptions = {}): Promise<StreamInfo> {
    return this.request<StreamInfo>('streamStyle', { style }, options);
  }

  /** The live-control stream switches to `style` from its next frame, blended over about a second (as switchStyle). */
  controlStyle(style: string, options: RequestOptions = {}): Promise<StreamInfo> {
    return this.request<StreamInfo>('controlStyle', { style }, options);
  }

  /** Starts (or replaces) the live-control stream at the origin, facing +z. */
  controlStart(params: ControlStartParams, options: RequestOptions = {}): Promise<StreamInfo> {
    return this.request<StreamInfo>('controlStart', { ...params }, options);
  }

  /**
   * The control stream's next `frames` frames (1…12), optimised toward `target`. Cancelled with `signal`
   * while queued it never runs; once running it runs whole (as `pull`).
   */
  async controlPull(frames: number, target: ControlTargetParams, options: RequestOptions = {}): Promise<ControlledMotion> {
    const chunk = await this.request<ControlChunkReply>('controlPull', { frames, ...target }, options);
    return { ...this.toMotion(chunk), speed: chunk.speed, heading: chunk.heading, computeMs: chunk.computeMs };
  }

  /** The live-control loop driven by a schedule instead of a person; cancelled with `signal` (as followPath). */
  async simulateControl(params: SimulateControlParams, options: ProgressOptions = {}): Promise<SimulatedControl> {
    const c = await this.request<SimulatedControlChunk>('simulateControl', { ...params }, options);
    const { speed, heading, targetSpeed, targetHeading, computeMs, batchMs, batchFrames } = c;
    return { ...this.toMotion(c), speed, heading, targetSpeed, targetHeading, computeMs, batchMs, batchFrames };
  }

  /** Motion clean-up with `map` or `lowpass` (cleanup.ts) in the worker; `onProgress` hears the share done; `signal` cancels it. */
  denoise(params: DenoiseParams, options: ProgressOptions = {}): Promise<CleanupResult> {
    return this.request<CleanupResult>('denoise', { ...params }, options);
  }

  protected toMotion(chunk: GeneratedChunk): GeneratedMotion {
    return this.chunkMotion(chunk);
  }

}
