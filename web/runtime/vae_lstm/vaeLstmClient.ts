// Main-thread handle on the VAE-LSTM's worker: promise methods (ModelClient; requests matched to replies by
// id: WorkerClient), and followPath.
import type { Motion } from '../../motion/types';
import type {
  VaeLstmChunk,
  VaeLstmFollowPathChunk,
  VaeLstmFollowPathParams,
  VaeLstmGenerateParams,
  VaeLstmInitResult,
  VaeLstmParityInputs,
  VaeLstmParityResult,
} from './vaeLstmProtocol';
import { ModelClient, modelFiles, type ModelFileOptions, type ProgressOptions } from '../worker/workerClient';

export type { VaeLstmFollowPathParams, VaeLstmGenerateParams, VaeLstmInitResult, VaeLstmParityInputs, VaeLstmParityResult };

/** A generated motion (fitted, foot-locked positions and the contacts they were locked with), with the model's extras. */
export type VaeLstmMotion = Motion & Omit<VaeLstmChunk, 'frames' | 'positions'>;
export type VaeLstmFollowedPath = VaeLstmMotion & Pick<VaeLstmFollowPathChunk, 'stats' | 'path'>;

/** Left out: models/vae-lstm.onnx and models/vae-lstm.json (which names the other graphs). */
export type VaeLstmClientOptions = ModelFileOptions;

type GenerateParams = Omit<VaeLstmGenerateParams, 'frames'>;

export class VaeLstmClient extends ModelClient<GenerateParams, VaeLstmInitResult, VaeLstmChunk, never, VaeLstmParityResult, VaeLstmParityInputs, VaeLstmMotion> {
  constructor(options: VaeLstmClientOptions = {}) {
    super(new Worker(new URL('./vaeLstm.worker.ts', import.meta.url), { type: 'module', name: 'vae-lstm' }), 'vae-lstm', modelFiles('vae-lstm', options));
  }

  /** Raw graph calls and/or a whole generation from z1 (tests/fixtures/vae_lstm_reference.json). */
  parity(inputs: VaeLstmParityInputs): Promise<VaeLstmParityResult> {
    return this.parityRequest(inputs);
  }

  /** The motion for a whole ground path in one go; `onProgress` hears the share done. */
  async followPath(params: VaeLstmFollowPathParams, options: ProgressOptions = {}): Promise<VaeLstmFollowedPath> {
    const chunk = await this.request<VaeLstmFollowPathChunk>('followPath', { ...params }, options);
    return { ...this.toMotion(chunk), stats: chunk.stats, path: chunk.path };
  }

  protected toMotion(chunk: VaeLstmChunk): VaeLstmMotion {
    return this.chunkMotion(chunk);
  }
}
