// The latent ERD worker's control requests: following a ground path in closed loop, live control by speed
// and heading (one live stream at a time: Steer mode), and its scripted twin simulateControl. There is no
// search: every latent step (4 frames) the control signal comes straight from where the stream's root
// stands now (web/motion/control.ts), so drift is corrected as it happens:
//   - path: controlAlongPath(path, root.x, root.z, root.heading, progress, speed) (pure pursuit);
//   - speed and heading: controlTowardHeading(root.heading, target heading, target speed);
// repeated for the step's 4 frames (the look-ahead repeats it too: the future is not known). The result
// keeps the generator's return shapes and stats (optimizerRequests.ts), measured the same way.
// Also `manifoldProject`: canonical motion projected through the autoencoder (the `manifold` clean-up,
// manifoldProjection.ts).
import { controlAlongPath, controlTowardHeading, PolylinePath, type Control } from '../../motion/control';
import { plantFeet } from '../../motion/footLock';
import { footStats } from '../../motion/footSkating';
import { checkSchedule, checkTarget, SPEED_WINDOW, type ControlTarget } from '../../optimizer/liveControl';
import { checkFollowRequest, checkFootLock, checkGait, checkSeconds, checkSeed, optional } from '../../optimizer/options';
import { angleDifference, moveBack } from '../../optimizer/path';
import { pathErrors, type Gait } from '../../optimizer/pathFollower';
import { describeValue } from '../../motion/describe';
import type { LatentErdCore, LatentErdStream } from './latentErdCore';
import type { ManifoldProjection } from '../autoencoder/manifoldProjection';
import type {
  LatentChunk,
  LatentControlChunk,
  LatentControlStartParams,
  LatentControlTarget,
  LatentFollowPathChunk,
  LatentFollowPathParams,
  LatentSimulateControlParams,
  LatentSimulatedControlChunk,
  LatentStreamInfo,
} from './latentErdProtocol';

/** Forward speed the path follower asks for by default, per gait (m/s). */
export const LATENT_PATH_SPEED: Record<Gait, number> = { walk: 1.2, run: 2.8 };
/** The largest speed a path may be followed at (m/s), as a control target (liveControl.ts MAX_CONTROL_SPEED). */
export const MAX_LATENT_PATH_SPEED = 4;
/** A follower whose control has been zero (arrived) for this long (s) stops. */
export const ARRIVED_SECONDS = 1;
/** Frames a live pull may ask for. */
export const MAX_LIVE_FRAMES = 12;

/** A `manifoldProject` request: canonical world positions (frames × joints × 3) at the model's fps, optional contacts (frames × 2). */
export interface ManifoldProjectParams {
  positions: Float32Array;
  contacts?: Uint8Array;
}

export function checkPathSpeed(speed: unknown): number {
  if (typeof speed !== 'number' || !(speed > 0 && speed <= MAX_LATENT_PATH_SPEED)) throw new RangeError(`speed must be a number above 0 and at most ${MAX_LATENT_PATH_SPEED} m/s, got ${describeValue(speed)}`);
  return speed;
}

/** The control of one frame repeated for a latent step's frames. */
function repeated(control: Control, frames: number): Float64Array {
  const out = new Float64Array(frames * 3);
  for (let t = 0; t < frames; t++) out.set(control, t * 3);
  return out;
}

/** Achieved speed: the root's (joint 0's) mean horizontal speed over the last SPEED_WINDOW frames, as liveControl.ts measures it. */
class SpeedMeter {
  private readonly recent: [number, number][] = [];

  constructor(private readonly fps: number) {}

  push(x: number, z: number): number {
    this.recent.push([x, z]);
    if (this.recent.length > SPEED_WINDOW + 1) this.recent.shift();
    const first = this.recent[0];
    const span = this.recent.length - 1;
    return span ? (Math.hypot(x - first[0], z - first[1]) * this.fps) / span : 0;
  }
}

export class LatentErdRequests {
  private live: { stream: LatentErdStream; meter: SpeedMeter } | undefined;

  constructor(private readonly core: LatentErdCore) {}

  /** The `manifold` clean-up of canonical positions (frames × joints × 3 at the model's fps) and optional contacts (frames × 2). */
  manifoldProject(p: ManifoldProjectParams, progress: (fraction: number) => void, signal?: AbortSignal): Promise<ManifoldProjection> {
    if (!(p.positions instanceof Float32Array)) throw new TypeError(`positions must be a Float32Array of frames × joints × 3 values, got ${describeValue(p.positions)}`);
    if (p.contacts !== undefined && !(p.contacts instanceof Uint8Array)) throw new TypeError(`contacts must be a Uint8Array of frames × 2 bits, got ${describeValue(p.contacts)}`);
    return this.core.projectManifold(p.positions, p.contacts, signal, progress);
  }

  async followPath(p: LatentFollowPathParams, progress: (fraction: number) => void, signal?: AbortSignal): Promise<LatentFollowPathChunk> {
    const started = performance.now();
    // Followed, locked and measured near the origin; moved back to where the path is last (as the generator's).
    const { gait, seed, lock, origin, ground } = checkFollowRequest(p);
    const speed = checkPathSpeed(optional(p.speed, LATENT_PATH_SPEED[gait]));
    const core = this.core;
    const { fps, pooling } = core.layout;
    const path = new PolylinePath(ground.points());
    const s = await core.createStream({ seed, gait, footLock: false }, signal, { root: { x: ground.xs[0], z: ground.zs[0], heading: ground.headingAt(0) } });
    // As the generator's follower: 2.5× the time the pace needs, and 2 s, before giving up.
    const maxFrames = Math.ceil(((path.length / speed) * 2.5 + 2) * fps);
    const arrivedSteps = Math.ceil((ARRIVED_SECONDS * fps) / pooling);
    let arc = 0, still = 0, frames = 0;
    while (frames < maxFrames && still < arrivedSteps) {
      const root = s.stream.root;
      const next = controlAlongPath(path, root.x, root.z, root.heading, arc, speed);
      arc = next.progress;
      still = next.control.every((v) => v === 0) ? still + 1 : 0;
      await core.emit(s, repeated(next.control, pooling), undefined, signal);
      frames += pooling;
      progress(Math.min(1, arc / path.length));
    }
    progress(1);
    const chunk = core.take(s, core.pendingFrames(s));
    const { joints, offsets } = core.skeleton;
    const fitted = { positions: chunk.positions, contacts: chunk.contacts };
    const shown = lock ? plantFeet(fitted.positions, fitted.contacts, joints, offsets, fps) : fitted;
    const stats = {
      ...pathErrors(ground, shown.positions, joints.length, chunk.frames),
      optimizeMs: performance.now() - started,
      windows: s.stream.steps,
      particleSteps: s.stream.erdCalls,
      ...footStats({ fps, skeleton: core.skeleton }, chunk.frames, shown, fitted),
    };
    chunk.positions = moveBack(shown.positions, origin);
    chunk.contacts = shown.contacts;
    moveBack(chunk.predicted, origin);
    moveRootsBack(chunk, origin);
    chunk.computeMs = stats.optimizeMs;
    return { ...chunk, stats, path: ground.flatAt(origin) };
  }

  async controlStart(p: LatentControlStartParams, signal?: AbortSignal): Promise<LatentStreamInfo> {
    this.live = undefined;
    const stream = await this.core.createStream({ seed: checkSeed(p.seed), gait: checkGait(p.gait) }, signal);
    this.live = { stream, meter: new SpeedMeter(this.core.fps) };
    return this.core.streamInfo(stream);
  }

  /** The live stream's next `frames` frames (1…12), each latent step steered toward `target` from where the root stands. Runs whole once started. */
  async controlPull(p: LatentControlTarget & { frames: number }): Promise<LatentControlChunk> {
    const live = this.live;
    if (!live) throw new Error('no control stream: send controlStart first');
    const frames = p.frames;
    if (!Number.isInteger(frames) || frames < 1 || frames > MAX_LIVE_FRAMES) throw new RangeError(`frames must be an integer from 1 to ${MAX_LIVE_FRAMES}, got ${describeValue(frames)}`);
    const target: ControlTarget = { speed: p.speed, heading: p.heading };
    checkTarget(target);
    const started = performance.now();
    const core = this.core;
    while (core.pendingFrames(live.stream) < frames) {
      const root = live.stream.stream.root;
      await core.emit(live.stream, repeated(controlTowardHeading(root.heading, target.heading, target.speed), core.layout.pooling));
    }
    const chunk = core.take(live.stream, frames, performance.now() - started);
    return { ...chunk, ...this.measure(chunk, live.meter) };
  }

  /** Per frame: the achieved speed (joint 0, SpeedMeter) and the root's facing in (−π, π]. */
  private measure(chunk: LatentChunk, meter: SpeedMeter): { speed: Float32Array; heading: Float32Array } {
    const n = this.core.skeleton.joints.length * 3;
    const speed = new Float32Array(chunk.frames), heading = new Float32Array(chunk.frames);
    for (let f = 0; f < chunk.frames; f++) {
      speed[f] = meter.push(chunk.positions[f * n], chunk.positions[f * n + 2]);
      heading[f] = angleDifference(chunk.rootHeading[f], 0);
    }
    return { speed, heading };
  }

  async simulate(p: LatentSimulateControlParams, progress: (fraction: number) => void, signal?: AbortSignal): Promise<LatentSimulatedControlChunk> {
    checkSeconds(p.seconds);
    const schedule = checkSchedule(p.schedule);
    const seed = checkSeed(p.seed);
    const gait = p.gait === undefined ? (schedule[0].speed >= 2 ? 'run' : 'walk') : checkGait(p.gait);
    const lock = checkFootLock(p.footLock);
    const core = this.core;
    const { fps, pooling } = core.layout;
    const s = await core.createStream({ seed, gait, footLock: false }, signal);
    const total = Math.max(1, Math.round(p.seconds * fps));
    const targetSpeed = new Float32Array(total), targetHeading = new Float32Array(total);
    const batchMs: number[] = [], batchFrames: number[] = [];
    let done = 0;
    while (done < total) {
      const now = done / fps;
      const goal = [...schedule].reverse().find((e) => e.t <= now + 1e-9) ?? schedule[0];
      const root = s.stream.root;
      const t0 = performance.now();
      await core.emit(s, repeated(controlTowardHeading(root.heading, goal.heading, goal.speed), pooling), undefined, signal);
      const kept = Math.min(pooling, total - done);
      batchMs.push(performance.now() - t0);
      batchFrames.push(kept);
      targetSpeed.fill(goal.speed, done, done + kept);
      targetHeading.fill(goal.heading, done, done + kept);
      done += kept;
      progress(done / total);
    }
    const chunk = core.take(s, total);
    const measured = this.measure(chunk, new SpeedMeter(fps));
    const computeMsPerFrame = new Float32Array(total);
    let at = 0;
    batchMs.forEach((ms, i) => {
      computeMsPerFrame.fill(ms / batchFrames[i], at, at + batchFrames[i]);
      at += batchFrames[i];
    });
    if (lock) ({ positions: chunk.positions, contacts: chunk.contacts } = plantFeet(chunk.positions, chunk.contacts, core.skeleton.joints, core.skeleton.offsets, fps));
    chunk.computeMs = batchMs.reduce((a, b) => a + b, 0);
    return {
      ...chunk,
      ...measured,
      targetSpeed,
      targetHeading,
      computeMsPerFrame,
      batchMs: Float32Array.from(batchMs),
      batchFrames: Uint8Array.from(batchFrames),
    };
  }
}

/** Adds `origin` to the x and z of every root (x, z, heading triples). */
export function moveRootsBack(chunk: { roots: Float64Array }, origin: [number, number]): void {
  for (let i = 0; i < chunk.roots.length; i += 3) {
    chunk.roots[i] += origin[0];
    chunk.roots[i + 1] += origin[1];
  }
}
