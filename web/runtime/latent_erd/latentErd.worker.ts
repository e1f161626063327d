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
import type { LatentStreamParams } from './latentErdProtocol';
import { LatentErdRequests } from './latentErdRequests';
import { loadExtraSession, ort, serveModel } from '../worker/ortWorker';

// One set of control requests per loaded core (a new init replaces the core, and with it the live stream).
const requests = new WeakMap<LatentErdCore, LatentErdRequests>();
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
  extra(request, core, progress, signal) {
    const erd = core as LatentErdCore;
    if (request.type === 'denoise') {
      return serveDenoise(request as unknown as DenoiseParams, {
        methods: ['manifold'],
        info: () => {
          generatorInfo ??= loadGeneratorInfo(new URL('generator.json', infoUrl).href);
          generatorInfo.catch(() => (generatorInfo = undefined)); // a failed fetch is tried again next time
          return generatorInfo;
        },
        cleaner: (_options, onProgress) => manifoldCleaner((positions) => erd.projectManifold(positions, undefined, signal, onProgress)),
      }, progress);
    }
    let handler = requests.get(erd);
    if (!handler) requests.set(erd, (handler = new LatentErdRequests(erd)));
    return handler.handle(request as { type: string } & Record<string, unknown>, progress, signal);
  },
});
