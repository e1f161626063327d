// The latent ERD's low-dimensional control signal (Yearsley §3.2.1, Ch. 6): per frame the root's forward
// and sideways velocity (m/s, in its own ground-projected facing frame; sideways positive to the walker's
// left, +x at heading 0) and turning speed (rad/s, positive turns from +z towards +x). Heading 0 faces +z,
// π/2 faces +x. Frame t's signal is the motion from frame t to frame t+1.
//
// The same rules are in training/control.py, and tests/fixtures/control_signal.json
// (python -m training.fixtures.control_signal) checks the two against each other: every function here
// does the float64 arithmetic in the same order as its Python twin.

import { Rng } from './random';

/** One frame's signal: [forward m/s, sideways m/s, turn rad/s]. */
export type Control = [number, number, number];
/** A walker's ground root: position (m) and heading (rad). */
export interface Root {
  x: number;
  z: number;
  heading: number;
}

/** The stick and the path follower close a heading error in TURN_TIME s, at most MAX_TURN_RATE rad/s. */
export const TURN_TIME = 0.25;
export const MAX_TURN_RATE = 2.5;
/** Pure pursuit looks LOOKAHEAD_SECONDS of travel ahead along the path, and at least MIN_LOOKAHEAD m. */
export const LOOKAHEAD_SECONDS = 0.6;
export const MIN_LOOKAHEAD = 0.5;
/**
 * The follower searches for itself on the path from its last arc length to PROGRESS_AHEAD m further, never behind
 * it: where a path doubles back, the leg it walked lies under the leg it walks.
 */
export const PROGRESS_AHEAD = 1.2;
/**
 * Of the stretches of the path within NEAR_TIE m as near the walker as the nearest, it is on the earliest: where a path
 * doubles back, the leg it came up and the leg it goes back on lie within a drawing's jitter of each other.
 */
export const NEAR_TIE = 0.05;
/** It slows down over the last STOP_SECONDS of travel so it stops at the end, and stands still within ARRIVED metres of it. */
export const STOP_SECONDS = 0.5;
export const ARRIVED = 0.05;
/**
 * A bend of the path sharper than SHARP_BEND rad (from the path's direction where the walker is) stops the look-ahead:
 * pure pursuit would cut across it (a reversal whole), so the walker is steered to the bend itself, slowing as it
 * nears (as at the end), looks past it once within BEND_REACH m of it, and speeds up again as it slowed.
 */
export const SHARP_BEND = Math.PI / 4;
export const BEND_REACH = 0.1;
/**
 * Forward speed falls with the heading error: full within FULL_SPEED_ERROR rad, none from STILL_ERROR on (so a
 * reversal turns on the spot rather than walking a loop off the path).
 */
export const FULL_SPEED_ERROR = Math.PI / 9;
export const STILL_ERROR = Math.PI / 4;
/** Random control: a new target speed and turn every RANDOM_SEGMENT s, eased towards with time constant RANDOM_EASE s. */
export const RANDOM_SEGMENT = 2.0;
export const RANDOM_EASE = 0.5;
/** Target forward speeds are drawn from [RANDOM_SPEED[0], RANDOM_SPEED[1]) m/s, turns from ±RANDOM_TURN rad/s. */
export const RANDOM_SPEED: readonly [number, number] = [0.4, 2.0];
export const RANDOM_TURN = 1.2;

const TWO_PI = 2 * Math.PI;

/**
 * Angle wrapped to [−π, π), as Python's ((a + π) % 2π) − π: its float modulo takes the sign of the divisor
 * (JavaScript's % takes the dividend's), so a negative remainder moves up by 2π and a zero one is +0.
 */
export function wrap(a: number): number {
  let m = (a + Math.PI) % TWO_PI;
  if (m === 0) m = 0;
  else if (m < 0) m += TWO_PI;
  return m - Math.PI;
}

/** World ground displacement (dx, dz) in the frame of a walker facing `heading`: [sideways, forward]. */
export function rotateToLocal(dx: number, dz: number, heading: number): [number, number] {
  const c = Math.cos(heading), s = Math.sin(heading);
  return [c * dx - s * dz, s * dx + c * dz];
}

/**
 * The signal (frames × 3: forward, sideways, turn) of a ground trajectory: `xz` frames × 2 (x, z), `heading`
 * per frame. The last frame repeats the one before it; one frame gives zeros.
 */
export function controlFromTrajectory(xz: ArrayLike<number>, heading: ArrayLike<number>, fps: number): Float64Array {
  const n = heading.length;
  const out = new Float64Array(n * 3);
  for (let t = 0; t + 1 < n; t++) {
    const [side, fwd] = rotateToLocal(xz[2 * t + 2] - xz[2 * t], xz[2 * t + 3] - xz[2 * t + 1], heading[t]);
    out[3 * t] = fwd * fps;
    out[3 * t + 1] = side * fps;
    out[3 * t + 2] = wrap(heading[t + 1] - heading[t]) * fps;
  }
  if (n > 1) out.copyWithin(3 * (n - 1), 3 * (n - 2), 3 * (n - 1));
  return out;
}

/** The root one frame later: `root` moved by one frame of `control` (root + R(heading)·[side, fwd] / fps). */
export function stepRoot(root: Root, control: ArrayLike<number>, fps: number): Root {
  const fwd = control[0] / fps, side = control[1] / fps, turn = control[2] / fps;
  const c = Math.cos(root.heading), s = Math.sin(root.heading);
  return { x: root.x + (c * side + s * fwd), z: root.z + (-s * side + c * fwd), heading: wrap(root.heading + turn) };
}

/**
 * The ground trajectory (`xz` frames × 2) and headings a signal (frames × 3) traces from `start`: frame 0 is
 * the start, frame t+1 applies frame t's signal (so the last frame's signal is not used).
 */
export function integrateControl(control: ArrayLike<number>, fps: number, start: Root = { x: 0, z: 0, heading: 0 }): { xz: Float64Array; heading: Float64Array } {
  const n = Math.floor(control.length / 3);
  const xz = new Float64Array(n * 2);
  const heading = new Float64Array(n);
  let root: Root = { x: start.x, z: start.z, heading: start.heading };
  for (let t = 0; t < n; t++) {
    xz[2 * t] = root.x;
    xz[2 * t + 1] = root.z;
    heading[t] = root.heading;
    root = stepRoot(root, [control[3 * t], control[3 * t + 1], control[3 * t + 2]], fps);
  }
  return { xz, heading };
}

/** A stick's signal: walk forward at `speed`, turning towards `targetHeading` (error / TURN_TIME, at most MAX_TURN_RATE). */
export function controlTowardHeading(heading: number, targetHeading: number, speed: number): Control {
  const turn = Math.min(Math.max(wrap(targetHeading - heading) / TURN_TIME, -MAX_TURN_RATE), MAX_TURN_RATE);
  return [speed, 0, turn];
}

/** A ground path through `points` ([x, z] pairs, at least 2) with arc lengths, as the follower walks it. */
export class PolylinePath {
  readonly points: [number, number][];
  /** Arc length at each point (m), from 0. */
  readonly arc: Float64Array;
  readonly length: number;

  constructor(points: ArrayLike<number>[]) {
    if (points.length < 2) throw new RangeError(`a PolylinePath needs at least 2 points, got ${points.length}`);
    this.points = Array.from(points, (p) => [p[0], p[1]]);
    this.arc = new Float64Array(points.length);
    for (let i = 1; i < this.points.length; i++) {
      const dx = this.points[i][0] - this.points[i - 1][0], dz = this.points[i][1] - this.points[i - 1][1];
      this.arc[i] = this.arc[i - 1] + Math.sqrt(dx * dx + dz * dz); // as numpy's norm and cumsum
    }
    this.length = this.arc[this.arc.length - 1];
  }

  /** The point at arc length s (clamped to the path). */
  pointAt(s: number): [number, number] {
    s = Math.min(Math.max(s, 0), this.length);
    const i = this.segmentAt(s);
    const span = this.arc[i + 1] - this.arc[i];
    const t = span > 0 ? (s - this.arc[i]) / span : 0;
    const a = this.points[i], b = this.points[i + 1];
    return [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t];
  }

  /** Index of the segment at arc length s (at a point, the segment leaving it; kept on the path). */
  segmentAt(s: number): number {
    // The last point whose arc length is ≤ s (numpy searchsorted side="right" − 1), kept on a segment.
    let lo = 0, hi = this.arc.length;
    while (lo < hi) {
      const mid = (lo + hi) >>> 1;
      if (this.arc[mid] <= s) lo = mid + 1;
      else hi = mid;
    }
    return Math.min(Math.max(lo - 1, 0), this.points.length - 2);
  }

  /**
   * Arc length of the first point after arc length `from` and up to `to` where the path's direction has turned more
   * than `angle` rad from its direction at `from` (zero-length segments skipped), or Infinity if there is none.
   */
  bendAfter(from: number, to: number, angle: number): number {
    let i = this.segmentAt(from);
    while (i < this.points.length - 2 && this.arc[i + 1] === this.arc[i]) i++;
    const a = this.points[i], b = this.points[i + 1];
    const along = Math.atan2(b[0] - a[0], b[1] - a[1]);
    for (let k = i + 1; k + 1 < this.points.length && this.arc[k] <= to; k++) {
      if (this.arc[k + 1] === this.arc[k] || this.arc[k] <= from) continue;
      const p = this.points[k], q = this.points[k + 1];
      if (Math.abs(wrap(Math.atan2(q[0] - p[0], q[1] - p[1]) - along)) > angle) return this.arc[k];
    }
    return Infinity;
  }

  /**
   * Arc length of the last point before arc length `from` and down to `to` (to ≤ from) where the path's direction
   * differs by more than `angle` rad from its direction at `from` (zero-length segments skipped), or −Infinity if
   * there is none.
   */
  bendBefore(from: number, to: number, angle: number): number {
    let i = this.segmentAt(from);
    while (i < this.points.length - 2 && this.arc[i + 1] === this.arc[i]) i++;
    const a = this.points[i], b = this.points[i + 1];
    const along = Math.atan2(b[0] - a[0], b[1] - a[1]);
    for (let k = i; k > 0 && this.arc[k] >= to; k--) {
      if (this.arc[k] === this.arc[k - 1]) continue;
      const p = this.points[k - 1], q = this.points[k];
      if (Math.abs(wrap(Math.atan2(q[0] - p[0], q[1] - p[1]) - along)) > angle) return this.arc[k];
    }
    return -Infinity;
  }

  /**
   * Arc length of the nearest point to (x, z) on the path between arc lengths `from` and `to` (0 if the path has
   * none there); of points less than `tie` m farther than the nearest, the earliest.
   */
  project(x: number, z: number, from: number, to: number, tie = 0): number {
    const arcs: number[] = [], distances: number[] = [];
    for (let i = 0; i + 1 < this.points.length; i++) {
      if (this.arc[i + 1] < from || this.arc[i] > to) continue;
      const a = this.points[i], b = this.points[i + 1];
      const dx = b[0] - a[0], dz = b[1] - a[1];
      const len2 = dx * dx + dz * dz;
      const span = this.arc[i + 1] - this.arc[i];
      // The part of the segment inside [from, to], as fractions of it.
      const lo = span > 0 ? Math.max((from - this.arc[i]) / span, 0) : 0;
      const hi = span > 0 ? Math.min((to - this.arc[i]) / span, 1) : 0;
      const t = len2 > 0 ? Math.min(Math.max(((x - a[0]) * dx + (z - a[1]) * dz) / len2, lo), hi) : 0;
      // Held at its end where the path goes on inside the window: the next segment has that point or a nearer one.
      if (t === 1 && i + 2 < this.points.length && this.arc[i + 1] <= to) continue;
      const ex = a[0] + dx * t - x, ez = a[1] + dz * t - z;
      arcs.push(this.arc[i] + t * span);
      distances.push(Math.sqrt(ex * ex + ez * ez));
    }
    const nearest = Math.min(...distances);
    for (let k = 0; k < arcs.length; k++) if (distances[k] <= nearest + tie) return arcs[k];
    return 0;
  }
}

/**
 * The signal that steers a walker at (x, z) facing `heading` along `path` at `speed` (pure pursuit towards
 * the point max(MIN_LOOKAHEAD, speed · LOOKAHEAD_SECONDS) further along, or a sharp bend before it: SHARP_BEND),
 * slowing over the last STOP_SECONDS before the end or the bend, and zero at the end; and its new progress (arc
 * length), searched near the last one and never going back (where a path doubles back, its two legs lie close).
 */
export function controlAlongPath(path: PolylinePath, x: number, z: number, heading: number, progress: number, speed: number): { control: Control; progress: number } {
  const s = path.project(x, z, progress, progress + PROGRESS_AHEAD, NEAR_TIE);
  const remaining = path.length - s;
  if (remaining <= ARRIVED) return { control: [0, 0, 0], progress: s };
  const reach = Math.max(MIN_LOOKAHEAD, speed * LOOKAHEAD_SECONDS);
  const ahead = s + reach;
  let bend = path.bendAfter(s, ahead, SHARP_BEND);
  let passed = path.bendBefore(s, s - reach, SHARP_BEND);
  if (bend - s <= BEND_REACH) {
    // At the bend: look past it, and leave it as from a stop.
    passed = bend;
    bend = path.bendAfter(bend, ahead, SHARP_BEND);
  }
  const target = path.pointAt(Math.min(ahead, bend));
  const want = Math.atan2(target[0] - x, target[1] - z);
  // Slowing over STOP_SECONDS into the end or a bend, and speeding up as gently out of a bend.
  const slowing = Math.min(remaining, Math.max(bend - s, BEND_REACH), Math.max(s - passed, BEND_REACH));
  const error = Math.abs(wrap(want - heading));
  const facing = Math.min(Math.max((STILL_ERROR - error) / (STILL_ERROR - FULL_SPEED_ERROR), 0), 1);
  const fwd = Math.min(speed, slowing / STOP_SECONDS) * facing;
  return { control: controlTowardHeading(heading, want, fwd), progress: s };
}

/** Python's round(): to the nearest integer, halves to the even one. */
function roundHalfEven(v: number): number {
  const r = Math.round(v);
  return r - v === 0.5 && r % 2 !== 0 ? r - 1 : r;
}

/** A smooth random [forward, 0, turn] signal (frames × 3) drawn from `seed`. */
export function randomControl(seed: number, frames: number, fps: number): Float64Array {
  const rng = new Rng(seed);
  const segment = Math.max(1, roundHalfEven(RANDOM_SEGMENT * fps));
  const ease = 1 - Math.exp(-1 / (RANDOM_EASE * fps));
  let fwd = 1, turn = 0;
  let targetFwd = fwd, targetTurn = turn;
  const out = new Float64Array(frames * 3);
  for (let t = 0; t < frames; t++) {
    if (t % segment === 0) {
      targetFwd = RANDOM_SPEED[0] + (RANDOM_SPEED[1] - RANDOM_SPEED[0]) * rng.uniform();
      targetTurn = RANDOM_TURN * (2 * rng.uniform() - 1);
    }
    fwd += (targetFwd - fwd) * ease;
    turn += (targetTurn - turn) * ease;
    out[3 * t] = fwd;
    out[3 * t + 2] = turn;
  }
  return out;
}
