// Main-thread handle on a dance model's worker (acLSTM or the vanilla baseline): promise methods
// (ModelClient; requests matched to replies by id: WorkerClient).
import type { Motion } from '../../motion/types';
import type { DanceChunk, DanceInitResult, DanceParityResult, DanceStepInputs, DanceStreamInfo, DanceStreamParams } from './danceProtocol';
import { ModelClient } from '../worker/workerClient';

export type { DanceInitResult, DanceParityResult, DanceStepInputs, DanceStreamInfo, DanceStreamParams };

/** Generated dance frames as a Motion (positions fitted to the skeleton, planted feet locked, with the contacts), with the raw network points. */
export type DanceMotion = Motion & {
  /** frames × joints × 3: the decoded network output before fitting (bone lengths drift). */
  predicted: Float32Array;
  /** frames × D features in physical units. */
  features: Float32Array;
  seedIndex: number;
  /** Index of the first frame within its stream (0 for `generate`). */
  startFrame: number;
};

export interface DanceClientOptions {
  /** Model id: the files are models/<id>.onnx and models/<id>.json (default "aclstm"). */
  model?: string;
  /** Override the file URLs (resolved against the page). */
  modelUrl?: string;
  infoUrl?: string;
  /** onnxruntime-web threads when the page is cross-origin isolated (default 2); without isolation always 1. */
  threads?: number;
  /** Gives up on the worker if `init` has no answer by then. */
  initTimeoutMs?: number;
}

export class DanceClient extends ModelClient<DanceStreamParams, DanceInitResult, DanceChunk, DanceStreamInfo, DanceParityResult, DanceStepInputs, DanceMotion> {
  constructor(options: DanceClientOptions = {}) {
    const model = options.model ?? 'aclstm';
    super(new Worker(new URL('./dance.worker.ts', import.meta.url), { type: 'module', name: 'dance' }), 'dance', {
      threads: options.threads,
      initTimeoutMs: options.initTimeoutMs,
      modelUrl: options.modelUrl ?? `models/${model}.onnx`,
      infoUrl: options.infoUrl ?? `models/${model}.json`,
    });
  }

  /** One raw ONNX step on the given inputs (e.g. tests/fixtures/aclstm_reference.json's `step.inputs`). */
  parity(inputs: DanceStepInputs): Promise<DanceParityResult> {
    return this.parityRequest(inputs);
  }

  protected toMotion(chunk: DanceChunk): DanceMotion {
    return {
      ...this.motionOf(chunk),
      contacts: chunk.contacts,
      predicted: chunk.predicted,
      features: chunk.features,
      seedIndex: chunk.seedIndex,
      startFrame: chunk.startFrame,
    };
  }
}
