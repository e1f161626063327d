/// <reference lib="webworker" />
// Runs the locomotion generator off the main thread with onnxruntime-web's wasm execution provider
// (setup and the requests are shared with the other model workers: ortWorker.ts). The refiner runs in the
// same worker, in a second session loaded the first time a stream asks for `refine`.
import { GeneratorCore, type GeneratorStream } from './generatorCore';
import { loadGeneratorInfo } from '../../model/generatorInfo';
import { ort, serveModel } from '../worker/ortWorker';
import { OptimizerRequests } from './optimizerRequests';
import type { ControlStartParams, ControlTargetParams, FollowPathParams, RefinerParityResult, RefinerStepInputs, SimulateControlParams, StreamParams } from './protocol';
import { loadRefiner } from '../refiner/refinerLoader';
import { mapCleaner } from '../cleanup/cleanup';
import { serveDenoise, type DenoiseParams } from '../cleanup/cleanupRequests';

// One optimiser per loaded core (a new init replaces the core, and with it the live control stream).
const optimizers = new WeakMap<GeneratorCore, OptimizerRequests>();

function optimizerOf(core: GeneratorCore): OptimizerRequests {
  let optimizer = optimizers.get(core);
  if (!optimizer) optimizers.set(core, (optimizer = new OptimizerRequests(core)));
  return optimizer;
}

/** The generator JSON's URL of the latest init: the refiner's files sit next to it. */
let generatorInfoUrl = '';

serveModel({
  name: 'generator',
  loadInfo: (url) => {
    generatorInfoUrl = url;
    return loadGeneratorInfo(url);
  },
  makeCore: (session, info, threads) => {
    // A user's pack (blob: URLs) has no refiner beside it: refine is refused when asked.
    const refinerInfoUrl = URL.canParse('refiner.json', generatorInfoUrl) ? new URL('refiner.json', generatorInfoUrl).href : null;
    const loadPackRefiner = () => Promise.reject(new Error("refine is not available for your own model (a pack has no refiner)"));
    // The refiner beside a style generator learnt from the CMU-only generator's output. One trained on the style model's
    // output made it no harder to tell from capture, so none is shipped (issue 39; docs/models/style-generator.md).
    if (info.styles) return new GeneratorCore(session, info, ort.Tensor, threads, { loadRefiner: () => Promise.reject(new Error(`refine is not available for the style generator "${info.id}" (no refiner for it is shipped)`)) });
    return new GeneratorCore(session, info, ort.Tensor, threads, { loadRefiner: (core) => (refinerInfoUrl ? loadRefiner(refinerInfoUrl, core.info, threads) : loadPackRefiner()) });
  },
  streamParams: (r: StreamParams): StreamParams => ({ seed: r.seed, temperature: r.temperature, seedIndex: r.seedIndex, ...(r.refine === undefined ? {} : { refine: r.refine }), ...(r.style === undefined ? {} : { style: r.style }) }),
  requests: {
    refinerParity: (r: { inputs: RefinerStepInputs; frames?: number[] }, core: GeneratorCore) => refinerParity(core, r),
    denoise: (r: DenoiseParams, core: GeneratorCore, progress, signal) =>
      serveDenoise(r, {
        methods: ['map', 'lowpass'],
        info: () => Promise.resolve(core.info),
        cleaner: (options, onProgress) => mapCleaner({ step: (b, x, h, c) => core.step(b, x, h, c, signal), info: core.info, mean: core.mean, std: core.std, options, onProgress, signal }),
      }, progress, signal),
    followPath: (r: FollowPathParams, core: GeneratorCore, progress, signal) => optimizerOf(core).followPath(r, progress, signal),
    // A style switch of the endless stream, ramped over a second from its next frame (GeneratorCore.switchStreamStyle);
    // a restart starts again in the new style.
    streamStyle: async (r: { style: string }, core: GeneratorCore, _progress, _signal, stream) => {
      if (!stream) throw new Error('no stream: send startStream first');
      core.switchStreamStyle(stream.value as GeneratorStream, r.style);
      stream.params = { ...(stream.params as StreamParams), style: r.style };
      return core.streamInfo(stream.value as GeneratorStream);
    },
    controlStart: async (r: ControlStartParams, core: GeneratorCore) => optimizerOf(core).controlStart(r),
    controlStyle: async (r: { style: string }, core: GeneratorCore) => optimizerOf(core).controlStyle(r.style),
    controlPull: (r: ControlTargetParams & { frames: number }, core: GeneratorCore) => optimizerOf(core).controlPull(r),
    simulateControl: (r: SimulateControlParams, core: GeneratorCore, progress, signal) => optimizerOf(core).simulate(r, progress, signal),
  },
});

/** One raw refiner step on given inputs and, for given physical generator frames, their end effectors. */
async function refinerParity(generator: GeneratorCore, request: { inputs: RefinerStepInputs; frames?: number[] }): Promise<RefinerParityResult> {
  const refiner = await generator.refiner();
  const outputs = await refiner.parity(request.inputs);
  return request.frames ? { outputs, ends: refiner.endEffectors(Float32Array.from(request.frames)) } : { outputs };
}
