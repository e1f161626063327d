// Main-thread handle on the generator worker: promise methods (ModelClient; requests matched to
// replies by id: WorkerClient).
import type { Motion } from '../motion/types';
import type { BenchmarkResult, GeneratedChunk, GenerateParams, InitResult, ParityResult, StepInputs, StreamInfo, StreamParams } from './protocol';
import { ModelClient } from './workerClient';

export type { BenchmarkResult, GenerateParams, InitResult, ParityResult, StepInputs, StreamInfo, StreamParams };

/** Generated frames as a Motion, with the generator's extras. */
export type GeneratedMotion = Motion & {
  contacts: Uint8Array;
  /** frames × D feature rows in physical units. */
  features: Float32Array;
  rootHeading: Float32Array;
  seedIndex: number;
  /** Index of the first frame within its stream (0 for `generate`). */
  startFrame: number;
};

export interface GeneratorClientOptions {
  /** Defaults resolve against the page: models/generator.onnx and models/generator.json. */
  modelUrl?: string;
  infoUrl?: string;
  /** onnxruntime-web threads when the page is cross-origin isolated (default 2); without isolation always 1. */
  threads?: number;
  /** Gives up on the worker (rejecting `init` and later calls) if `init` has no answer by then: a stalled download or wasm. */
  initTimeoutMs?: number;
}

export class GeneratorClient extends ModelClient<StreamParams, InitResult, GeneratedChunk, StreamInfo, ParityResult, StepInputs, GeneratedMotion> {
  constructor(options: GeneratorClientOptions = {}) {
    super(new Worker(new URL('./generator.worker.ts', import.meta.url), { type: 'module', name: 'generator' }), 'generator', {
      ...options,
      modelUrl: options.modelUrl ?? 'models/generator.onnx',
      infoUrl: options.infoUrl ?? 'models/generator.json',
    });
  }

  /**
   * One raw ONNX step. Without inputs it uses the first and last seed states at batch 2, the inputs of
   * tests/fixtures/generator_reference.json's `step`.
   */
  parity(inputs?: StepInputs): Promise<ParityResult> {
    return this.parityRequest(inputs);
  }

  protected toMotion(chunk: GeneratedChunk): GeneratedMotion {
    return {
      ...this.motionOf(chunk),
      contacts: chunk.contacts,
      features: chunk.features,
      rootHeading: chunk.rootHeading,
      seedIndex: chunk.seedIndex,
      startFrame: chunk.startFrame,
    };
  }
}
