/// <reference lib="webworker" />
// Loading the refiner inside the generator worker, the first time a `refine` stream asks for it: its JSON
// and ONNX file come from next to the generator's (models/refiner.json, the ONNX file named in it), and its
// session runs on the worker's onnxruntime-web (ortWorker.ts), beside the generator's.
import type { GeneratorInfo } from './generatorModel';
import { describe, ort } from './ortWorker';
import { RefinerCore } from './refinerCore';
import { checkRefinerPairing, loadRefinerInfo } from './refinerModel';

async function fetchModel(url: string): Promise<Uint8Array> {
  let response: Response;
  try {
    response = await fetch(url);
  } catch (err) {
    throw new Error(`refiner model ${url}: could not fetch (${describe(err)})`);
  }
  if (!response.ok) throw new Error(`refiner model ${url}: HTTP ${response.status} ${response.statusText}`);
  if (response.headers.get('content-type')?.includes('text/html')) throw new Error(`refiner model ${url}: got an HTML page, not a model file (wrong URL?)`);
  return new Uint8Array(await response.arrayBuffer());
}

/** The refiner described by `infoUrl`, checked against the loaded generator and with one step run. */
export async function loadRefiner(infoUrl: string, generator: GeneratorInfo, threads: number): Promise<RefinerCore> {
  const info = await loadRefinerInfo(infoUrl);
  checkRefinerPairing(info, generator, infoUrl);
  const modelUrl = new URL(info.file, infoUrl).href;
  const bytes = await fetchModel(modelUrl);
  let session: ort.InferenceSession;
  try {
    session = await ort.InferenceSession.create(bytes, { executionProviders: ['wasm'], graphOptimizationLevel: 'all' });
  } catch (err) {
    throw new Error(`could not create an onnxruntime-web session for ${modelUrl}: ${describe(err)}`);
  }
  try {
    const core = new RefinerCore(session, info, generator, ort.Tensor, threads);
    await core.check();
    return core;
  } catch (err) {
    await session.release();
    throw new Error(`${modelUrl} with ${infoUrl}: ${describe(err)}`);
  }
}
