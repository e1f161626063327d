/// <reference lib="webworker" />
// Runs the latent ERD off the main thread with onnxruntime-web's wasm execution provider (setup and the
// common requests are shared with the other model workers: ortWorker.ts). Two sessions: the ERD step
// (latent-erd.onnx, loaded by init) and the autoencoder's decoder (manifold-decoder.onnx, named by the
// manifold.json that latent-erd.json names; loaded while the model is checked); and the autoencoder's encoder
// (manifold-encoder.onnx), loaded by the first manifold projection: the `manifoldProject` request (latentErdRequests.ts)
// or the `denoise` request of the manifold clean-up (cleanupRequests.ts).
import { loadGeneratorInfo, type GeneratorInfo } from '../../model/generatorInfo';
import { loadLatentErdModel } from '../../model/latentErdInfo';
import { manifoldCleaner } from '../cleanup/cleanup';
import { serveDenoise, type DenoiseParams } from '../cleanup/cleanupRequests';
import { LatentErdCore } from './latentErdCore';
import type { LatentControlStartParams, LatentControlTarget, LatentFollowPathParams, LatentSimulateControlParams, LatentStreamParams } from './latentErdProtocol';
import { LatentErdRequests, type ManifoldProjectParams } from './latentErdRequests';
import { loadExtraSession, ort, serveModel } from '../worker/ortWorker';

// One set of control requests per loaded core (a new init replaces the core, and with it the live stream).
const controls = new WeakMap<LatentErdCore, LatentErdRequests>();

function requestsOf(core: LatentErdCore): LatentErdRequests {
  let requests = controls.get(core);
  if (!requests) controls.set(core, (requests = new LatentErdRequests(core)));
  return requests;
}
/** latent-erd.json's URL of the latest init: generator.json, whose skeleton the clean-up's IK uses, sits next to it. */
let infoUrl = '';
let generatorInfo: Promise<GeneratorInfo> | undefined;

serveModel({
  name: 'latent ERD',
  loadInfo: (url) => {
    infoUrl = url;
    generatorInfo = undefined;
    return loadLatentErdModel(url);
  },
  makeCore: (session, model, threads) =>
    new LatentErdCore(
      session,
      model,
      ort.Tensor,
      threads,
      () => loadExtraSession(model.decoderUrl, 'manifold decoder'),
      model.encoderUrl === undefined ? undefined : () => loadExtraSession(model.encoderUrl!, 'manifold encoder'),
    ),
  streamParams: (r: LatentStreamParams): LatentStreamParams => ({
    seed: r.seed,
    ...(r.gait === undefined ? {} : { gait: r.gait }),
    ...(r.control === undefined ? {} : { control: r.control }),
    ...(r.knownFuture === undefined ? {} : { knownFuture: r.knownFuture }),
    ...(r.footLock === undefined ? {} : { footLock: r.footLock }),
  }),
  requests: {
    denoise: (r: DenoiseParams, core: LatentErdCore, progress, signal) =>
      serveDenoise(r, {
        methods: ['manifold'],
        info: () => {
          generatorInfo ??= loadGeneratorInfo(new URL('generator.json', infoUrl).href);
          generatorInfo.catch(() => (generatorInfo = undefined)); // a failed fetch is tried again next time
          return generatorInfo;
        },
        cleaner: (_options, onProgress) => manifoldCleaner((positions) => core.projectManifold(positions, undefined, signal, onProgress)),
      }, progress, signal),
    followPath: (r: LatentFollowPathParams, core: LatentErdCore, progress, signal) => requestsOf(core).followPath(r, progress, signal),
    controlStart: (r: LatentControlStartParams, core: LatentErdCore, _progress, signal) => requestsOf(core).controlStart(r, signal),
    controlPull: async (r: LatentControlTarget & { frames: number }, core: LatentErdCore) => requestsOf(core).controlPull(r),
    simulateControl: (r: LatentSimulateControlParams, core: LatentErdCore, progress, signal) => requestsOf(core).simulate(r, progress, signal),
    manifoldProject: (r: ManifoldProjectParams, core: LatentErdCore, progress, signal) => requestsOf(core).manifoldProject(r, progress, signal),
  },
});
