/// <reference lib="webworker" />
// Runs the latent ERD off the main thread with onnxruntime-web's wasm execution provider (setup and the
// common requests are shared with the other model workers: ortWorker.ts). Two sessions: the ERD step
// (latent-erd.onnx, loaded by init) and the autoencoder's decoder (manifold-decoder.onnx, named by the
// manifold.json that latent-erd.json names; loaded while the model is checked); and the autoencoder's encoder
// (manifold-encoder.onnx), loaded by the first manifoldProject request (latentErdRequests.ts).
import { loadLatentErdModel } from '../model/latentErdInfo';
import { LatentErdCore } from './latentErdCore';
import type { LatentStreamParams } from './latentErdProtocol';
import { LatentErdRequests } from './latentErdRequests';
import { loadExtraSession, ort, serveModel } from './ortWorker';

// One set of control requests per loaded core (a new init replaces the core, and with it the live stream).
const requests = new WeakMap<LatentErdCore, LatentErdRequests>();

serveModel({
  name: 'latent ERD',
  loadInfo: loadLatentErdModel,
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
    let handler = requests.get(erd);
    if (!handler) requests.set(erd, (handler = new LatentErdRequests(erd)));
    return handler.handle(request as { type: string } & Record<string, unknown>, progress, signal);
  },
});
