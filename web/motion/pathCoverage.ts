// How much of a ground path a walk followed: the share of the path's arc length whose points the walk's
// root passed within a tolerance, in the path's order. The shared measure of "followed N% of its length"
// for every model's path follower (docs/models/control.md, issue 43's back-and-forth path).
//
// In order matters: a walk that turns back before the tip of a reversal and later crosses near the skipped
// tip on its way elsewhere must not get that tip counted, nor may a walk that runs a path backwards. So each
// covered path point is matched to a stretch of the walk, the matches never going back in time, and the
// matching that covers the most arc length counts (a longest-common-subsequence style dynamic programme).

/** [x, z] on the ground (metres). */
export type GroundXZ = readonly [number, number];

/** Default tolerance (m): within 0.15 m of the path counts as on it. */
export const PATH_COVERAGE_TOLERANCE = 0.15;
/** The path is sampled every this many metres (or finer: at most 4,000 samples on a long path). */
const SAMPLE_SPACING = 0.01;
const MAX_SAMPLES = 4000;

/**
 * Share (0…1) of `path`'s arc length followed by `walk`: path points (sampled every cm along the polyline)
 * within `tolerance` of the walk's polyline (each frame's root, joined frame to frame), matched to the walk
 * in order (a later path point never to an earlier stretch of the walk), maximised over such matchings.
 * `path` is the polyline as given (no smoothing); `walk` one [x, z] per frame, e.g. rootGroundTrack's.
 */
export function pathCoverage(path: readonly GroundXZ[], walk: readonly GroundXZ[], tolerance = PATH_COVERAGE_TOLERANCE): number {
  if (path.length < 2) throw new RangeError(`pathCoverage: the path needs at least 2 points, got ${path.length}`);
  if (!(tolerance > 0)) throw new RangeError(`pathCoverage: tolerance must be a positive number of metres, got ${tolerance}`);
  const { xs, zs, weights, length } = samplePath(path);
  if (!(length > 0) || walk.length === 0) return 0;
  // Stretches of the walk: segment k joins frames k and k + 1 (one point when the walk has one frame).
  const segments = Math.max(1, walk.length - 1);
  const tol2 = tolerance * tolerance;
  // best[k]: most arc length covered by the samples so far with the last match at stretch ≤ k.
  let best = new Float64Array(segments);
  let next = new Float64Array(segments);
  for (let i = 0; i < xs.length; i++) {
    let running = 0;
    for (let k = 0; k < segments; k++) {
      const a = walk[k], b = walk[Math.min(k + 1, walk.length - 1)];
      const matched = segmentDistance2(xs[i], zs[i], a[0], a[1], b[0], b[1]) <= tol2 ? best[k] + weights[i] : best[k];
      running = Math.max(running, matched);
      next[k] = running;
    }
    [best, next] = [next, best];
  }
  return Math.min(1, best[segments - 1] / length);
}

/** The root's [x, z] each frame from frames × joints × 3 positions (the root is joint 0). */
export function rootGroundTrack(positions: ArrayLike<number>, jointCount: number, frames = Math.floor(positions.length / (jointCount * 3))): GroundXZ[] {
  const track: GroundXZ[] = [];
  for (let f = 0; f < frames; f++) track.push([positions[f * jointCount * 3], positions[f * jointCount * 3 + 2]]);
  return track;
}

/** Points every SAMPLE_SPACING m along the polyline (ends included), each weighted by the arc length it stands for. */
function samplePath(path: readonly GroundXZ[]): { xs: Float64Array; zs: Float64Array; weights: Float64Array; length: number } {
  const cumulative = [0];
  for (let i = 1; i < path.length; i++) cumulative.push(cumulative[i - 1] + Math.hypot(path[i][0] - path[i - 1][0], path[i][1] - path[i - 1][1]));
  const length = cumulative[cumulative.length - 1];
  const n = Math.max(2, Math.min(MAX_SAMPLES, Math.ceil(length / SAMPLE_SPACING) + 1));
  const step = length / (n - 1);
  const xs = new Float64Array(n), zs = new Float64Array(n), weights = new Float64Array(n);
  let seg = 1;
  for (let i = 0; i < n; i++) {
    const s = i === n - 1 ? length : i * step;
    while (seg < path.length - 1 && cumulative[seg] < s) seg++;
    const span = cumulative[seg] - cumulative[seg - 1];
    const t = span > 0 ? (s - cumulative[seg - 1]) / span : 0;
    xs[i] = path[seg - 1][0] + (path[seg][0] - path[seg - 1][0]) * t;
    zs[i] = path[seg - 1][1] + (path[seg][1] - path[seg - 1][1]) * t;
    weights[i] = i === 0 || i === n - 1 ? step / 2 : step;
  }
  return { xs, zs, weights, length };
}

/** Squared distance from (x, z) to the segment a–b. */
function segmentDistance2(x: number, z: number, ax: number, az: number, bx: number, bz: number): number {
  const dx = bx - ax, dz = bz - az;
  const len2 = dx * dx + dz * dz;
  const t = len2 > 0 ? Math.min(Math.max(((x - ax) * dx + (z - az) * dz) / len2, 0), 1) : 0;
  const ex = ax + dx * t - x, ez = az + dz * t - z;
  return ex * ex + ez * ez;
}
