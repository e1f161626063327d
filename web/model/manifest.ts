// The model manifest (public/models/index.json, written by training/onnx/manifest.py): the models the page
// can run. Every error names the file, and for a bad entry its index and model file.
import { describeValue } from '../motion/describe';
import { quoteInput } from '../motion/text';
import { loadModelInfo, ModelInfoError } from './modelInfo';

/** A model listed in the manifest (its `file` is internal and not exposed). */
export interface ModelInfo {
  id: string;
  kind: string;
  skeleton: string;
  fps: number;
  styles?: string[];
  bytes: number;
  /** A model not from the manifest (a user's pack, runtime/packs/): its files' URLs instead of models/<id>.*. */
  files?: { model: string; info: string };
  /** The pickers' label of such a model. */
  label?: string;
  /** What it learnt from, and that data's terms (training/onnx/manifest.py TRAINED_ON); shown by the pickers. */
  data?: string;
  licence?: string;
  /** False for a model trained on non-commercial data (the Bandai Namco set): labelled so wherever it is offered. */
  commercial?: boolean;
}

export class ManifestError extends ModelInfoError {
  override readonly name = 'ManifestError';
}

/** Checks a parsed manifest; throws a ManifestError naming `source` and the first bad entry. */
export function parseManifest(raw: unknown, source = 'models/index.json'): ModelInfo[] {
  const fail = (message: string): never => {
    throw new ManifestError(source, message);
  };
  const models = typeof raw === 'object' && raw !== null ? (raw as { models?: unknown }).models : undefined;
  if (!Array.isArray(models)) return fail(`expected { "models": [...] }, got ${describeValue(raw)}`);
  return models.map((m: Record<string, unknown> | null, i) => {
    const entry = `entry ${i}${typeof m?.file === 'string' ? ` (${quoteInput(m.file)})` : ''}`;
    if (typeof m !== 'object' || m === null) return fail(`${entry} must be an object, got ${describeValue(m)}`);
    const { id, kind, skeleton, fps, bytes, styles, data, licence, commercial } = m;
    if (typeof id !== 'string' || typeof kind !== 'string' || typeof skeleton !== 'string' || typeof fps !== 'number' || typeof bytes !== 'number') {
      return fail(`${entry} needs id, kind, skeleton (strings), fps and bytes (numbers)`);
    }
    if (!(fps > 0 && Number.isFinite(fps))) fail(`${entry}: fps must be a positive number, got ${describeValue(fps)}`);
    if (styles !== undefined && !(Array.isArray(styles) && styles.every((s) => typeof s === 'string'))) {
      fail(`${entry}: styles must be an array of strings, got ${describeValue(styles)}`);
    }
    for (const [name, value] of [['data', data], ['licence', licence]] as const) {
      if (value !== undefined && typeof value !== 'string') fail(`${entry}: ${name} must be a string, got ${describeValue(value)}`);
    }
    if (commercial !== undefined && typeof commercial !== 'boolean') fail(`${entry}: commercial must be true or false, got ${describeValue(commercial)}`);
    const info: ModelInfo = { id, kind, skeleton, fps, bytes };
    if (styles) info.styles = [...(styles as string[])];
    if (typeof data === 'string') info.data = data;
    if (typeof licence === 'string') info.licence = licence;
    if (typeof commercial === 'boolean') info.commercial = commercial;
    return info;
  });
}

/** Fetches and checks the manifest at `url` (not from the HTTP cache: it changes with every export). */
export function loadManifest(url: string): Promise<ModelInfo[]> {
  return loadModelInfo(url, parseManifest, ManifestError, { cache: 'no-cache' });
}
