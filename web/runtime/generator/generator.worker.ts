/// <reference lib="webworker" />
// Runs the locomotion generator off the main thread with onnxruntime-web's wasm execution provider
// (setup and the requests are shared with the other model workers: ortWorker.ts). The refiner runs in the
// same worker, in a second session loaded the first time a stream asks for `refine`.
import { GeneratorCore } from './generatorCore';
import { loadGeneratorInfo } from '../../model/generatorInfo';
import { ort, serveModel } from '../worker/ortWorker';
import { OptimizerRequests } from './optimizerRequests';
import type { RefinerParityResult, RefinerStepInputs, StreamParams } from './protocol';
import { loadRefiner } from '../refiner/refinerLoader';
import { mapCleaner } from '../cleanup/cleanup';
import { serveDenoise, type DenoiseParams } from '../cleanup/cleanupRequests';

// One optimiser per loaded core (a new init replaces the core, and with it the live control stream).
const optimizers = new WeakMap<GeneratorCore, OptimizerRequests>();
/** The generator JSON's URL of the latest init: the refiner's files sit next to it. */
let generatorInfoUrl = '';

serveModel({
  name: 'generator',
  loadInfo: (url) => {
    generatorInfoUrl = url;
    return loadGeneratorInfo(url);
  },
  makeCore: (session, info, threads) => {
    const refinerInfoUrl = new URL('refiner.json', generatorInfoUrl).href;
    return new GeneratorCore(session, info, ort.Tensor, threads, { loadRefiner: (core) => loadRefiner(refinerInfoUrl, core.info, threads) });
  },
  streamParams: (r: StreamParams): StreamParams => ({ seed: r.seed, temperature: r.temperature, seedIndex: r.seedIndex, ...(r.refine === undefined ? {} : { refine: r.refine }) }),
  extra(request, core, progress, signal) {
    const generator = core as GeneratorCore;
    if (request.type === 'refinerParity') return refinerParity(generator, request as unknown as { inputs: RefinerStepInputs; frames?: number[] });
    if (request.type === 'denoise') {
      return serveDenoise(request as unknown as DenoiseParams, {
        methods: ['map', 'lowpass'],
        info: () => Promise.resolve(generator.info),
        cleaner: (options, onProgress) => mapCleaner({ step: (b, x, h, c) => generator.step(b, x, h, c, signal), info: generator.info, mean: generator.mean, std: generator.std, options, onProgress }),
      }, progress);
    }
    let optimizer = optimizers.get(generator);
    if (!optimizer) optimizers.set(generator, (optimizer = new OptimizerRequests(generator)));
    return optimizer.handle(request as { type: string } & Record<string, unknown>, progress, signal);
  },
});

/** One raw refiner step on given inputs and, for given physical generator frames, their end effectors. */
async function refinerParity(generator: GeneratorCore, request: { inputs: RefinerStepInputs; frames?: number[] }): Promise<RefinerParityResult> {
  const refiner = await generator.refiner();
  const outputs = await refiner.parity(request.inputs);
  return request.frames ? { outputs, ends: refiner.endEffectors(Float32Array.from(request.frames)) } : { outputs };
}
