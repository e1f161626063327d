/// <reference lib="webworker" />
// Runs the locomotion generator off the main thread with onnxruntime-web's wasm execution provider
// (setup and the requests are shared with the other model workers: ortWorker.ts).
import { GeneratorCore } from './generatorCore';
import { loadGeneratorInfo } from './generatorModel';
import { ort, serveModel } from './ortWorker';
import { OptimizerRequests } from './optimizerRequests';
import type { StreamParams } from './protocol';

// One optimiser per loaded core (a new init replaces the core, and with it the live control stream).
const optimizers = new WeakMap<GeneratorCore, OptimizerRequests>();

serveModel({
  name: 'generator',
  loadInfo: loadGeneratorInfo,
  makeCore: (session, info, threads) => new GeneratorCore(session, info, ort.Tensor, threads),
  streamParams: (r: StreamParams): StreamParams => ({ seed: r.seed, temperature: r.temperature, seedIndex: r.seedIndex }),
  extra(request, core, progress) {
    const generator = core as GeneratorCore;
    let optimizer = optimizers.get(generator);
    if (!optimizer) optimizers.set(generator, (optimizer = new OptimizerRequests(generator)));
    return optimizer.handle(request as { type: string } & Record<string, unknown>, progress);
  },
});
