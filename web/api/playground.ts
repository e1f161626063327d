// The public automation API, installed as `window.playground`. Documented in docs/api.md: keep the two
// in step. Every method that takes user data checks it, and on bad input throws / rejects with an Error
// whose message says what is wrong, shows the same message on the page, and leaves the scene as it was.

import { LOOKS, type Look } from '../viewer/look';
import { exportBVH as exportBVHText, type BVHExportOptions } from '../motion/bvh';
import type { RestPose } from '../motion/restPose';
import { exportGLB as exportGLBBytes, type GLBExportOptions } from '../motion/gltf';
import { validateMotion } from '../motion/io';
import type { Motion } from '../motion/types';
import type { PlaybackState } from '../viewer/playback';
import type { RenderStats } from '../viewer/viewer';
import type { App } from '../ui/app';
import { errorMessage } from '../ui/dom';
import { CancelledError, isCancelled, unlessAborted } from '../runtime/worker/cancellation';
import { checkSchedule } from '../optimizer/liveControl';
import { checkPathPoints, GroundPath } from '../optimizer/path';
import { checkFootLock, checkGait, checkSeconds, checkSeed, optional } from '../optimizer/options';
import { describeValue } from '../motion/describe';
import { capMessage } from '../motion/text';
import { loadManifest, type ModelInfo } from '../model/manifest';
import { assetUrl } from '../runtime/worker/assetBase';
import { checkCleanupMotion, checkCleanupOptions, type CleanupMethod, type CleanupStats } from '../runtime/cleanup/cleanup';
import { checkStyleOption, type Capability, type GenerateCall, type PathStats } from '../runtime/descriptor';
import { Registry, type RegisteredModel } from '../runtime/registry';
import { mapSkeleton } from '../motion/skeletonMap';
import { addNoise as addNoiseTo, checkNoiseOptions, type NoiseOptions } from '../motion/noise';
import type { CharacterInfo, CharacterSource } from '../ui/characterInput';

declare const __APP_VERSION__: string;

/** A model listed in public/models/index.json (the manifest's `file` is internal and not exposed). */
export type { ModelInfo };

export type ImportFormat = 'bvh' | 'amc';

export interface ViewOptions {
  follow?: boolean;
  trail?: boolean;
  footprints?: boolean;
  framing?: 'character' | 'all';
  /** What is drawn: the stick figure ('skeleton'), the mannequin ('character', the default) or both. */
  look?: Look;
}

/** Options of a request that can be cancelled (docs/api.md "Cancelling requests"). */
export interface CancellableOptions {
  /**
   * Cancels the call when it aborts (an AbortController's signal): the call rejects at once with an Error
   * named "AbortError", and the worker stops the work (a model between two model steps; an import before
   * its parse, or at the next chunk of a file being read).
   */
  signal?: AbortSignal;
}

export interface GenerateOptions extends CancellableOptions {
  /** A model id from `models()` that generates: of kind "lstm-gmm" ("generator"), "aclstm" ("aclstm-mdn", "aclstm"), "latent-erd" ("latent-erd") or "vae-lstm" ("vae-lstm"). */
  model: string;
  /** Number of frames, an integer 1…100000. */
  frames: number;
  /**
   * Integer 0…2³²−1. Generator: picks the seed state (seed mod the number of seed states) and seeds the
   * random stream. acLSTM: picks the seed motion, seed mod the number of seed motions of the style. Latent
   * ERD: picks the seed state (seed mod the number of seeds in latent-erd.json) and, without `control`, the
   * random control.
   */
  seed: number;
  /**
   * Latent ERD only: the control signal, one [forward m/s, sideways m/s, turn rad/s] per frame (at least
   * `frames`; further ones are the future the look-ahead sees at the end). Left out: smooth random control
   * drawn from the seed (web/motion/control.ts randomControl).
   */
  control?: [number, number, number][];
  /**
   * One of the model's `styles` (models()): required for the acLSTM models ("salsa", "indian", "martial"); for a
   * style generator (an "lstm-gmm" model with styles, e.g. "elderly") left out means its first style. Refused for a
   * model without styles.
   */
  style?: string;
  /** Generator only. Sampling temperature 0…2 (left out: 0.5; null is refused): 0 = each step's most likely mixture mean, 1 = the trained distribution. */
  temperature?: number;
  /**
   * Generator only (default false). true: the same sampled frames run through the refiner model (loaded on
   * first use) and the foot-contact clean-up; the result is the refined, foot-locked motion with the refined contacts.
   */
  refine?: boolean;
}

export interface FollowPathOptions extends CancellableOptions {
  /**
   * "generator" (default: the MAP optimiser over the generator), "latent-erd" (closed-loop control, no search)
   * or "vae-lstm" (the path becomes one control signal and the whole walk is made in one pass).
   */
  model?: string;
  /** The path on the ground: [x, z] pairs in metres, at least 2, each x and z within ±10000 m, 0.5–200 m long. The character starts at the first point facing along the path. */
  points: [number, number][];
  /** "walk" (default) or "run": picks the seed states and the pace. */
  gait?: 'walk' | 'run';
  /** Integer 0…2³²−1 (default 0): the same seed and path give the same motion. VAE-LSTM: the seed draws z, so another seed is another variation. */
  seed?: number;
  /** Generator only. σ_fit of the path-fit term in metres, 0.02–2 (default 0.1): smaller follows tighter. */
  fitTolerance?: number;
  /** Latent ERD and VAE-LSTM only. The forward speed asked for, above 0 and at most 4 m/s (default 1.2 walking, 2.8 running). */
  speed?: number;
  /** A model with styles (models() lists them): one of them (left out: its first); refused for a model without styles. */
  style?: string;
  /** Lock planted feet (the refiner issue's contact clean-up; default true). The root path is not changed. */
  footLock?: boolean;
}

/** How well a walk follows its path, and its foot skating and sliding (web/runtime/worker/protocol.ts PathStats). */
export type FollowPathStats = PathStats;

export type FollowedPathMotion = Motion & { contacts: Uint8Array; stats: FollowPathStats };

export interface SimulateControlOptions extends CancellableOptions {
  /** "generator" (default: the MAP live controller) or "latent-erd" (controlTowardHeading every latent step). */
  model?: string;
  /** Length of the simulated run, seconds (0 < seconds ≤ 600), rounded to whole frames (at least one). */
  seconds: number;
  /** Targets over time: [{ t: 0, speed, heading }, …] with t in seconds, increasing; speed 0–4 m/s; heading in radians (0 faces +z). */
  schedule: { t: number; speed: number; heading: number }[];
  /** Integer 0…2³²−1 (default 0). */
  seed?: number;
  /** Seed states to start from: "walk", or "run"; default "run" when the first target speed is 2 m/s or more. */
  gait?: 'walk' | 'run';
  /** A model with styles (models() lists them): one of them (left out: its first); refused for a model without styles. */
  style?: string;
  /** Lock planted feet (default true). */
  footLock?: boolean;
}

export type ControlledMotion = Motion & {
  contacts: Uint8Array;
  /** Per frame: achieved speed (m/s, the root's mean horizontal speed over the last 0.5 s) and facing heading (rad, in (−π, π]). */
  speed: Float32Array;
  heading: Float32Array;
  /** Per frame: compute milliseconds of the optimised batch it belongs to, divided by the batch's frames. */
  computeMs: Float32Array;
};

export interface DenoiseOptions extends CancellableOptions {
  /** "map" (MAP under the generator, Wang, Chai, Xia §5.4), "manifold" (the motion autoencoder) or "lowpass" (zero-phase Butterworth). */
  method: CleanupMethod;
  /** map: σ of the root observation, metres (0.001–1); default measured from the motion's own jitter. */
  sigmaRoot?: number;
  /** map: σ of the joint-angle observations, radians (0.001–1.5); default measured per joint from the motion. */
  sigmaAngle?: number;
  /** lowpass: cut-off, Hz (0.5–14; default 6). */
  cutoffHz?: number;
}

/** A cleaned motion: the input's own skeleton (joints, parents, fps, frames; one length per bone), with contacts. */
export type DenoisedMotion = Motion & { contacts: Uint8Array; stats: CleanupStats };

export { GENERATE_DEFAULT_TEMPERATURE } from '../runtime/generator/descriptor';
export const GENERATE_MAX_FRAMES = 100_000;

/** Your own character (docs/api.md "Your own character"). */
export type { CharacterInfo, CharacterSource };

export interface LoadCharacterOptions {
  /** Load it for Compare's second figure only (the side-by-side companion); default false: for both figures. */
  companion?: boolean;
}

export interface RetargetCallOptions {
  /** Keep planted feet planted with two-bone IK on the character's legs (default true). */
  footIK?: boolean;
}

/** exportGLB's options with `character: true`: the loaded character animated (resolves with the bytes). */
export type CharacterGLBExportOptions = { character: true; name?: string };
/** exportBVH's options with `character: true`: the motion on the character's skeleton. */
export type CharacterBVHExportOptions = { character: true };

export interface Playground {
  /** Package version of the page, e.g. "0.1.0". */
  readonly version: string;
  /** Resolves once the page is set up and the model manifest is loaded. */
  readonly ready: Promise<void>;
  /** Models from the manifest (empty until models ship). */
  models(): ModelInfo[];
  /** Parses a BVH, or an AMC with its ASF skeleton text. Does not show it. `signal` cancels it. */
  importMotion(text: string, format: ImportFormat, asfText?: string, options?: CancellableOptions): Promise<Motion>;
  /**
   * BVH text of a motion (centimetres, y up, ZYX Euler channels, Frame Time = 1/fps). `options.restPose`:
   * 'clip' (default, the clip's tallest frame) or 'tpose' (a T-pose facing +z, for retargeting tools).
   */
  exportBVH(motion: Motion, options?: BVHExportOptions | CharacterBVHExportOptions): string;
  /**
   * Binary glTF (GLB) of a motion: a skinned figure bound to a skeleton and one animation (root translation,
   * joint rotations). `options.restPose`: 'tpose' (default) or 'clip'; `options.name` names it.
   */
  exportGLB(motion: Motion, options?: GLBExportOptions & { character?: false }): Uint8Array<ArrayBuffer>;
  /** With `character: true`: the loaded character's mesh, skin and materials with the motion retargeted onto it (a Promise). */
  exportGLB(motion: Motion, options: CharacterGLBExportOptions): Promise<Uint8Array<ArrayBuffer>>;
  /**
   * Loads a rigged humanoid (.glb, self-contained .gltf or .vrm; a URL under the `src` rules, a Blob or bytes) and
   * draws it instead of the mannequin in every mode, retargeted from the shown motion. Rejects with a short reason
   * (no skin, broken, over 32 MiB, not a humanoid), keeping the character and motion shown.
   */
  loadCharacter(source: CharacterSource, options?: LoadCharacterOptions): Promise<CharacterInfo>;
  /**
   * Loads a model pack written by `python -m training.own` (the URL of its .json under the `src` rules, its .onnx
   * beside it; its files as File[], a folder's files or its .zip; or one .zip Blob) and lists it in the Random
   * walk, Path and Steer pickers as the user's. Resolves to its model id (use it as `model` in generate,
   * followPath, simulateControl); a broken or incompatible pack rejects with a short reason and changes nothing.
   */
  loadModels(source: string | readonly File[] | Blob): Promise<string>;
  /** The loaded character (as loadCharacter resolved), or null: the mannequin. */
  character(): CharacterInfo | null;
  /** Back to the project's mannequin. */
  clearCharacter(): void;
  /** The motion retargeted onto the loaded character: its bones' names and parents, world positions per frame (metres). */
  retarget(motion: Motion, options?: RetargetCallOptions): Motion;
  /** Shows a motion in the viewer from its first frame, playing. `name` labels it on the page. */
  show(motion: Motion, name?: string): void;
  play(): void;
  pause(): void;
  /** Moves to a frame (fractional allowed; clamped to the clip). */
  seek(frame: number): void;
  /** Sets the playback speed, clamped to 0.25–2; returns the speed used. */
  setSpeed(x: number): number;
  state(): PlaybackState;
  /** The motion being shown, or null. */
  current(): Motion | null;
  /** The last error message shown on the page, or null. */
  lastError(): string | null;
  /**
   * View options: camera following the root, the trail and footprint layers, and a one-off camera
   * framing ("character": three-quarter view of the figure now; "all": the whole trajectory).
   */
  setView(options: ViewOptions): void;
  /** Rendering diagnostics: display fps, current pixel ratio, quality tier, WebGL renderer. */
  stats(): RenderStats;
  /**
   * A new motion from a generator or dance model (loaded on first use). Same arguments → bit-identical
   * motion. Does not show it (call `show`). `signal` cancels it.
   */
  generate(options: GenerateOptions): Promise<Motion>;
  /**
   * A walk or run along a ground path, optimised with the generator (Wang, Chai, Xia §5.2). Does not
   * show it (call `show`). Resolves with the motion and how well it follows the path. `signal` cancels it.
   */
  followPath(options: FollowPathOptions): Promise<FollowedPathMotion>;
  /**
   * The live steering loop driven by a schedule of speed and heading targets instead of a person (the
   * same code as the Steer mode). Does not show it. `signal` cancels it.
   */
  simulateControl(options: SimulateControlOptions): Promise<ControlledMotion>;
  /**
   * Motion clean-up (docs/models/cleanup.md): the motion cleaned on its own skeleton, with contact labels. A
   * skeleton whose joints cannot be matched to the canonical one rejects with the joints that are missing. Does not
   * show it. `signal` cancels it.
   */
  denoise(motion: Motion, options: DenoiseOptions): Promise<DenoisedMotion>;
  /** Synthetic capture noise for trying clean-up on a clean clip: jitter σ (m), a share of outlier frames, foot drift (m/s); seeded. */
  addNoise(motion: Motion, options: NoiseOptions): Motion;
}

declare global {
  interface Window {
    playground: Playground;
  }
}

/** Checks generate's options against the model they name (`models`: the manifest); the error says what is wrong. */
export function checkGenerate(options: unknown, models: ModelInfo[]): GenerateCall {
  if (typeof options !== 'object' || options === null || Array.isArray(options)) {
    throw new TypeError(`options must be an object: { model, frames, seed, temperature? } (acLSTM: { model, style, frames, seed }), got ${describeValue(options)}`);
  }
  const o = options as Record<string, unknown>;
  const registry = new Registry(models);
  const { info: entry, descriptor } = pickModel(registry, 'generate', o.model, `a model id string (available: ${registry.ids('generate').join(', ') || 'none'})`);
  const generate = descriptor.generate!;
  for (const [key, reason] of Object.entries(generate.refused ?? {})) if (key in o) throw new TypeError(reason);
  const known = [...generate.options, 'signal'];
  for (const k of Object.keys(options)) {
    if (!known.includes(k)) throw new TypeError(`unknown option ${describeValue(k)} for model "${entry.id}" (known: ${known.join(', ')})`);
  }
  if (typeof o.frames !== 'number' || !Number.isInteger(o.frames) || o.frames < 1 || o.frames > GENERATE_MAX_FRAMES) {
    throw new RangeError(`frames must be an integer from 1 to ${GENERATE_MAX_FRAMES}, got ${describeValue(o.frames)}`);
  }
  const seed = checkSeed(o.seed);
  return { kind: entry.kind, model: entry.id, frames: o.frames, seed, ...generate.check(o, entry, models) };
}

/**
 * The model a call names (`value`) among those that can do `capability`: its manifest entry and
 * descriptor. `what` says what a model must be, for the refusal of a non-string.
 */
function pickModel(registry: Registry, capability: Capability, value: unknown, what: string): RegisteredModel {
  const usable = registry.with(capability);
  const available = usable.map((m) => m.info.id).join(', ');
  if (typeof value !== 'string') throw new TypeError(`model must be ${what}, got ${describeValue(value)}`);
  const found = usable.find((m) => m.info.id === value);
  if (!found) {
    const refusal = capability === 'liveControl' ? registry.find(value)?.descriptor.noLiveControl : undefined;
    if (refusal) throw new Error(refusal);
    throw new Error(`unknown model ${describeValue(value)} (available: ${available || 'none — the model list did not load'})`);
  }
  return found;
}

/** Throws unless `options` is a plain object whose keys are all in `known`. */
function checkKeys(options: unknown, known: string[], shape: string): Record<string, unknown> {
  if (typeof options !== 'object' || options === null || Array.isArray(options)) throw new TypeError(`options must be an object: ${shape}, got ${describeValue(options)}`);
  for (const k of Object.keys(options)) {
    if (!known.includes(k)) throw new TypeError(`unknown option ${describeValue(k)} (known: ${known.join(', ')})`);
  }
  return options as Record<string, unknown>;
}

/** Export options (undefined: the defaults); the values themselves are checked by the exporters. */
function checkExportOptions(options: unknown, withName: boolean): { restPose?: RestPose; name?: string } {
  if (options === undefined) return {};
  const keys = withName ? ['restPose', 'name', 'character'] : ['restPose', 'character']; // character: false (onCharacter)
  const { restPose, name } = checkKeys(options, keys, `{ restPose?: 'tpose' | 'clip'${withName ? ', name?' : ''} }`) as { restPose?: RestPose; name?: string };
  return { ...(restPose !== undefined ? { restPose } : {}), ...(name !== undefined ? { name } : {}) };
}

/** Whether export options ask for the loaded character (`character: true`); any other `character` value is refused. */
function onCharacter(options: unknown): boolean {
  if (typeof options !== 'object' || options === null || !('character' in options)) return false;
  const v = (options as { character: unknown }).character;
  if (v === true) return true;
  if (v === false || v === undefined) return false; // the plain export
  throw new TypeError(`character must be true or false, got ${describeValue(v)}`);
}

/** Throws unless `options` are view options: layer switches true or false, framing "character" or "all". */
function checkView(options: unknown): ViewOptions {
  if (typeof options !== 'object' || options === null) throw new TypeError(`options must be an object, got ${describeValue(options)}`);
  const known = ['follow', 'trail', 'footprints', 'framing', 'look'];
  for (const [k, v] of Object.entries(options)) {
    if (!known.includes(k)) throw new TypeError(`unknown option ${describeValue(k)} (known: ${known.join(', ')})`);
    if (k === 'look') {
      if (!(LOOKS as readonly unknown[]).includes(v)) throw new TypeError(`look must be ${LOOKS.map((l) => `"${l}"`).join(', ')}, got ${describeValue(v)}`);
      continue;
    }
    if (k === 'framing' ? v !== 'character' && v !== 'all' : typeof v !== 'boolean') {
      throw new TypeError(`${k === 'framing' ? 'framing must be "character" or "all"' : `${k} must be true or false`}, got ${describeValue(v)}`);
    }
  }
  return options as ViewOptions;
}

/**
 * The `signal` option: undefined when left out, else anything with an AbortSignal's `aborted` and
 * `addEventListener` (so a signal from the page embedding this one in an iframe works too).
 */
/** A call's `signal` option as the call uses it: an AbortSignal of the API's own that follows the one given. */
export interface FollowedSignal {
  /** Undefined when the option was left out; else aborts (with the given signal's reason) when the given one does. */
  signal: AbortSignal | undefined;
  /** Stops following the given signal (called once the call settles); never throws. */
  release(): void;
}

/**
 * The `signal` option: an object with what the API uses of an AbortSignal (`aborted`, `addEventListener`,
 * `removeEventListener`; an AbortController's signal, from this window or another). The call never hands the
 * given object to its workers: it listens to it once, here (a listener that cannot be added is refused), and
 * passes on a signal of its own, so an odd signal-like object (one whose methods throw) cannot leave a call
 * hanging, and removing the listener afterwards is tried once and its failure ignored.
 */
export function checkSignal(options: unknown): FollowedSignal {
  const given = typeof options === 'object' && options !== null ? (options as { signal?: unknown }).signal : undefined;
  if (given === undefined) return { signal: undefined, release: () => undefined };
  const s = given as Partial<AbortSignal> | null;
  if (typeof s !== 'object' || s === null || typeof s.aborted !== 'boolean' || typeof s.addEventListener !== 'function' || typeof s.removeEventListener !== 'function') {
    throw new TypeError(`signal must be an AbortSignal (an AbortController's signal), got ${describeValue(given)}`);
  }
  const own = new AbortController();
  const reason = () => {
    try {
      return s.reason;
    } catch {
      return undefined;
    }
  };
  const onAbort = () => own.abort(reason());
  try {
    s.addEventListener.call(s, 'abort', onAbort, { once: true });
  } catch (e) {
    throw new TypeError(`signal must be an AbortSignal (an AbortController's signal): its addEventListener failed (${errorMessage(e)})`);
  }
  let released = false;
  const release = () => {
    if (released) return;
    released = true;
    try {
      s.removeEventListener!.call(s, 'abort', onAbort);
    } catch {
      // an odd signal's failure to forget the listener costs nothing: the listener only aborts our own signal
    }
  };
  if (s.aborted) own.abort(reason());
  return { signal: own.signal, release };
}

/**
 * The `model` option of followPath (`capability` "followPath") and simulateControl ("liveControl"): the
 * default model for it when left out, else a listed model that can do it.
 */
function controlModel(registry: Registry, capability: 'followPath' | 'liveControl', value: unknown): RegisteredModel {
  const fallback = registry.defaultFor(capability);
  if (value === undefined && fallback) return fallback;
  const ids = registry.ids(capability).map((id) => `"${id}"`);
  const what = ids.length === 0 ? 'a listed model id (none is listed)' : ids.length === 1 ? ids[0] : ids.length === 2 ? ids.join(' or ') : `one of ${ids.join(', ')}`;
  return pickModel(registry, capability, value, what);
}

/** followPath's options every model takes; each model adds its own (its descriptor's followPath.options). */
const FOLLOW_PATH_COMMON = ['model', 'points', 'gait', 'seed', 'style', 'footLock', 'signal'];
const FOLLOW_PATH_SHAPE = '{ points: [[x, z], …], model?, gait?, seed?, style? (a model with styles), fitTolerance? (generator) or speed? (latent-erd, vae-lstm), footLock?, signal? }';
const SIMULATE_OPTIONS = ['model', 'seconds', 'schedule', 'seed', 'gait', 'style', 'footLock', 'signal'];

/**
 * How the API's calls fail: `guarded(context, fn)` runs `fn`, and a failure is shown on the page as
 * `context: message` and thrown as an Error with that message (the original as its cause).
 */
function errorGuards(app: App) {
  /** Shows `context: message` on the page and returns an Error with that message (the original as cause). */
  function reported(context: string, e: unknown): Error {
    const message = capMessage(`${context}: ${errorMessage(e)}`); // as the page shows it (lastError())
    app.reportError(message);
    const err = new Error(message, { cause: e });
    if (e instanceof Error) err.name = e.name;
    return err;
  }

  /** Runs `fn`; on failure reports it on the page and throws with the context. */
  function guarded<T>(context: string, fn: () => T): T {
    try {
      return fn();
    } catch (e) {
      throw reported(context, e);
    }
  }

  /** Like `guarded` for promises; a cancelled call rejects with `context: cancelled` (an AbortError), not shown on the page. */
  async function guardedAsync<T>(context: string, fn: () => Promise<T>): Promise<T> {
    try {
      return await fn();
    } catch (e) {
      if (isCancelled(e)) throw new CancelledError(`${context}: cancelled`, { cause: e });
      throw reported(context, e);
    }
  }

  /** Like `guardedAsync` for a call with a `signal` option (checked first): `fn` gets it, and the call rejects as soon as it aborts. */
  function cancellable<T>(context: string, options: unknown, fn: (signal: AbortSignal | undefined) => Promise<T>): Promise<T> {
    return guardedAsync(context, () => {
      const { signal, release } = checkSignal(options);
      return unlessAborted(signal, () => fn(signal)).finally(release);
    });
  }

  return { guarded, guardedAsync, cancellable };
}

export function createPlayground(app: App): Playground {
  let models: ModelInfo[] = [];
  const { guarded, guardedAsync, cancellable } = errorGuards(app);

  const ready = loadManifest(assetUrl('models/index.json')).then(
    (m) => {
      models = m;
      app.useModels(m);
    },
    (e) => {
      // The page still works without models (clips, import, export, low-pass clean-up need none); say so rather
      // than failing `ready`, and let the modes waiting for the list go on with none.
      app.reportError(`Model list unavailable: ${errorMessage(e)}`);
      app.useModels([]);
    },
  );

  const api: Playground = {
    version: __APP_VERSION__,
    ready,
    models: () => [...models, ...app.packModels().map(({ files: _blobs, ...pack }) => pack)].map((m) => ({ ...m, ...(m.styles ? { styles: [...m.styles] } : {}) })),

    importMotion(text, format, asfText, options) {
      return cancellable('importMotion', options, async (signal) => {
        if (options !== undefined) checkKeys(options, ['signal'], '{ signal? }');
        if (typeof text !== 'string') throw new TypeError(`text must be a string, got ${describeValue(text)}`);
        if (format !== 'bvh' && format !== 'amc') throw new TypeError(`format must be "bvh" or "amc", got ${describeValue(format)}`);
        if (format === 'amc' && typeof asfText !== 'string') throw new TypeError('an AMC motion needs its skeleton: pass the ASF file text as asfText');
        return app.importer.importText(text, format, format === 'amc' ? asfText : undefined, { signal }); // parsed in the import worker
      });
    },

    exportBVH(motion, options) {
      return guarded('exportBVH', () => {
        if (onCharacter(options)) {
          checkKeys(options, ['character'], '{ character: true }');
          return app.characters.exportBVH(validateMotion(motion));
        }
        return exportBVHText(validateMotion(motion), checkExportOptions(options, false));
      });
    },
    exportGLB: ((motion: Motion, options?: GLBExportOptions | CharacterGLBExportOptions) => {
      if (onCharacter(options)) {
        return guardedAsync('exportGLB', async () => {
          const { name } = checkKeys(options, ['character', 'name'], '{ character: true, name? }') as { name?: unknown };
          if (name !== undefined && typeof name !== 'string') throw new TypeError(`name must be a string, got ${describeValue(name)}`);
          return app.characters.exportGLB(validateMotion(motion), name ?? 'motion');
        });
      }
      return guarded('exportGLB', () => exportGLBBytes(validateMotion(motion), checkExportOptions(options, true)));
    }) as Playground['exportGLB'],

    loadCharacter(source, options) {
      return guardedAsync('loadCharacter', async () => {
        const o = options === undefined ? {} : checkKeys(options, ['companion'], '{ companion? }');
        if (o.companion !== undefined && typeof o.companion !== 'boolean') throw new TypeError(`companion must be true or false, got ${describeValue(o.companion)}`);
        return app.loadCharacter(source, o.companion === true);
      });
    },
    loadModels(source) {
      return guardedAsync('loadModels', () => app.loadModels(source));
    },
    character: () => app.characters.info,
    clearCharacter: () => app.clearCharacter(),
    retarget(motion, options) {
      return guarded('retarget', () => {
        const o = options === undefined ? {} : checkKeys(options, ['footIK'], '{ footIK? }');
        if (o.footIK !== undefined && typeof o.footIK !== 'boolean') throw new TypeError(`footIK must be true or false, got ${describeValue(o.footIK)}`);
        return app.characters.retarget(validateMotion(motion), o as RetargetCallOptions).motion;
      });
    },

    show(motion, name = 'motion') {
      guarded('show', () => {
        if (typeof name !== 'string') throw new TypeError('name must be a string');
        app.show(validateMotion(motion), name);
      });
    },

    play: () => app.viewer.play(),
    pause: () => app.viewer.pause(),
    seek(frame) {
      guarded('seek', () => {
        if (typeof frame !== 'number' || !Number.isFinite(frame)) throw new TypeError(`frame must be a finite number, got ${describeValue(frame)}`);
        app.viewer.seek(frame);
      });
    },
    setSpeed(x) {
      return guarded('setSpeed', () => {
        if (typeof x !== 'number' || !Number.isFinite(x) || x <= 0) throw new TypeError(`speed must be a positive number, got ${describeValue(x)}`);
        return app.viewer.setSpeed(x);
      });
    },
    state: () => app.viewer.state(),
    current: () => app.current,
    lastError: () => app.lastError,
    setView(options) {
      guarded('setView', () => {
        const { framing, look, ...layers } = checkView(options);
        app.viewer.setLayers(layers);
        if (look !== undefined) {
          app.viewer.setLook(look);
          app.panel.syncLayers();
          app.panel.announceLook(); // links and the element's attributes follow
        }
        if (framing === 'character') app.viewer.frameCharacter();
        if (framing === 'all') app.viewer.frameAll();
        app.panel.syncLayers();
      });
    },
    stats: () => app.viewer.stats(),

    generate(options) {
      return cancellable('generate', options, async (signal) => {
        await ready;
        const call = checkGenerate(options, [...models, ...app.packModels()]);
        return app.withModel(call.model, (client, descriptor) => descriptor.generate!.run(client, call, { signal }));
      });
    },

    followPath(options) {
      return cancellable('followPath', options, async (signal) => {
        checkKeys(options, Object.keys(options ?? {}), FOLLOW_PATH_SHAPE); // an object; its keys are checked once the model is known
        await ready;
        const { info, descriptor } = controlModel(app.registry, 'followPath', (options as { model?: unknown }).model);
        const follow = descriptor.followPath!;
        // style: refused with its reason for a model without styles, and known only to a model with them.
        const style = checkStyleOption((options as { style?: unknown }).style, info);
        const common = info.styles?.length ? FOLLOW_PATH_COMMON : FOLLOW_PATH_COMMON.filter((k) => k !== 'style');
        const o = checkKeys(options, [...common.slice(0, common.indexOf('footLock')), ...follow.options, ...common.slice(common.indexOf('footLock'))], FOLLOW_PATH_SHAPE);
        // Checked here too (the worker checks again), so bad input fails fast and without a worker prefix.
        const points = checkPathPoints(o.points);
        GroundPath.fromPoints(points);
        const gait = checkGait(optional(o.gait, 'walk'));
        const seed = checkSeed(optional(o.seed, 0));
        const footLock = checkFootLock(o.footLock);
        const own = follow.check(o, gait);
        const walk = await app.withModel(info.id, (client) => follow.run(client, { points, gait, seed, ...own, footLock, ...(style ? { style } : {}) }, { signal }));
        return { ...walk.motion, stats: walk.stats };
      });
    },

    denoise(motion, options) {
      return cancellable('denoise', options, async (signal) => {
        const input = validateMotion(motion);
        const rest = { ...(options as unknown as Record<string, unknown>) };
        delete rest.signal;
        const o = checkCleanupOptions(typeof options === 'object' && options !== null ? rest : options);
        checkCleanupMotion(input); // a frame rate or length clean-up cannot handle is refused here, before any worker
        if (o.method !== 'lowpass') mapSkeleton(input, 1); // an unmappable skeleton fails here, naming its missing joints
        await ready;
        const cleaner = app.registry.with('cleanup').find((m) => m.descriptor.cleanup!.methods.includes(o.method));
        if (!cleaner) throw new Error(`no model that cleans up with "${o.method}" is listed in models/index.json`);
        const r = await app.withModel(cleaner.info.id, (client, descriptor) => descriptor.cleanup!.run(client, { motion: input, options: o }, { signal }));
        return { ...r.motion, stats: r.stats };
      });
    },

    addNoise(motion, options) {
      return guarded('addNoise', () => addNoiseTo(validateMotion(motion), checkNoiseOptions(options)).motion);
    },

    simulateControl(options) {
      return cancellable('simulateControl', options, async (signal) => {
        const o = checkKeys(options, SIMULATE_OPTIONS, '{ seconds, schedule: [{ t, speed, heading }, …], model?, seed?, gait?, style? (a model with styles), footLock?, signal? }');
        const lockFeet = checkFootLock(o.footLock);
        const seconds = checkSeconds(o.seconds);
        const schedule = checkSchedule(o.schedule);
        const seed = checkSeed(optional(o.seed, 0));
        const gait = o.gait === undefined ? undefined : checkGait(o.gait);
        await ready;
        const { info, descriptor } = controlModel(app.registry, 'liveControl', o.model);
        const style = checkStyleOption(o.style, info);
        return app.withModel(info.id, (client) => descriptor.liveControl!.simulate(client, { seconds, schedule, seed, footLock: lockFeet, ...(gait ? { gait } : {}), ...(style ? { style } : {}) }, { signal }));
      });
    },
  };
  return Object.freeze(api);
}
