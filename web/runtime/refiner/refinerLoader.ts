/// <reference lib="webworker" />
// Loading the refiner inside the generator worker, the first time a `refine` stream asks for it: its JSON
// and ONNX file come from next to the generator's (models/refiner.json, the ONNX file named in it), and its
// session runs on the worker's onnxruntime-web (ortWorker.ts), beside the generator's.
import type { GeneratorInfo } from '../../model/generatorInfo';
import { describe, loadExtraSession, ort } from '../worker/ortWorker';
import { RefinerCore } from './refinerCore';
import { checkRefinerPairing, loadRefinerInfo } from './refinerModel';

/** The refiner described by `infoUrl`, checked against the loaded generator and with one step run. */
export async function loadRefiner(infoUrl: string, generator: GeneratorInfo, threads: number): Promise<RefinerCore> {
  const info = await loadRefinerInfo(infoUrl);
  checkRefinerPairing(info, generator, infoUrl);
  const modelUrl = new URL(info.file, infoUrl).href;
  const session = await loadExtraSession(modelUrl, 'refiner model');
  try {
    const core = new RefinerCore(session, info, generator, ort.Tensor, threads);
    await core.check();
    return core;
  } catch (err) {
    await session.release();
    throw new Error(`${modelUrl} with ${infoUrl}: ${describe(err)}`);
  }
}
