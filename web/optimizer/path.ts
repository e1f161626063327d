// Ground paths for the path follower: a drawn polyline (x, z pairs in metres) cleaned, smoothed and
// resampled at even arc length, with lookups by arc length and nearest-point projection; and moving a path
// to the origin and its motion back (the follower works near the origin, see relativeToStart).
import { describeValue } from '../motion/describe';
import { checkNoHoles } from '../motion/validate';

export type GroundPoint = [number, number];

/** Spacing of the resampled path (m): fine enough that nearest-point error from resampling is < 1 mm. */
export const PATH_SPACING = 0.05;
/**
 * A reversal (cusp) is where the path turns by more than this (rad, 120°) within ±CUSP_SPAN of a point: the
 * walker must get to it, stop, turn round and walk back, so the follower treats it specially (pathFollower.ts).
 */
export const CUSP_TURN = (2 * Math.PI) / 3;
const CUSP_SPAN = 0.15;
/** A path must be at least this long to follow (m). */
export const MIN_PATH_LENGTH = 0.5;
/** And at most this long: 200 m is minutes of walking. */
export const MAX_PATH_LENGTH = 200;
export const MAX_PATH_POINTS = 20_000;
/**
 * Largest |x| or |z| of a path point (m). Motions hold float32 positions, whose steps are at most 1/1024 m
 * (0.98 mm) below 16,384 m and 8 mm at 100 km: within 10 km (plus the 200 m a path can reach) every joint
 * keeps the millimetre precision it has at the origin (the FK parity tolerance, docs/architecture.md).
 */
export const MAX_PATH_COORDINATE = 10_000;

/** Checks user points: an array of ≥ 2 finite [x, z] pairs within ±MAX_PATH_COORDINATE. Throws with what is wrong. */
export function checkPathPoints(points: unknown): GroundPoint[] {
  if (!Array.isArray(points)) throw new TypeError(`points must be an array of [x, z] pairs (metres), got ${describeValue(points)}`);
  if (points.length < 2) throw new RangeError(`points needs at least 2 [x, z] pairs, got ${points.length}`);
  if (points.length > MAX_PATH_POINTS) throw new RangeError(`points has ${points.length} pairs; at most ${MAX_PATH_POINTS} are accepted`);
  checkNoHoles(points, 'points');
  return points.map((p, i) => {
    if (Array.isArray(p)) checkNoHoles(p, `points[${i}]`);
    if (!Array.isArray(p) || p.length !== 2 || !p.every((v) => typeof v === 'number' && Number.isFinite(v))) {
      throw new TypeError(`points[${i}] must be a pair of finite numbers [x, z], got ${describeValue(p)}`);
    }
    if (Math.abs(p[0]) > MAX_PATH_COORDINATE || Math.abs(p[1]) > MAX_PATH_COORDINATE) {
      throw new RangeError(`points[${i}] ${describeValue(p)} is too far out: x and z must be within ±${MAX_PATH_COORDINATE} m (float32 positions lose millimetre precision beyond)`);
    }
    return [p[0], p[1]];
  });
}

/**
 * The points moved so that the first is at the origin, and that first point. The follower runs on the moved
 * path, so the same shape gives the same motion wherever it lies (its root sums and float32 features never
 * see large coordinates); `moveBack` then puts the motion where the path is.
 */
export function relativeToStart(points: GroundPoint[]): { origin: GroundPoint; local: GroundPoint[] } {
  const [ox, oz] = points[0];
  return { origin: [ox, oz], local: points.map(([x, z]) => [x - ox, z - oz]) };
}

/** Adds `origin` to the x and z of every point of `values` (x, y, z triples, e.g. frames × joints × 3 positions), in place, one rounding each. */
export function moveBack(values: Float32Array, origin: GroundPoint): Float32Array {
  for (let i = 0; i < values.length; i += 3) {
    values[i] += origin[0];
    values[i + 2] += origin[1];
  }
  return values;
}

/** Drops points closer than `minGap` to the previous kept one (pointer jitter, repeated events). */
function dedupe(points: GroundPoint[], minGap: number): GroundPoint[] {
  const out: GroundPoint[] = [points[0]];
  for (const p of points.slice(1)) {
    const q = out[out.length - 1];
    if (Math.hypot(p[0] - q[0], p[1] - q[1]) >= minGap) out.push(p);
  }
  const last = points[points.length - 1];
  const kept = out[out.length - 1];
  if (out.length > 1 && kept !== last) out[out.length - 1] = last; // the end is where the user stopped
  else if (out.length === 1 && Math.hypot(last[0] - kept[0], last[1] - kept[1]) > 0) out.push(last);
  return out;
}

/** Evenly spaced points along a polyline (every `spacing` metres, plus the end). */
function resample(points: GroundPoint[], spacing: number): GroundPoint[] {
  const out: GroundPoint[] = [points[0]];
  let carried = 0; // arc length since the last emitted point
  for (let i = 1; i < points.length; i++) {
    const [ax, az] = points[i - 1];
    const [bx, bz] = points[i];
    const len = Math.hypot(bx - ax, bz - az);
    let at = spacing - carried;
    while (at <= len) {
      const f = at / len;
      out.push([ax + (bx - ax) * f, az + (bz - az) * f]);
      at += spacing;
    }
    carried = len - (at - spacing);
  }
  const end = points[points.length - 1];
  const last = out[out.length - 1];
  if (Math.hypot(end[0] - last[0], end[1] - last[1]) > spacing * 0.25) out.push(end);
  else out[out.length - 1] = end;
  return out;
}

/** Moving average over ±`radius` points, ends held fixed (the start and end are where the user put them). */
function smooth(points: GroundPoint[], radius: number): GroundPoint[] {
  if (radius < 1 || points.length < 3) return points;
  return points.map((p, i) => {
    const r = Math.min(radius, i, points.length - 1 - i);
    let x = 0, z = 0;
    for (let k = i - r; k <= i + r; k++) {
      x += points[k][0];
      z += points[k][1];
    }
    return [x / (2 * r + 1), z / (2 * r + 1)];
  });
}

/** A path resampled at even arc length. Positions along it are arc lengths s ∈ [0, length]. */
export class GroundPath {
  /** x, z of each resampled point. */
  readonly xs: Float64Array;
  readonly zs: Float64Array;
  readonly length: number;
  readonly spacing: number;
  /** Arc lengths of the path's reversals (CUSP_TURN), in order. */
  readonly cusps: number[];

  private constructor(points: GroundPoint[]) {
    this.xs = Float64Array.from(points, (p) => p[0]);
    this.zs = Float64Array.from(points, (p) => p[1]);
    let length = 0;
    for (let i = 1; i < points.length; i++) length += Math.hypot(this.xs[i] - this.xs[i - 1], this.zs[i] - this.zs[i - 1]);
    this.length = length;
    this.spacing = length / Math.max(1, points.length - 1);
    this.cusps = this.findCusps();
  }

  /**
   * Reversals: points where the direction from CUSP_SPAN back to the point and from the point to CUSP_SPAN on
   * differ by more than CUSP_TURN; of each run of such points, the one farthest along the way it came (the tip).
   */
  private findCusps(): number[] {
    const n = this.xs.length;
    const k = Math.max(1, Math.round(CUSP_SPAN / this.spacing));
    const cusps: number[] = [];
    // The run of points past CUSP_TURN now, where it started, and its point farthest along the direction it
    // came in (the tip).
    let run: { first: number; tip: number; reach: number } | null = null;
    for (let i = 1; i < n - 1; i++) {
      const a = Math.max(0, i - k), b = Math.min(n - 1, i + k);
      const inX = this.xs[i] - this.xs[a], inZ = this.zs[i] - this.zs[a];
      const outX = this.xs[b] - this.xs[i], outZ = this.zs[b] - this.zs[i];
      const turn = Math.abs(angleDifference(Math.atan2(outX, outZ), Math.atan2(inX, inZ)));
      if (turn > CUSP_TURN) {
        if (!run) run = { first: i, tip: i, reach: -Infinity };
        const from = Math.max(0, run.first - k);
        const dx: number = this.xs[run.first] - this.xs[from], dz: number = this.zs[run.first] - this.zs[from];
        const along: number = (this.xs[i] - this.xs[from]) * dx + (this.zs[i] - this.zs[from]) * dz;
        if (along > run.reach) run = { ...run, tip: i, reach: along };
      } else if (run) {
        cusps.push(run.tip * this.spacing);
        run = null;
      }
    }
    if (run) cusps.push(run.tip * this.spacing);
    return cusps;
  }

  /** The first reversal after arc length s (Infinity if none). */
  nextCusp(s: number): number {
    for (const c of this.cusps) if (c > s) return c;
    return Infinity;
  }

  /**
   * The path through `points` as given (benchmark paths, API calls): only resampled, not smoothed.
   * Throws if it is shorter than MIN_PATH_LENGTH or longer than MAX_PATH_LENGTH.
   */
  static fromPoints(points: GroundPoint[]): GroundPath {
    const clean = dedupe(points, 1e-6);
    const path = new GroundPath(resample(clean, PATH_SPACING));
    if (!(path.length >= MIN_PATH_LENGTH)) throw new RangeError(`the path is ${path.length.toFixed(2)} m long; it must be at least ${MIN_PATH_LENGTH} m`);
    if (path.length > MAX_PATH_LENGTH) throw new RangeError(`the path is ${path.length.toFixed(1)} m long; at most ${MAX_PATH_LENGTH} m is accepted`);
    return path;
  }

  /** A hand-drawn stroke: jitter below 2 cm dropped, smoothed over ~±15 cm, then resampled. */
  static fromStroke(points: GroundPoint[]): GroundPath {
    const even = resample(dedupe(points, 0.02), PATH_SPACING);
    return GroundPath.fromPoints(smooth(even, 3));
  }

  get count(): number {
    return this.xs.length;
  }

  /** Point at arc length s (clamped to the path). */
  pointAt(s: number): GroundPoint {
    const n = this.count;
    const f = Math.min(Math.max(s / this.spacing, 0), n - 1);
    const i = Math.min(Math.floor(f), n - 2);
    const t = f - i;
    return [this.xs[i] + (this.xs[i + 1] - this.xs[i]) * t, this.zs[i] + (this.zs[i + 1] - this.zs[i]) * t];
  }

  /**
   * Nearest point to (x, z) among arc lengths [from, to] (clamped): its arc length and distance. The
   * follower searches a window around its last position so a path that crosses itself (figure eight)
   * is not short-cut. With `backCost`, each metre of arc before `backFrom` counts as that many metres
   * farther (a path that runs back over itself then projects onto its later stretch, not the earlier).
   */
  project(x: number, z: number, from = 0, to = this.length, backFrom = -Infinity, backCost = 0): { s: number; distance: number } {
    const n = this.count;
    const i0 = Math.max(0, Math.floor(from / this.spacing) - 1);
    const i1 = Math.min(n - 2, Math.ceil(to / this.spacing));
    let best = Infinity, bestS = 0, bestD = Infinity;
    for (let i = i0; i <= i1; i++) {
      const ax = this.xs[i], az = this.zs[i];
      const dx = this.xs[i + 1] - ax, dz = this.zs[i + 1] - az;
      const len2 = dx * dx + dz * dz;
      const t = len2 > 0 ? Math.min(Math.max(((x - ax) * dx + (z - az) * dz) / len2, 0), 1) : 0;
      const ex = ax + dx * t - x, ez = az + dz * t - z;
      const d = Math.sqrt(ex * ex + ez * ez);
      const s = (i + t) * this.spacing;
      const cost = d + backCost * Math.max(0, backFrom - s);
      if (cost < best) {
        best = cost;
        bestS = s;
        bestD = d;
      }
    }
    return { s: bestS, distance: bestD };
  }

  /** Distance from (x, z) to the whole path. */
  distance(x: number, z: number): number {
    return this.project(x, z).distance;
  }

  /** Heading (radians, 0 = +z, π/2 = +x) of the path's direction at arc length s. */
  headingAt(s: number): number {
    const a = this.pointAt(Math.max(0, s - this.spacing));
    const b = this.pointAt(Math.min(this.length, s + this.spacing));
    return Math.atan2(b[0] - a[0], b[1] - a[1]);
  }

  /** The resampled points as [x, z] pairs. */
  points(): GroundPoint[] {
    return Array.from(this.xs, (x, i) => [x, this.zs[i]]);
  }

  /** The points moved by `origin` (relativeToStart's, back to where the user drew), as flat x, z pairs for the page. */
  flatAt(origin: GroundPoint): Float32Array {
    const flat = new Float32Array(this.count * 2);
    for (let i = 0; i < this.count; i++) {
      flat[2 * i] = this.xs[i] + origin[0];
      flat[2 * i + 1] = this.zs[i] + origin[1];
    }
    return flat;
  }
}

/** Angle a − b wrapped to (−π, π]. */
export function angleDifference(a: number, b: number): number {
  let d = (a - b) % (2 * Math.PI);
  if (d > Math.PI) d -= 2 * Math.PI;
  if (d <= -Math.PI) d += 2 * Math.PI;
  return d;
}
