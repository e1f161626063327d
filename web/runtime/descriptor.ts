// What the page knows of one kind of model, in one place: what it can do, its options and their checks
// (used by the API, the UI and the worker's own checks alike), how to start its worker's client, and how
// that client's output becomes a Motion. Each model folder (web/runtime/<model>/descriptor.ts, mirroring
// training/<model>/) exports one `descriptor`; the registry (registry.ts) joins them with the models that
// public/models/index.json lists, and the API, the page and the modes iterate over it instead of naming models.

import { describeValue } from '../motion/describe';
import type { Motion } from '../motion/types';
import type { ModelInfo } from '../model/manifest';
import type { Gait } from '../optimizer/pathFollower';
import type { CleanupMethod, CleanupResult } from './cleanup/cleanup';
import type { DenoiseParams } from './cleanup/cleanupRequests';
import type { FollowPathRequest, PathStats } from './worker/protocol';
import type { ModelFileOptions, ModelSkeleton, ProgressOptions, RequestOptions } from './worker/workerClient';

export type { PathStats };

/**
 * What a model can do, and so where the page offers it:
 * - generate: `playground.generate`;
 * - walk: Random walk's endless stream (with refine: the refiner behind it);
 * - dance: Dance mode's endless stream, in one of its styles;
 * - followPath: `playground.followPath` and Path mode;
 * - liveControl: `playground.simulateControl` and Steer mode;
 * - cleanup: `playground.denoise` and Clip mode's Clean up, with the methods it runs.
 */
export type Capability = 'generate' | 'walk' | 'dance' | 'followPath' | 'liveControl' | 'cleanup';

/** Any model's main-thread client: loads its worker's model, and stops the worker. */
export interface ModelClientBase {
  init(): Promise<ModelSkeleton>;
  dispose(): void;
}

/** generate's checked options: the common ones and the model's own (`kind`: the model's kind). */
export interface GenerateCall {
  kind: string;
  model: string;
  frames: number;
  seed: number;
  [option: string]: unknown;
}

/**
 * A path to walk, checked (optimizer/path.ts), with the model's own option (fitSigma or speed) added by its check,
 * and for a model with styles its style (checked by checkStyleOption; left out: the model's first).
 */
export interface PathRequest extends FollowPathRequest {
  fitSigma?: number;
  speed?: number;
  style?: string;
}

/** One model's walk along a path: the motion (foot-locked, with its contacts), the path as followed, its numbers. */
export interface PathWalk {
  motion: Motion & { contacts: Uint8Array };
  /** The path as followed, x and z pairs. */
  path: Float32Array;
  stats: PathStats;
}

/** The live loop's targets: speed (m/s) and heading (rad), and for a searching controller its particle budget. */
export interface LiveTarget {
  speed: number;
  heading: number;
  particles?: number;
}

/** A batch of live control: frames with their achieved speed and heading, and the time they took. */
export type LiveControlChunk = Motion & { contacts?: Uint8Array; startFrame: number; speed: Float32Array; heading: Float32Array; computeMs: number };

/** simulateControl's result (docs/api.md ControlledMotion). */
export type SimulatedControl = Motion & { contacts: Uint8Array; speed: Float32Array; heading: Float32Array; computeMs: Float32Array };

export interface SimulateRequest {
  seconds: number;
  schedule: { t: number; speed: number; heading: number }[];
  seed: number;
  footLock?: boolean;
  gait?: Gait;
  /** A model with styles: one of them (left out: its first). */
  style?: string;
}

/**
 * A model kind's description. `C` is its client; methods take the client the registry made with
 * `createClient` (method syntax, so a registry of several kinds holds them all).
 */
export interface ModelDescriptor<C extends ModelClientBase = ModelClientBase> {
  /** The `kind` of public/models/index.json entries this describes. */
  kind: string;
  /** Lower-case name in titles and stats lines ("latent ERD"). */
  shortName: string;
  /** The picker's label of each model (by id); a model not named here is listed by its id. */
  labels?: Record<string, string>;
  capabilities: readonly Capability[];
  /** The model's client (a worker of its own), for the manifest entry. `threads`: onnxruntime-web threads. */
  createClient(entry: ModelInfo, threads: number): C;

  /** generate's options, when it has the capability. */
  generate?: {
    /** Every option name but signal, in the order a refusal lists them (model, frames and seed among them). */
    options: readonly string[];
    /** Options refused with a reason before anything else is checked (e.g. temperature for a deterministic model). */
    refused?: Record<string, string>;
    /** Checks the model's own options (the common ones are checked already); returns them, checked. `models`: the manifest. */
    check(options: Record<string, unknown>, entry: ModelInfo, models: readonly ModelInfo[]): Record<string, unknown>;
    /** Runs a checked call. */
    run(client: C, call: GenerateCall, options: RequestOptions): Promise<Motion>;
  };

  /** followPath and Path mode, when it has the capability. */
  followPath?: {
    /** Option names besides points, model, gait, seed, footLock and signal. */
    options: readonly string[];
    /** Checks the API's options the model reads (its `options`) for `gait`, returned as PathRequest fields. */
    check(options: Record<string, unknown>, gait: Gait): Pick<PathRequest, 'fitSigma' | 'speed'>;
    run(client: C, request: PathRequest, options: ProgressOptions): Promise<PathWalk>;
    /** The speed asked for when none is given, per gait (models whose `options` include speed; Path mode's slider). */
    defaultSpeed?: Record<Gait, number>;
    /** A path walked quickly enough to start as soon as it is drawn (no Go needed). */
    immediate?: boolean;
    /** Draws a new sample of the same path with the next seed (Path mode's Vary). */
    varies?: boolean;
    /** What Path mode's progress line says while it works, for `gait`. */
    working(gait: Gait): string;
    /** A limit the stats line states for a walk of `seconds` at `gait`, or null. */
    limit?(gait: Gait, seconds: number): string | null;
  };

  /** simulateControl and Steer mode, when it has the capability. */
  liveControl?: {
    /** Frames per pull and frames kept ready beyond the playhead (left out: the mode's own). */
    chunk?: number;
    ahead?: number;
    /** The controller searches with particles: Steer adapts their number to the time a batch takes. */
    particles: boolean;
    /** `style`: a model with styles only (its manifest entry lists them). */
    start(client: C, params: { seed: number; gait: Gait; style?: string }, options: RequestOptions): Promise<{ seedName: string }>;
    /** A model with styles: the running stream switches to `style` from its next frame, blended over about a second. */
    switchStyle?(client: C, style: string, options: RequestOptions): Promise<unknown>;
    pull(client: C, frames: number, target: LiveTarget, options: RequestOptions): Promise<LiveControlChunk>;
    simulate(client: C, request: SimulateRequest, options: ProgressOptions): Promise<SimulatedControl>;
  };
  /** Why the model takes no live control, for a model that has none but could be mistaken for one. */
  noLiveControl?: string;

  /** denoise and Clean up, when it has the capability: the methods it runs, and what loading it is called. */
  cleanup?: {
    methods: readonly CleanupMethod[];
    /** "loading the <loading>…" while it loads. */
    loading: string;
    run(client: C, params: DenoiseParams, options: ProgressOptions): Promise<CleanupResult>;
  };
}

/** A listed model's client options: its files (models/<id>.onnx and models/<id>.json beside the page, or a pack's own), and its threads. */
export function clientFiles(entry: ModelInfo, threads: number): ModelFileOptions {
  if (entry.files) return { threads, modelUrl: entry.files.model, infoUrl: entry.files.info };
  return { threads, modelUrl: `models/${entry.id}.onnx`, infoUrl: `models/${entry.id}.json` };
}

/**
 * A call's `style` for the model `entry` (generate, followPath, simulateControl, the view's style): undefined when
 * left out; refused with a short reason for a model without styles, and for a name that is not one of its styles.
 */
export function checkStyleOption(value: unknown, entry: ModelInfo): string | undefined {
  if (value === undefined) return undefined;
  const styles = entry.styles ?? [];
  if (styles.length === 0) throw new TypeError(`style is not an option of model "${entry.id}": it has no styles; leave it out`);
  if (typeof value !== 'string' || !styles.includes(value)) throw new RangeError(`unknown style ${describeValue(value)} for model "${entry.id}" (styles: ${styles.join(', ')})`);
  return value;
}

/** The public stats of a walk (a worker's stats carry more). */
export function pathStatsOf(s: PathStats): PathStats {
  const { meanError, maxError, arcProgress, optimizeMs, skating, skatingBeforeLock, sliding, slidingBeforeLock } = s;
  return { meanError, maxError, arcProgress, optimizeMs, skating, skatingBeforeLock, sliding, slidingBeforeLock };
}

/** A model's output as a plain Motion with its contacts: the skeleton copied, the frames shared. */
export function motionOf(m: Motion, positions = m.positions, contacts = m.contacts): Motion & { contacts: Uint8Array } {
  if (!contacts) throw new Error('the model returned no contacts');
  return { fps: m.fps, frames: m.frames, joints: [...m.joints], parents: [...m.parents], positions, contacts };
}
