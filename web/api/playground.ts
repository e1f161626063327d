// The public automation API, installed as `window.playground`. Documented in docs/api.md: keep the two
// in step. Every method that takes user data checks it, and on bad input throws / rejects with an Error
// whose message says what is wrong, shows the same message on the page, and leaves the scene as it was.

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
import { checkFitSigma, checkFootLock, checkGait, checkSeconds, checkSeed, optional } from '../optimizer/options';
import { describeValue } from '../motion/describe';
import { loadManifest, type ModelInfo } from '../model/manifest';
import { assetUrl } from '../runtime/worker/assetBase';
import { checkControlSignal } from '../model/latentErdInfo';
import { checkPathSpeed, LATENT_PATH_SPEED } from '../runtime/latent_erd/latentErdRequests';
import { checkCleanupOptions, type CleanupMethod, type CleanupStats } from '../runtime/cleanup/cleanup';
import { mapSkeleton } from '../motion/skeletonMap';
import { addNoise as addNoiseTo, checkNoiseOptions, type NoiseOptions } from '../motion/noise';

declare const __APP_VERSION__: string;

/** A model listed in public/models/index.json (the manifest's `file` is internal and not exposed). */
export type { ModelInfo };

export type ImportFormat = 'bvh' | 'amc';

export interface ViewOptions {
  follow?: boolean;
  trail?: boolean;
  footprints?: boolean;
  framing?: 'character' | 'all';
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
  /** A model id from `models()` of kind "lstm-gmm" ("generator"), "aclstm" ("aclstm", "aclstm-vanilla") or "latent-erd" ("latent-erd"). */
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
  /** acLSTM models only, and required there: one of the model's `styles` ("salsa", "indian", "martial"). */
  style?: string;
  /** Generator only. Sampling temperature 0…2 (left out: 0.5; null is refused): 0 = each step's most likely mixture mean, 1 = the trained distribution. */
  temperature?: number;
  /**
   * Generator only (default false). true: the same sampled frames run through the refiner model (loaded on
   * first use) and the foot-contact clean-up; the result is the refined, foot-locked motion with the refined contacts.
   */
  refine?: boolean;
}

/** The models that follow paths and take live control: the generator with the MAP optimiser (default), or the latent ERD. */
export type ControlModel = 'generator' | 'latent-erd';
/** The models that follow paths: those, and the VAE-LSTM (the whole walk in one pass; it takes no live control). */
export type PathModel = ControlModel | 'vae-lstm';

export interface FollowPathOptions extends CancellableOptions {
  /**
   * "generator" (default: the MAP optimiser over the generator), "latent-erd" (closed-loop control, no search)
   * or "vae-lstm" (the path becomes one control signal and the whole walk is made in one pass).
   */
  model?: PathModel;
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
  /** Lock planted feet (the refiner issue's contact clean-up; default true). The root path is not changed. */
  footLock?: boolean;
}

export interface FollowPathStats {
  /** Mean and largest distance from the root (on the ground) to the path over all frames, metres. */
  meanError: number;
  maxError: number;
  /** Share of the path's length the character covered (0…1). */
  arcProgress: number;
  /** Wall-clock milliseconds the optimisation took. */
  optimizeMs: number;
  /** Foot skating (m/s, mean planted-toe speed by the returned contacts) of the motion, and of the motion before the foot lock (by the model's own contact bits). */
  skating: number;
  skatingBeforeLock: number;
  /** Foot sliding (m/s): the lowest foot point's horizontal speed while within 4 cm of the floor (no contacts needed), the same two. */
  sliding: number;
  slidingBeforeLock: number;
}

export type FollowedPathMotion = Motion & { contacts: Uint8Array; stats: FollowPathStats };

export interface SimulateControlOptions extends CancellableOptions {
  /** "generator" (default: the MAP live controller) or "latent-erd" (controlTowardHeading every latent step). */
  model?: ControlModel;
  /** Length of the simulated run, seconds (0 < seconds ≤ 600), rounded to whole frames (at least one). */
  seconds: number;
  /** Targets over time: [{ t: 0, speed, heading }, …] with t in seconds, increasing; speed 0–4 m/s; heading in radians (0 faces +z). */
  schedule: { t: number; speed: number; heading: number }[];
  /** Integer 0…2³²−1 (default 0). */
  seed?: number;
  /** Seed states to start from: "walk", or "run"; default "run" when the first target speed is 2 m/s or more. */
  gait?: 'walk' | 'run';
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

export const GENERATE_DEFAULT_TEMPERATURE = 0.5;
export const GENERATE_MAX_FRAMES = 100_000;

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
  exportBVH(motion: Motion, options?: BVHExportOptions): string;
  /**
   * Binary glTF (GLB) of a motion: a skinned figure bound to a skeleton and one animation (root translation,
   * joint rotations). `options.restPose`: 'tpose' (default) or 'clip'; `options.name` names it.
   */
  exportGLB(motion: Motion, options?: GLBExportOptions): Uint8Array<ArrayBuffer>;
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

type GeneratorCall = { kind: 'lstm-gmm'; model: string; frames: number; seed: number; temperature: number; refine: boolean };
type DanceCall = { kind: 'aclstm'; model: string; frames: number; seed: number; style: string };
type ControlledCall<K> = { kind: K; model: string; frames: number; seed: number; control?: Float64Array };
type LatentCall = ControlledCall<'latent-erd'> | ControlledCall<'vae-lstm'>;

/** Checks generate's options against the model they name (`models`: the manifest); the error says what is wrong. */
export function checkGenerate(options: unknown, models: ModelInfo[]): GeneratorCall | DanceCall | LatentCall {
  if (typeof options !== 'object' || options === null || Array.isArray(options)) {
    throw new TypeError(`options must be an object: { model, frames, seed, temperature? } (acLSTM: { model, style, frames, seed }), got ${describeValue(options)}`);
  }
  const o = options as Partial<Record<keyof GenerateOptions, unknown>>;
  const usable = models.filter((m) => m.kind === 'lstm-gmm' || m.kind === 'aclstm' || m.kind === 'latent-erd' || m.kind === 'vae-lstm');
  const available = usable.map((m) => m.id).join(', ');
  if (typeof o.model !== 'string') throw new TypeError(`model must be a model id string (available: ${available || 'none'}), got ${describeValue(o.model)}`);
  const entry = usable.find((m) => m.id === o.model);
  if (!entry) throw new Error(`unknown model ${describeValue(o.model)} (available: ${available || 'none — the model list did not load'})`);
  const dance = entry.kind === 'aclstm';
  // The latent ERD and the VAE-LSTM take the same options: a seed and an optional control signal.
  const latent = entry.kind === 'latent-erd' || entry.kind === 'vae-lstm';
  if (dance) {
    // Dance models have no sampling and no refiner: say so rather than silently ignoring the option.
    if ('temperature' in o) throw new TypeError(`temperature is not meaningful for acLSTM models: they are deterministic (the seed only picks the seed motion); leave it out`);
    if ('refine' in o) throw new TypeError(`refine is not available for acLSTM models (there is no refiner for dance); leave it out`);
  }
  const known = dance ? ['model', 'style', 'frames', 'seed', 'signal'] : latent ? ['model', 'frames', 'seed', 'control', 'signal'] : ['model', 'frames', 'seed', 'temperature', 'refine', 'signal'];
  for (const k of Object.keys(options)) {
    if (!known.includes(k)) throw new TypeError(`unknown option ${describeValue(k)} for model "${entry.id}" (known: ${known.join(', ')})`);
  }
  if (typeof o.frames !== 'number' || !Number.isInteger(o.frames) || o.frames < 1 || o.frames > GENERATE_MAX_FRAMES) {
    throw new RangeError(`frames must be an integer from 1 to ${GENERATE_MAX_FRAMES}, got ${describeValue(o.frames)}`);
  }
  const seed = checkSeed(o.seed);
  if (latent) {
    const control = o.control === undefined ? undefined : checkControlSignal(o.control, o.frames);
    return { kind: entry.kind as 'latent-erd' | 'vae-lstm', model: entry.id, frames: o.frames, seed, ...(control ? { control } : {}) } as LatentCall;
  }
  if (dance) {
    const styles = entry.styles ?? [];
    if (o.style === undefined) throw new TypeError(`style is required for model "${entry.id}" (styles: ${styles.join(', ')})`);
    if (typeof o.style !== 'string' || !styles.includes(o.style)) {
      throw new RangeError(`unknown style ${describeValue(o.style)} for model "${entry.id}" (styles: ${styles.join(', ')})`);
    }
    return { kind: 'aclstm', model: entry.id, frames: o.frames, seed, style: o.style };
  }
  const temperature = optional(o.temperature, GENERATE_DEFAULT_TEMPERATURE);
  if (typeof temperature !== 'number' || !Number.isFinite(temperature) || temperature < 0 || temperature > 2) {
    throw new RangeError(`temperature must be a number from 0 to 2, got ${describeValue(temperature)}`);
  }
  if (o.refine !== undefined && typeof o.refine !== 'boolean') throw new TypeError(`refine must be true or false, got ${describeValue(o.refine)}`);
  const refine = o.refine === true;
  if (refine && !models.some((m) => m.kind === 'refiner')) throw new Error('refine is not available: no refiner model is listed in models/index.json');
  return { kind: 'lstm-gmm', model: entry.id, frames: o.frames, seed, temperature, refine };
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
  const keys = withName ? ['restPose', 'name'] : ['restPose'];
  return checkKeys(options, keys, `{ restPose?: 'tpose' | 'clip'${withName ? ', name?' : ''} }`) as { restPose?: RestPose; name?: string };
}

/** Throws unless `options` are view options: layer switches true or false, framing "character" or "all". */
function checkView(options: unknown): ViewOptions {
  if (typeof options !== 'object' || options === null) throw new TypeError(`options must be an object, got ${describeValue(options)}`);
  const known = ['follow', 'trail', 'footprints', 'framing'];
  for (const [k, v] of Object.entries(options)) {
    if (!known.includes(k)) throw new TypeError(`unknown option ${describeValue(k)} (known: ${known.join(', ')})`);
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
function checkSignal(options: unknown): AbortSignal | undefined {
  const signal = typeof options === 'object' && options !== null ? (options as { signal?: unknown }).signal : undefined;
  if (signal === undefined) return undefined;
  const s = signal as Partial<AbortSignal> | null;
  if (typeof s !== 'object' || s === null || typeof s.aborted !== 'boolean' || typeof s.addEventListener !== 'function') {
    throw new TypeError(`signal must be an AbortSignal (an AbortController's signal), got ${describeValue(signal)}`);
  }
  return signal as AbortSignal;
}

/**
 * The `model` option of followPath and simulateControl: "generator" when left out, else a listed model of
 * kind "lstm-gmm" or "latent-erd" (`models`: the manifest).
 */
function checkControlModel(value: unknown, models: ModelInfo[], live = true): PathModel {
  if (value === undefined) return 'generator';
  const kinds: Record<PathModel, string> = { generator: 'lstm-gmm', 'latent-erd': 'latent-erd', 'vae-lstm': 'vae-lstm' };
  const usable = models.filter((m) => kinds[m.id as PathModel] === m.kind).map((m) => m.id);
  const available = usable.join(', ') || 'none — the model list did not load';
  if (typeof value !== 'string') {
    throw new TypeError(`model must be ${live ? '"generator" or "latent-erd"' : 'one of "generator", "latent-erd", "vae-lstm"'}, got ${describeValue(value)}`);
  }
  if (live && value === 'vae-lstm') {
    throw new Error('the VAE-LSTM makes the whole motion for a whole control signal and takes no live control: use followPath or generate({ model: "vae-lstm", control })');
  }
  if (!usable.includes(value)) throw new Error(`unknown model ${describeValue(value)} (available: ${available})`);
  return value as PathModel;
}

const FOLLOW_PATH_OPTIONS: Record<PathModel, string[]> = {
  generator: ['model', 'points', 'gait', 'seed', 'fitTolerance', 'footLock', 'signal'],
  'latent-erd': ['model', 'points', 'gait', 'seed', 'speed', 'footLock', 'signal'],
  'vae-lstm': ['model', 'points', 'gait', 'seed', 'speed', 'footLock', 'signal'],
};
const FOLLOW_PATH_SHAPE = '{ points: [[x, z], …], model?, gait?, seed?, fitTolerance? (generator) or speed? (latent-erd, vae-lstm), footLock?, signal? }';
const SIMULATE_OPTIONS = ['model', 'seconds', 'schedule', 'seed', 'gait', 'footLock', 'signal'];

/** A latent ERD or VAE-LSTM motion as a Motion: the fitted, foot-locked positions and the contacts they were locked with. */
async function generateLatent(app: App, o: LatentCall, signal: AbortSignal | undefined): Promise<Motion> {
  const { client } = o.kind === 'vae-lstm' ? await app.vaeLstm.load() : await app.latentErd.load();
  const m = await client.generate({ seed: o.seed, frames: o.frames, ...(o.control ? { control: o.control } : {}) }, { signal });
  return { fps: m.fps, frames: m.frames, joints: [...m.joints], parents: [...m.parents], positions: m.positions, contacts: m.contacts };
}

/** A dance as a Motion: the fitted, foot-locked positions and the contacts they were locked with. */
async function generateDance(app: App, o: DanceCall, signal: AbortSignal | undefined): Promise<Motion> {
  const { client } = await app.dance(o.model).load();
  const m = await client.generate({ style: o.style, seed: o.seed, frames: o.frames }, { signal });
  return { fps: m.fps, frames: m.frames, joints: [...m.joints], parents: [...m.parents], positions: m.positions, contacts: m.contacts };
}

/**
 * How the API's calls fail: `guarded(context, fn)` runs `fn`, and a failure is shown on the page as
 * `context: message` and thrown as an Error with that message (the original as its cause).
 */
function errorGuards(app: App) {
  /** Shows `context: message` on the page and returns an Error with that message (the original as cause). */
  function reported(context: string, e: unknown): Error {
    const message = `${context}: ${errorMessage(e)}`;
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
      const signal = checkSignal(options);
      return unlessAborted(signal, () => fn(signal));
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
    },
    (e) => {
      // The page still works without models; say so rather than failing `ready`.
      app.reportError(`Model list unavailable: ${errorMessage(e)}`);
    },
  );

  const api: Playground = {
    version: __APP_VERSION__,
    ready,
    models: () => models.map((m) => ({ ...m, ...(m.styles ? { styles: [...m.styles] } : {}) })),

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
      return guarded('exportBVH', () => exportBVHText(validateMotion(motion), checkExportOptions(options, false)));
    },
    exportGLB(motion, options) {
      return guarded('exportGLB', () => exportGLBBytes(validateMotion(motion), checkExportOptions(options, true)));
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
        const { framing, ...layers } = checkView(options);
        app.viewer.setLayers(layers);
        if (framing === 'character') app.viewer.frameCharacter();
        if (framing === 'all') app.viewer.frameAll();
        app.panel.syncLayers();
      });
    },
    stats: () => app.viewer.stats(),

    generate(options) {
      return cancellable('generate', options, async (signal) => {
        await ready;
        const o = checkGenerate(options, models);
        if (o.kind === 'aclstm') return generateDance(app, o, signal);
        if (o.kind === 'latent-erd' || o.kind === 'vae-lstm') return generateLatent(app, o, signal);
        const { client } = await app.generator.load();
        const m = await client.generate({ frames: o.frames, seed: o.seed, temperature: o.temperature, ...(o.refine ? { refine: true } : {}) }, { signal });
        const shown = o.refine ? m.refined : m;
        if (!shown) throw new Error('the generator worker returned no refined frames');
        const motion: Motion = { fps: m.fps, frames: m.frames, joints: [...m.joints], parents: [...m.parents], positions: shown.positions, contacts: shown.contacts };
        return motion;
      });
    },

    followPath(options) {
      return cancellable('followPath', options, async (signal) => {
        checkKeys(options, Object.keys(options ?? {}), FOLLOW_PATH_SHAPE); // an object; its keys are checked once the model is known
        await ready;
        const model = checkControlModel((options as { model?: unknown }).model, models, false);
        const o = checkKeys(options, FOLLOW_PATH_OPTIONS[model], FOLLOW_PATH_SHAPE);
        // Checked here too (the worker checks again), so bad input fails fast and without a worker prefix.
        const points = checkPathPoints(o.points);
        GroundPath.fromPoints(points);
        const gait = checkGait(optional(o.gait, 'walk'));
        const seed = checkSeed(optional(o.seed, 0));
        const lockFeet = checkFootLock(o.footLock);
        if (model === 'latent-erd' || model === 'vae-lstm') {
          const speed = checkPathSpeed(optional(o.speed, LATENT_PATH_SPEED[gait]));
          const { client } = model === 'vae-lstm' ? await app.vaeLstm.load() : await app.latentErd.load();
          const m = await client.followPath({ points, gait, seed, speed, footLock: lockFeet }, { signal });
          const { meanError, maxError, arcProgress, optimizeMs, skating, skatingBeforeLock, sliding, slidingBeforeLock } = m.stats;
          return { fps: m.fps, frames: m.frames, joints: [...m.joints], parents: [...m.parents], positions: m.positions, contacts: m.contacts, stats: { meanError, maxError, arcProgress, optimizeMs, skating, skatingBeforeLock, sliding, slidingBeforeLock } };
        }
        const fitSigma = checkFitSigma(optional(o.fitTolerance, 0.1), 'fitTolerance');
        const { client } = await app.generator.load();
        const m = await client.followPath({ points, gait, seed, fitSigma, footLock: lockFeet }, { signal });
        const { meanError, maxError, arcProgress, optimizeMs, skating, skatingBeforeLock, sliding, slidingBeforeLock } = m.stats;
        return { fps: m.fps, frames: m.frames, joints: [...m.joints], parents: [...m.parents], positions: m.positions, contacts: m.contacts, stats: { meanError, maxError, arcProgress, optimizeMs, skating, skatingBeforeLock, sliding, slidingBeforeLock } };
      });
    },

    denoise(motion, options) {
      return cancellable('denoise', options, async (signal) => {
        const input = validateMotion(motion);
        const rest = { ...(options as unknown as Record<string, unknown>) };
        delete rest.signal;
        const o = checkCleanupOptions(typeof options === 'object' && options !== null ? rest : options);
        if (o.method !== 'lowpass') mapSkeleton(input, 1); // an unmappable skeleton fails here, naming its missing joints
        await ready;
        const { client } = o.method === 'manifold' ? await app.latentErd.load() : await app.generator.load();
        const r = await client.denoise({ motion: input, options: o }, { signal });
        return { ...r.motion, stats: r.stats };
      });
    },

    addNoise(motion, options) {
      return guarded('addNoise', () => addNoiseTo(validateMotion(motion), checkNoiseOptions(options)).motion);
    },

    simulateControl(options) {
      return cancellable('simulateControl', options, async (signal) => {
        const o = checkKeys(options, SIMULATE_OPTIONS, '{ seconds, schedule: [{ t, speed, heading }, …], model?, seed?, gait?, footLock?, signal? }');
        const lockFeet = checkFootLock(o.footLock);
        const seconds = checkSeconds(o.seconds);
        const schedule = checkSchedule(o.schedule);
        const seed = checkSeed(optional(o.seed, 0));
        const gait = o.gait === undefined ? undefined : checkGait(o.gait);
        await ready;
        if (checkControlModel(o.model, models) === 'latent-erd') {
          const { client } = await app.latentErd.load();
          const m = await client.simulateControl({ seconds, schedule, seed, footLock: lockFeet, ...(gait ? { gait } : {}) }, { signal });
          return { fps: m.fps, frames: m.frames, joints: [...m.joints], parents: [...m.parents], positions: m.positions, contacts: m.contacts, speed: m.speed, heading: m.heading, computeMs: m.computeMsPerFrame };
        }
        const { client } = await app.generator.load();
        const m = await client.simulateControl({ seconds, schedule, seed, footLock: lockFeet, ...(gait ? { gait } : {}) }, { signal });
        return { fps: m.fps, frames: m.frames, joints: [...m.joints], parents: [...m.parents], positions: m.positions, contacts: m.contacts, speed: m.speed, heading: m.heading, computeMs: m.computeMs };
      });
    },
  };
  return Object.freeze(api);
}
