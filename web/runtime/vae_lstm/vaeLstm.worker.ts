/// <reference lib="webworker" />
// Runs the VAE-LSTM off the main thread with onnxruntime-web's wasm execution provider (setup and the common
// requests are shared with the other model workers: ortWorker.ts). Four sessions: the cell (vae-lstm.onnx,
// loaded by init) and the control encoder, decoder and inference network (named by vae-lstm.json, loaded
// while the model is checked). It serves generate, followPath, benchmark and parity; it has no stream.
import { loadVaeLstmModel } from '../../model/vaeLstmInfo';
import { loadExtraSession, ort, serveModel } from '../worker/ortWorker';
import { VaeLstmCore } from './vaeLstmCore';
import type { VaeLstmFollowPathParams, VaeLstmGenerateParams } from './vaeLstmProtocol';
import { followPathVae } from './vaeLstmRequests';

serveModel({
  name: 'VAE-LSTM',
  loadInfo: loadVaeLstmModel,
  makeCore: (session, model, threads) => new VaeLstmStreamless(session, model, ort.Tensor, threads, (graph, url) => loadExtraSession(url, `VAE-LSTM ${graph} graph`)),
  streamParams: (r: VaeLstmGenerateParams): VaeLstmGenerateParams => ({
    frames: r.frames,
    seed: r.seed,
    ...(r.control === undefined ? {} : { control: r.control }),
    ...(r.footLock === undefined ? {} : { footLock: r.footLock }),
  }),
  requests: {
    followPath: (r: VaeLstmFollowPathParams, core: VaeLstmStreamless, progress, signal) => followPathVae(core, r, progress, signal),
  },
});

/** The core with the stream requests every model worker has, answered with what the VAE-LSTM does instead. */
class VaeLstmStreamless extends VaeLstmCore {
  createStream(): never {
    throw new Error('the VAE-LSTM makes whole motions for a whole control signal: use generate or followPath, not a stream');
  }

  streamInfo(): never {
    return this.createStream();
  }

  advance(): never {
    return this.createStream();
  }
}
