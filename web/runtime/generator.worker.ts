/// <reference lib="webworker" />
// Runs the locomotion generator off the main thread with onnxruntime-web's wasm execution provider
// (setup and the requests are shared with the other model workers: ortWorker.ts).
import { GeneratorCore } from './generatorCore';
import { loadGeneratorInfo } from './generatorModel';
import { ort, serveModel } from './ortWorker';
import type { StreamParams } from './protocol';

serveModel({
  name: 'generator',
  loadInfo: loadGeneratorInfo,
  makeCore: (session, info, threads) => new GeneratorCore(session, info, ort.Tensor, threads),
  streamParams: (r: StreamParams): StreamParams => ({ seed: r.seed, temperature: r.temperature, seedIndex: r.seedIndex }),
});
