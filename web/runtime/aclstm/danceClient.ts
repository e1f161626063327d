// Main-thread handle on a dance model's worker (an acLSTM, or a dropped dance pack): promise methods
// (ModelClient; requests matched to replies by id: WorkerClient).
import type { Motion } from '../../motion/types';
import type { DanceChunk, DanceInitResult, DanceParityResult, DanceStepInputs, DanceStreamInfo, DanceStreamParams } from './danceProtocol';
import { ModelClient, modelFiles, type ModelFileOptions } from '../worker/workerClient';

export type { DanceInitResult, DanceParityResult, DanceStepInputs, DanceStreamInfo, DanceStreamParams };

/**
 * Generated dance frames as a Motion (positions fitted to the skeleton, planted feet locked, with the contacts),
 * with the chunk's extras: the raw network points (`predicted`), the features, the seed motion and `startFrame`.
 */
export type DanceMotion = Motion & Omit<DanceChunk, 'frames' | 'positions'>;

/** `model`: the model id, whose files are models/<id>.onnx and models/<id>.json (default "aclstm"). */
export type DanceClientOptions = ModelFileOptions & { model?: string };

export class DanceClient extends ModelClient<DanceStreamParams, DanceInitResult, DanceChunk, DanceStreamInfo, DanceParityResult, DanceStepInputs, DanceMotion> {
  constructor(options: DanceClientOptions = {}) {
    super(new Worker(new URL('./dance.worker.ts', import.meta.url), { type: 'module', name: 'dance' }), 'dance', modelFiles(options.model ?? 'aclstm', options));
  }

  /** One raw ONNX step on the given inputs (e.g. tests/fixtures/aclstm_reference.json's `step.inputs`). */
  parity(inputs: DanceStepInputs): Promise<DanceParityResult> {
    return this.parityRequest(inputs);
  }

  protected toMotion(chunk: DanceChunk): DanceMotion {
    return this.chunkMotion(chunk);
  }
}
