/// <reference lib="webworker" />
// Runs a dance model (an acLSTM, or a dropped dance pack) off the main thread with onnxruntime-web's wasm
// execution provider (setup and the requests are shared with the generator worker: ortWorker.ts).
import { DanceCore } from './danceCore';
import { loadDanceInfo } from './danceModel';
import type { DanceStreamParams } from './danceProtocol';
import { ort, serveModel } from '../worker/ortWorker';

serveModel({
  name: 'dance',
  loadInfo: loadDanceInfo,
  makeCore: (session, info, threads) => new DanceCore(session, info, ort.Tensor, threads),
  streamParams: (r: DanceStreamParams): DanceStreamParams => ({ style: r.style, seed: r.seed }),
});
