// Offline path following (Wang, Chai, Xia §5.2): sliding windows of 34 frames overlapping by 17. In each
// window a population of particles — sampling variables plus a few steering parameters — is run through
// the generator in one batched call per frame and ranked by E = −log(P_prior · P_noise · P_curve ·
// P_contact) (eq. 19) with a progress term; the best few seed the next rounds, which perturb them ever
// more locally (the cross-entropy search of search.ts). The best particle's first 17 frames are kept and
// the next window starts from its state.
import { decodeFeatures, type RootStart } from '../model/featureDecode';
import { noiseCorrelation, styleSeeds, type GeneratorInfo } from '../model/generatorInfo';
import { Rng } from '../model/sampler';
import { contactCost, lastToes, particleFeatures, type ToeState } from './objective';
import { angleDifference, GroundPath } from './path';
import { seedStreamState, type RolloutResult, type SteerRequest, type StepFn, type Steering } from './rollout';
import { crossEntropySearch } from './search';

export type Gait = 'walk' | 'run';
export const WINDOW_FRAMES = 34;
export const COMMIT_FRAMES = 17;

/**
 * The speeds a gait's particles try (m/s) and the pace the progress term expects. Running's pace is the real runs':
 * the Bandai Namco set's normal runs go 2.9 m/s (median root speed; 2.5-3.6 across its styles, elderly's 1.5). At the
 * 2.4 m/s it asked before, the style generator ran in short steps (active: 51-56% of real runs' toe swing in its
 * weakest second; at 2.9 m/s 82-88%, docs/models/style-generator.md).
 */
const GAITS: Record<Gait, { speeds: [number, number]; pace: number }> = {
  walk: { speeds: [0.9, 1.5], pace: 1.1 },
  run: { speeds: [2.4, 3.6], pace: 2.9 },
};
/** Largest heading change a steering target asks for in one frame (rad): 4.5 rad/s. */
const MAX_TURN_PER_FRAME = 0.15;
/**
 * A reversal of the path (GroundPath.cusps) counts as reached once the root comes this close (m): until then
 * the tracked arc and the look-ahead stop at it, so the walk neither turns back early nor is credited for
 * the way back before it got there. Under the 0.15 m of pathCoverage, so a reached tip counts as followed.
 */
export const CUSP_REACH = 0.1;
/**
 * Where a path runs back over itself, a point there is as near the earlier stretch as the later one: each metre
 * of arc behind the walker's last position counts as this many metres farther (tracking then keeps to the later
 * stretch, the one the walker is on), small enough not to matter where the stretches are apart.
 */
const BACK_COST = 0.1;
/**
 * A target more than 90° off the facing (behind, after a reversal) is not stepped toward: that would be walking
 * backwards. From 90° to 150° off (smoothly) the step shrinks to TURNING_STEP of the pace and turns from toward
 * the target to 45° off the facing, on the side of the turn: the walker turns round on a small loop while still
 * stepping. Asked to stop and turn on the spot (no step), the generator often kept shuffling at 0.1–0.15 m/s for
 * many seconds after. With this loop alone it still did at times (back-and-forth path, seeds 3, 4, 6 in Node
 * shuffled at 0.1–0.2 m/s after a turn and ran out of time at 62–74% followed); see STALL_WINDOWS for the rest.
 * A faster loop (0.9 of the pace) did not cure it: 58.8, 61.9, 80.6% for those seeds.
 */
const TURN_FROM = Math.PI / 2;
const TURN_FULL_AT = (5 * Math.PI) / 6;
const TURNING_STEP = 0.6;
/**
 * Escaping a shuffle. After turning round the generator at times falls into a shuffle at 0.1–0.2 m/s that the
 * search cannot leave: the model is so sure of a shuffle's small steps that its prior NLL is ~1000 lower over a
 * window than a walk's, more than the progress term's whole range, and with full-size input noise no particle
 * walks off (more particles or rounds made it worse: 52–58% followed; a higher temperature did not help). After
 * STALL_WINDOWS committed windows each under STALL_SHARE of the pace, the next windows (until one is not slow)
 * draw input noise STALL_NOISE_SCALE× the size, which moves the network's input off the shuffle, and weigh the
 * prior by STALL_PRIOR_WEIGHT. Back-and-forth path, seeds 0–8 in Node: 96.9–100% followed (seeds 3, 4, 6 were
 * at 62.1, 73.7, 69.0%). Turning round at a tip is slow too: from the first slow window on, the extra noise threw
 * the walker off the way back (seeds 5 and 8: 91.8, 93.2%), hence two windows.
 */
const STALL_SHARE = 0.5;
const STALL_WINDOWS = 2;
const STALL_NOISE_SCALE = 3;
const STALL_PRIOR_WEIGHT = 0.5;
/** Progress shortfall of 10 cm over a window costs 1. */
const PROGRESS_SIGMA = 0.05;
/**
 * Beyond this distance from the path (m) each frame pays an extra ((e − margin) / 3 cm)²: eq. (17)'s
 * squared error alone ranks a window that overshoots a sharp corner by 35 cm for a few frames above
 * one that stays within 15 cm but is a little off everywhere. 10 cm (it was 15) leaves room under the 15 cm
 * within which pathCoverage counts the path followed: after turning round at a reversal the walker drifted
 * 15–20 cm off the way back for a second (back-and-forth seed 2: 93% followed at 15 cm, 99% at 10).
 */
const FIT_MARGIN = 0.1;
const FIT_MARGIN_SIGMA = 0.03;
/**
 * The best eighth of a round seeds the next (live control keeps a quarter): over a 34-frame window the
 * fit and progress terms separate particles clearly, so the search can narrow to the few best.
 */
export const PATH_ELITE_SHARE = 1 / 8;
/**
 * Perturbation after round r: β = PATH_BETA / (r + 1) and knob jitter × 1 / (r + 1), ever more local
 * (live control's stays fixed): offline windows can afford more rounds, each refining the last.
 */
export const PATH_BETA = 0.6;
const pathBeta = (round: number) => PATH_BETA / (round + 1);
const pathJitterScale = (round: number) => 1 / (round + 1);

export interface FollowPathOptions {
  step: StepFn;
  info: GeneratorInfo;
  mean: Float32Array;
  std: Float32Array;
  path: GroundPath;
  gait: Gait;
  seed: number;
  /** A style generator's style, whose seed states the walk starts from (default its first); `step` must feed the same style. */
  style?: string;
  /** σ_fit of eq. (17), metres (default 0.1). */
  fitSigma?: number;
  temperature?: number;
  /** Particles per round and rounds per window (defaults 24 and 2: measured 3× faster than real time on one core, docs/models/control.md). */
  particles?: number;
  rounds?: number;
  /** Called after each window with the share of the path covered (0…1). */
  onProgress?: (fraction: number) => void;
}

export interface FollowPathStats {
  /** Mean and largest distance from the root (on the ground) to the path, over all frames (m). */
  meanError: number;
  maxError: number;
  /** How far along the path the character got, as a share of its length. */
  arcProgress: number;
  optimizeMs: number;
  windows: number;
  /** Generator evaluations (particles × frames) spent. */
  particleSteps: number;
}

export interface FollowPathResult {
  features: Float32Array;
  positions: Float32Array;
  contacts: Uint8Array;
  rootHeading: Float32Array;
  seedIndex: number;
  frames: number;
  stats: FollowPathStats;
}

/** A particle's steering parameters. */
interface Knobs {
  /** Share of the heading error to the look-ahead point asked for per frame. */
  gain: number;
  /** Look-ahead along the path (m). */
  look: number;
  /** Speed asked for (m/s). */
  speed: number;
  /** Authority of the steering over the step (Δtx, Δtz) and the turn (Δry), 0…1, and the step's reach in model σ (rollout.ts). */
  authority: number;
  turnAuthority: number;
  reach: number;
}

function randomKnobs(rng: Rng, gait: Gait): Knobs {
  const [lo, hi] = GAITS[gait].speeds;
  return {
    gain: 0.08 + 0.22 * rng.uniform(),
    look: (gait === 'run' ? 0.5 : 0.25) + 0.8 * rng.uniform(),
    speed: lo + (hi - lo) * rng.uniform(),
    authority: 0.3 + 0.65 * rng.uniform(),
    turnAuthority: 0.5 + 0.5 * rng.uniform(),
    reach: 0.5 + 3.5 * rng.uniform(),
  };
}

function jitterKnobs(k: Knobs, scale: number, rng: Rng, gait: Gait): Knobs {
  const [lo, hi] = GAITS[gait].speeds;
  const clamp = (v: number, a: number, b: number) => Math.min(Math.max(v, a), b);
  return {
    gain: clamp(k.gain + 0.05 * scale * rng.normal(), 0.03, 0.4),
    look: clamp(k.look + 0.15 * scale * rng.normal(), 0.15, 1.4),
    speed: clamp(k.speed + 0.15 * scale * rng.normal(), lo * 0.8, hi * 1.1),
    authority: clamp(k.authority + 0.1 * scale * rng.normal(), 0.05, 0.98),
    turnAuthority: clamp(k.turnAuthority + 0.1 * scale * rng.normal(), 0.05, 1),
    reach: clamp(k.reach + 0.4 * scale * rng.normal(), 0.2, 6),
  };
}

/** Steers each particle toward a point `look` metres ahead of where it stands on the path. */
class PathSteering implements Steering {
  readonly arcs: Float64Array;

  constructor(
    private readonly path: GroundPath,
    private readonly knobs: Knobs[],
    startArc: number,
    private readonly fps: number,
  ) {
    this.arcs = new Float64Array(knobs.length).fill(startArc);
  }

  target(b: number, _t: number, x: number, z: number, heading: number, out: SteerRequest): void {
    const k = this.knobs[b];
    const s = (this.arcs[b] = trackArc(this.path, x, z, this.arcs[b]));
    // Look no further than a reversal not yet reached: walk to its tip first.
    const cusp = this.path.nextCusp(s);
    const lookArc = s + k.look > cusp && !reachedCusp(this.path, cusp, x, z) ? cusp : s + k.look;
    const [lx, lz] = this.path.pointAt(lookArc);
    let dx = lx - x, dz = lz - z;
    const far = Math.hypot(dx, dz);
    const remaining = this.path.length - s;
    // At the end, stop asking for a turn and let the pace run out.
    const want = far > 0.05 ? Math.atan2(dx, dz) : heading;
    const off = angleDifference(want, heading);
    // 0 while the target is within 90° of the facing, 1 from 150° (turning round: see TURN_FROM).
    const turning = smoothstep((Math.abs(off) - TURN_FROM) / (TURN_FULL_AT - TURN_FROM));
    if (turning > 0) {
      const side = off >= 0 ? 1 : -1;
      const direction = heading + side * TURN_FROM * (1 - turning / 2);
      dx = Math.sin(direction);
      dz = Math.cos(direction);
    } else if (far > 1e-6) {
      dx /= far;
      dz /= far;
    } else {
      dx = Math.sin(heading);
      dz = Math.cos(heading);
    }
    const step = Math.min(k.speed / this.fps, Math.max(remaining, 0)) * (1 - (1 - TURNING_STEP) * turning);
    const wx = dx * step, wz = dz * step;
    const cs = Math.cos(heading), sn = Math.sin(heading);
    out.target[0] = cs * wx - sn * wz; // the step in the previous frame's heading frame (inverse of featureDecode)
    out.target[1] = sn * wx + cs * wz;
    out.target[2] = Math.max(-MAX_TURN_PER_FRAME, Math.min(MAX_TURN_PER_FRAME, k.gain * off));
    out.authority[0] = out.authority[1] = k.authority;
    out.authority[2] = k.turnAuthority;
    out.reach[0] = out.reach[1] = k.reach;
  }
}

const smoothstep = (t: number) => {
  const u = Math.min(Math.max(t, 0), 1);
  return u * u * (3 - 2 * u);
};

/** Whether a walker at (x, z) is within CUSP_REACH of the reversal at arc `cusp`. */
function reachedCusp(path: GroundPath, cusp: number, x: number, z: number): boolean {
  const [cx, cz] = path.pointAt(cusp);
  return Math.hypot(x - cx, z - cz) <= CUSP_REACH;
}

/**
 * Where a walker at (x, z) is along the path: the nearest point from 0.3 m behind its last arc length to 1.2 m
 * ahead (so self-crossing paths are not short-cut), but not past a reversal it has not reached, and keeping to
 * the later stretch where the path runs back over itself (BACK_COST).
 */
export function trackArc(path: GroundPath, x: number, z: number, previous: number): number {
  const cusp = path.nextCusp(previous);
  const ahead = cusp < previous + 1.2 && !reachedCusp(path, cusp, x, z) ? cusp : previous + 1.2;
  return path.project(x, z, previous - 0.3, ahead, previous, BACK_COST).s;
}

/** Path cost of particle b: eq. (17) per frame, the margin penalty and the progress shortfall, from arc `startArc`. */
function pathCost(r: RolloutResult, b: number, path: GroundPath, startArc: number, fitSigma: number, pace: number, fps: number): number {
  let s = startArc, cost = 0;
  for (let t = 0; t < r.T; t++) {
    const i = (b * r.T + t) * 3;
    s = trackArc(path, r.roots[i], r.roots[i + 1], s);
    const near = path.pointAt(s);
    const e2 = (r.roots[i] - near[0]) ** 2 + (r.roots[i + 1] - near[1]) ** 2;
    cost += e2 / (fitSigma * fitSigma);
    const over = Math.sqrt(e2) - FIT_MARGIN;
    if (over > 0) cost += (over / FIT_MARGIN_SIGMA) ** 2;
  }
  const expected = Math.min((pace * r.T) / fps, path.length - startArc);
  const shortfall = Math.max(0, expected - (s - startArc));
  return cost + (shortfall / PROGRESS_SIGMA) ** 2;
}

/**
 * Seed states of a gait: those whose names start with it ("walk 02_01"). A model whose seeds name no gait at all
 * (a user's pack: its seeds are its own clips, named by file) starts every gait from any of them.
 */
export function gaitSeeds(info: GeneratorInfo, gait: Gait, style?: string): number[] {
  // A style generator's seeds of `style` (default its first style); every seed of a generator without styles.
  const pool = styleSeeds(info, style);
  const found = pool.filter((i) => info.seeds[i].name.startsWith(gait));
  const namesGaits = pool.some((i) => (Object.keys(GAITS) as string[]).some((g) => info.seeds[i].name.startsWith(g)));
  if (!found.length && !namesGaits) return pool;
  if (!found.length) throw new Error(`the generator has no "${gait}" seed states (it has ${info.seeds.map((s) => s.name).join(', ')})`);
  return found;
}

export async function followPath(o: FollowPathOptions): Promise<FollowPathResult> {
  const started = performance.now();
  const { info, path, gait } = o;
  const D = info.onnx.dim;
  const fps = info.fps;
  const P = o.particles ?? 24;
  const rounds = o.rounds ?? 2;
  const fitSigma = o.fitSigma ?? 0.1;
  const temperature = o.temperature ?? 0.5;
  const rng = new Rng(o.seed);
  const seeds = gaitSeeds(info, gait, o.style);
  const seedIndex = seeds[(o.seed >>> 0) % seeds.length];
  const start: RootStart = { x: path.xs[0], z: path.zs[0], heading: path.headingAt(0) };
  let state = seedStreamState(info.seeds[seedIndex], start);
  // A slow walker still gets 2.5× the time the pace needs before the follower gives up.
  const maxFrames = Math.ceil(((path.length / GAITS[gait].pace) * 2.5 + 2) * fps);

  const kept: Float32Array[] = [];
  let frames = 0, arc = 0, windows = 0, particleSteps = 0;
  let toes: ToeState | null = null;

  // Committed windows in a row that fell under STALL_SHARE of the pace.
  let slowWindows = 0;
  while (frames < maxFrames) {
    const stalled = slowWindows >= STALL_WINDOWS;
    const priorWeight = stalled ? STALL_PRIOR_WEIGHT : 1;
    const best = await crossEntropySearch({
      rollout: { step: o.step, info, mean: o.mean, std: o.std, start: state, temperature, noiseScale: stalled ? STALL_NOISE_SCALE : 1, commit: COMMIT_FRAMES, noiseCorrelation: noiseCorrelation(info) },
      particles: P,
      frames: WINDOW_FRAMES,
      rounds,
      eliteShare: PATH_ELITE_SHARE,
      beta: pathBeta,
      rng,
      randomKnobs: (r) => randomKnobs(r, gait),
      jitterKnobs: (k, round, r) => jitterKnobs(k, pathJitterScale(round), r, gait),
      steering: (knobs) => new PathSteering(path, knobs, arc, fps),
      cost: (result, b) =>
        priorWeight * result.priorCost[b] + result.noiseCost[b] + pathCost(result, b, path, arc, fitSigma, GAITS[gait].pace, fps) + contactCost(info, particleFeatures(result, b), state.root, toes),
    });
    particleSteps += best.particleSteps;
    windows++;

    const { result, particle: b } = best;
    const end = framesToKeep(path, result, b, arc);
    slowWindows = end.arc - arc < (STALL_SHARE * GAITS[gait].pace * COMMIT_FRAMES) / fps ? slowWindows + 1 : 0;
    arc = end.arc;
    const chunk = particleFeatures(result, b, end.keep);
    kept.push(chunk.slice());
    // Toe state for the next window's contact term.
    const decoded = decodeFeatures(info, chunk, state.root);
    toes = lastToes(info, decoded.positions, decoded.contacts);
    frames += end.keep;
    if (end.finished) {
      o.onProgress?.(1);
      break;
    }
    state = result.states[b];
    o.onProgress?.(Math.min(1, arc / path.length));
  }

  const features = new Float32Array(frames * D);
  let at = 0;
  for (const chunk of kept) {
    features.set(chunk, at);
    at += chunk.length;
  }
  const decoded = decodeFeatures(info, features, start);
  return {
    features,
    positions: decoded.positions,
    contacts: decoded.contacts,
    rootHeading: decoded.rootHeading,
    seedIndex,
    frames,
    stats: { ...pathErrors(path, decoded.positions, info.skeleton.joints.length, frames), optimizeMs: performance.now() - started, windows, particleSteps },
  };
}

/**
 * How many of the best particle's frames a window keeps: COMMIT_FRAMES, or fewer where it reaches the
 * path's end before; and the arc length where the kept frames end.
 */
function framesToKeep(path: GroundPath, result: RolloutResult, b: number, arc: number): { keep: number; arc: number; finished: boolean } {
  const [ex, ez] = path.pointAt(path.length);
  let s = arc, committedArc = arc;
  for (let t = 0; t < result.T; t++) {
    const i = (b * result.T + t) * 3;
    s = trackArc(path, result.roots[i], result.roots[i + 1], s);
    if (s >= path.length - 0.05 || (path.length - s < 0.3 && Math.hypot(result.roots[i] - ex, result.roots[i + 1] - ez) < 0.1)) {
      if (t < COMMIT_FRAMES) return { keep: t + 1, arc: s, finished: true };
      break;
    }
    if (t === COMMIT_FRAMES - 1) committedArc = s;
  }
  return { keep: COMMIT_FRAMES, arc: committedArc, finished: false };
}

/** Mean and largest distance from the root (on the ground) to the path, and the share of the path covered. */
export function pathErrors(path: GroundPath, positions: Float32Array, J: number, frames: number): Pick<FollowPathStats, 'meanError' | 'maxError' | 'arcProgress'> {
  let sum = 0, worst = 0, s = 0;
  for (let f = 0; f < frames; f++) {
    const x = positions[f * J * 3], z = positions[f * J * 3 + 2];
    const e = path.distance(x, z);
    sum += e;
    worst = Math.max(worst, e);
    s = trackArc(path, x, z, s);
  }
  return { meanError: frames ? sum / frames : NaN, maxError: worst, arcProgress: s / path.length };
}
