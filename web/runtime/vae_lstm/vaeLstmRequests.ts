// The VAE-LSTM worker's path request. The whole drawn path becomes one control signal before the model runs:
// a bare root (no body) follows the path by pure pursuit (controlAlongPath, as the latent ERD's follower
// does every step) at the asked speed, frame by frame, until it arrives and has stood still for
// ARRIVED_SECONDS; its per-frame controls are the signal, and the root the motion is placed on
// (vaeLstmCore.ts step 5). The model then makes the body for the whole signal in one go. The result keeps
// the other followers' return shapes and stats, measured the same way (pathErrors on the hips, footStats).
import { controlAlongPath, MAX_TURN_RATE, PolylinePath, stepRoot, wrap, type Root } from '../../motion/control';
import { footStats } from '../../motion/footSkating';
import { checkFollowRequest, optional } from '../../optimizer/options';
import { moveBack } from '../../optimizer/path';
import { pathErrors } from '../../optimizer/pathFollower';
import { ARRIVED_SECONDS, checkPathSpeed, LATENT_PATH_SPEED, moveRootsBack } from '../latent_erd/latentErdRequests';
import type { VaeLstmCore } from './vaeLstmCore';
import type { VaeLstmFollowPathChunk, VaeLstmFollowPathParams } from './vaeLstmProtocol';

/**
 * The per-frame control (frames × 3) that walks a bare root along `path` from `start` at `speed`, as pure
 * pursuit steers it; it ends once the root has stood ARRIVED_SECONDS at the end, or after `maxFrames`.
 */
export function controlForPath(path: PolylinePath, start: Root, speed: number, fps: number, maxFrames: number): Float64Array {
  const out: number[] = [];
  const still = Math.ceil(ARRIVED_SECONDS * fps);
  let root = start, arc = 0, stopped = 0;
  while (out.length / 3 < maxFrames && stopped < still) {
    const next = controlAlongPath(path, root.x, root.z, root.heading, arc, speed);
    arc = next.progress;
    stopped = next.control.every((v) => v === 0) ? stopped + 1 : 0;
    out.push(...next.control);
    root = stepRoot(root, next.control, fps);
  }
  return Float64Array.from(out);
}

/** The path's total turning (rad): the sum of its direction changes at its points (zero-length segments skipped). */
export function totalTurning(path: PolylinePath): number {
  let total = 0, last: number | undefined;
  for (let i = 0; i + 1 < path.points.length; i++) {
    const [a, b] = [path.points[i], path.points[i + 1]];
    if (a[0] === b[0] && a[1] === b[1]) continue;
    const along = Math.atan2(b[0] - a[0], b[1] - a[1]);
    if (last !== undefined) total += Math.abs(wrap(along - last));
    last = along;
  }
  return total;
}

export async function followPathVae(core: VaeLstmCore, p: VaeLstmFollowPathParams, progress: (fraction: number) => void, signal?: AbortSignal): Promise<VaeLstmFollowPathChunk> {
  const started = performance.now();
  // Made near the origin and moved back to where the path is (as the other followers).
  const { gait, seed, lock, origin, ground } = checkFollowRequest(p);
  const speed = checkPathSpeed(optional(p.speed, LATENT_PATH_SPEED[gait]));
  const fps = core.fps;
  const path = new PolylinePath(ground.points());
  const start: Root = { x: ground.xs[0], z: ground.zs[0], heading: ground.headingAt(0) };
  // As the other followers, 2.5× the time the pace needs and 2 s before giving up; and twice the time its turns take
  // at the most turning speed, for the root slows down into a sharp bend, turns and speeds up again (a run that
  // doubles back four times needs 17 s where the pace needs 5).
  const seconds = (path.length / speed) * 2.5 + 2 + (2 * totalTurning(path)) / MAX_TURN_RATE;
  const control = controlForPath(path, start, speed, fps, Math.ceil(seconds * fps));
  progress(0.1);
  const frames = control.length / 3;
  const chunk = await core.generate({ frames, seed, control, footLock: lock }, signal, { root: start });
  progress(1);
  const J = core.skeleton.joints.length;
  const stats = {
    ...pathErrors(ground, chunk.positions, J, frames),
    optimizeMs: performance.now() - started,
    windows: Math.ceil(frames / core.info.pooling),
    particleSteps: Math.ceil(frames / core.info.pooling),
    ...footStats({ fps, skeleton: core.skeleton }, frames, chunk, { positions: chunk.fitted, contacts: chunk.decodedContacts }),
  };
  for (const positions of [chunk.positions, chunk.fitted, chunk.predicted]) moveBack(positions, origin);
  moveRootsBack(chunk, origin);
  chunk.computeMs = stats.optimizeMs;
  return { ...chunk, stats, path: ground.flatAt(origin) };
}
