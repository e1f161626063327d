// Online control by speed and direction (Wang, Chai, Xia §5.3): each short batch of frames is optimised
// for the speed term (eq. 22: the batch's mean speed near the asked speed) and the direction term
// (eq. 23: the last frame's facing near the asked heading), with the prior, noise and contact terms of
// the path follower, by the same cross-entropy search (search.ts). Particles look a little past the
// batch so the choice is not greedy; only the batch is kept. `LiveController` is what both the live page
// loop and `simulateControl` run.
import { decodeFeatures } from '../model/featureDecode';
import { noiseCorrelation, type GeneratorInfo } from '../model/generatorInfo';
import { Rng } from '../model/sampler';
import { describeValue } from '../motion/describe';
import { checkNoHoles } from '../motion/validate';
import { contactCost, lastToes, lowFootCost, particleFeatures, type ToeState } from './objective';
import { angleDifference } from './path';
import { seedStreamState, type RolloutResult, type SteerRequest, type StepFn, type Steering, type StreamState } from './rollout';
import { crossEntropySearch } from './search';

export interface ControlTarget {
  /** m/s, 0…MAX_CONTROL_SPEED. */
  speed: number;
  /** Radians, 0 faces +z, π/2 faces +x. */
  heading: number;
}

export const MAX_CONTROL_SPEED = 4;
/** Particles per round: the default (what simulateControl and the report use) and the range allowed. */
export const DEFAULT_CONTROL_PARTICLES = 24;
export const MIN_CONTROL_PARTICLES = 4;
export const MAX_CONTROL_PARTICLES = 64;
/** Frames kept per optimised batch (0.2 s at 30 fps) and frames looked at. */
export const CONTROL_BATCH = 6;
export const CONTROL_HORIZON = 12;
/** Eq. (22)'s σ_speed (m/s) and a σ for eq. (23)'s direction term (rad). */
const SPEED_SIGMA = 0.015;
const DIRECTION_SIGMA = 0.03;
const MAX_TURN_PER_FRAME = 0.15;
/**
 * σ_con for live control (m per frame): looser than the path follower's 1 cm, because with 1 cm the
 * generator's own planted-foot jitter (≈ 4 cm per frame) outweighs the speed and direction terms and
 * the character will not change pace.
 */
const LIVE_CONTACT_SIGMA = 0.01;
/**
 * σ of the low-foot term (objective.ts lowFootCost), m per frame: a foot point within 2 cm of the floor moving
 * 2 cm in a frame (0.6 m/s) costs 1. On the 8 s schedule of issue 43 (1.2 m/s, a 90° turn at 3 s), over the six
 * walk seed states (seeds 0–5, Node): lowest-foot sliding 0.190 m/s on average without it (the worst 0.388), 0.112
 * with it (0.240); skating by the contact labels 0.101 → 0.083. A σ of 1.5 cm slid 0.100 but skated 0.132 (a foot
 * held low longer, then dragged by the lock's out-of-reach legs), 2.5 cm slid 0.138; turns and pace unchanged.
 */
const LOW_FOOT_SIGMA = 0.02;
/** Input-noise draws at a quarter of σ_noise (rollout.ts noiseScale): the control terms then decide the ranking. */
const NOISE_SCALE = 0.25;
/** Achieved speed is the root's mean horizontal speed over this many frames (half a second: about a step). */
export const SPEED_WINDOW = 15;
/**
 * The best quarter of a round seeds the next (the path follower keeps an eighth): a 12-frame horizon's
 * speed and direction terms rank particles less surely than a 34-frame window's fit, so more are kept.
 */
export const CONTROL_ELITE_SHARE = 1 / 4;
/**
 * β of every perturbation, with knob jitter at full size every round (the path follower's shrink with the
 * round): a batch's latency budget allows few rounds (2 by default), so there is no long schedule to shrink.
 */
export const CONTROL_BETA = 0.5;

interface Knobs {
  /** Share of the heading error asked for per frame. */
  gain: number;
  /** Speed asked for, as a multiple of the target (the model's own pace pulls back). */
  push: number;
  /** Authority over the step (Δtx, Δtz) and over the turn (Δry); see rollout.ts. */
  authority: number;
  turnAuthority: number;
  /** Reach of a change to the step per frame, in model σ (rollout.ts); the turn has none (see below). */
  reach: number;
}

function randomKnobs(rng: Rng): Knobs {
  return { gain: 0.08 + 0.2 * rng.uniform(), push: 0.8 + 1.2 * rng.uniform(), authority: 0.3 + 0.65 * rng.uniform(), turnAuthority: 0.5 + 0.5 * rng.uniform(), reach: 0.5 + 3.5 * rng.uniform() };
}

function jitterKnobs(k: Knobs, rng: Rng): Knobs {
  return {
    gain: clamp(k.gain + 0.04 * rng.normal(), 0.03, 0.4),
    push: clamp(k.push + 0.1 * rng.normal(), 0.6, 2),
    authority: clamp(k.authority + 0.1 * rng.normal(), 0.05, 0.98),
    turnAuthority: clamp(k.turnAuthority + 0.1 * rng.normal(), 0.05, 1),
    reach: clamp(k.reach + 0.4 * rng.normal(), 0.2, 6),
  };
}

const clamp = (v: number, a: number, b: number) => Math.min(Math.max(v, a), b);

class ControlSteering implements Steering {
  constructor(
    private readonly knobs: Knobs[],
    private readonly goal: ControlTarget,
    private readonly fps: number,
  ) {}

  target(b: number, _t: number, _x: number, _z: number, heading: number, out: SteerRequest): void {
    const k = this.knobs[b];
    out.target[0] = 0;
    out.target[1] = (this.goal.speed * k.push) / this.fps;
    out.target[2] = Math.max(-MAX_TURN_PER_FRAME, Math.min(MAX_TURN_PER_FRAME, k.gain * angleDifference(this.goal.heading, heading)));
    out.authority[0] = out.authority[1] = k.authority;
    out.authority[2] = k.turnAuthority;
    // The turn is left unclipped: the model is so sure of its next heading change that a reach of even
    // 10 σ per frame kept 90° turns above 1.5 s (measured); quick turns need the steering's authority.
    out.reach[0] = out.reach[1] = k.reach;
  }
}

export interface ControlChunk {
  frames: number;
  /** frames × D, physical units. */
  features: Float32Array;
  positions: Float32Array;
  contacts: Uint8Array;
  rootHeading: Float32Array;
  /** Per frame: achieved speed (mean over the last SPEED_WINDOW frames, m/s) and facing heading (rad, wrapped to (−π, π]). */
  speed: Float32Array;
  heading: Float32Array;
  /** Milliseconds this batch took to optimise. */
  computeMs: number;
}

export interface LiveControllerOptions {
  step: StepFn;
  info: GeneratorInfo;
  mean: Float32Array;
  std: Float32Array;
  seed: number;
  seedIndex: number;
  /** Where the character starts (default the origin facing +z). */
  start?: { x: number; z: number; heading: number };
  temperature?: number;
  particles?: number;
  rounds?: number;
}

export class LiveController {
  private state: StreamState;
  private readonly rng: Rng;
  private toes: ToeState | null = null;
  /** The last committed frame's joint positions, for the low-foot term. */
  private lastPose: Float32Array | null = null;
  /** Root x, z of the last SPEED_WINDOW frames, for the achieved speed. */
  private readonly recent: [number, number][] = [];
  frame = 0;

  constructor(private readonly o: LiveControllerOptions) {
    const seed = o.info.seeds[o.seedIndex];
    if (!seed) throw new Error(`seedIndex ${o.seedIndex} is not one of the generator's ${o.info.seeds.length} seed states`);
    this.state = seedStreamState(seed, o.start ?? { x: 0, z: 0, heading: 0 });
    this.rng = new Rng(o.seed);
  }

  get root(): { x: number; z: number; heading: number } {
    return { ...this.state.root };
  }

  /**
   * Optimises and keeps the next `frames` (≤ CONTROL_HORIZON) frames toward `goal`, with `particles`
   * per round (default the controller's; the page lowers it when a batch takes longer than it lasts).
   */
  async advance(goal: ControlTarget, frames = CONTROL_BATCH, particles?: number): Promise<ControlChunk> {
    checkTarget(goal);
    if (!Number.isInteger(frames) || frames < 1 || frames > CONTROL_HORIZON) throw new RangeError(`frames must be an integer from 1 to ${CONTROL_HORIZON}, got ${describeValue(frames)}`);
    const started = performance.now();
    const { info, step, mean, std } = this.o;
    const fps = info.fps;
    const P = particles ?? this.o.particles ?? DEFAULT_CONTROL_PARTICLES, rounds = this.o.rounds ?? 2;
    if (!Number.isInteger(P) || P < MIN_CONTROL_PARTICLES || P > MAX_CONTROL_PARTICLES) {
      throw new RangeError(`particles must be an integer from ${MIN_CONTROL_PARTICLES} to ${MAX_CONTROL_PARTICLES}, got ${describeValue(P)}`);
    }
    const { result, particle: b } = await crossEntropySearch({
      rollout: { step, info, mean, std, start: this.state, temperature: this.o.temperature ?? 0.5, commit: frames, noiseScale: NOISE_SCALE, noiseCorrelation: noiseCorrelation(info) },
      particles: P,
      frames: CONTROL_HORIZON,
      rounds,
      eliteShare: CONTROL_ELITE_SHARE,
      beta: () => CONTROL_BETA,
      rng: this.rng,
      randomKnobs,
      jitterKnobs: (k, _round, rng) => jitterKnobs(k, rng),
      steering: (knobs) => new ControlSteering(knobs, goal, fps),
      cost: (r, b) => r.priorCost[b] + r.noiseCost[b] + controlCost(r, b, goal, this.state.root, fps) + contactCost(info, particleFeatures(r, b), this.state.root, this.toes, LIVE_CONTACT_SIGMA) +
        lowFootCost(info, particleFeatures(r, b), this.state.root, LOW_FOOT_SIGMA, this.lastPose),
    });
    const features = particleFeatures(result, b, frames).slice();
    const decoded = decodeFeatures(info, features, this.state.root);
    this.toes = lastToes(info, decoded.positions, decoded.contacts);
    this.state = result.states[b];
    const J = info.skeleton.joints.length;
    this.lastPose = decoded.positions.slice((frames - 1) * J * 3, frames * J * 3);
    const speed = new Float32Array(frames), heading = new Float32Array(frames);
    for (let f = 0; f < frames; f++) {
      const here: [number, number] = [decoded.positions[f * J * 3], decoded.positions[f * J * 3 + 2]];
      this.recent.push(here);
      if (this.recent.length > SPEED_WINDOW + 1) this.recent.shift();
      const first = this.recent[0];
      const span = this.recent.length - 1;
      speed[f] = span ? (Math.hypot(here[0] - first[0], here[1] - first[1]) * fps) / span : 0;
      heading[f] = angleDifference(decoded.rootHeading[f], 0);
    }
    this.frame += frames;
    return { frames, features, positions: decoded.positions, contacts: decoded.contacts, rootHeading: decoded.rootHeading, speed, heading, computeMs: performance.now() - started };
  }
}

export function checkTarget(goal: ControlTarget): void {
  if (typeof goal?.speed !== 'number' || !Number.isFinite(goal.speed) || goal.speed < 0 || goal.speed > MAX_CONTROL_SPEED) {
    throw new RangeError(`speed must be a number from 0 to ${MAX_CONTROL_SPEED} m/s, got ${describeValue(goal?.speed)}`);
  }
  if (typeof goal.heading !== 'number' || !Number.isFinite(goal.heading)) throw new RangeError(`heading must be a finite number of radians, got ${describeValue(goal.heading)}`);
}

/** Eqs. (22) and (23): mean horizontal speed over the horizon vs the goal, last frame's facing vs the goal. */
function controlCost(r: RolloutResult, b: number, goal: ControlTarget, start: { x: number; z: number }, fps: number): number {
  const last = (b * r.T + r.T - 1) * 3;
  // Path length rather than displacement, so a turning walker is not taken for a slow one.
  let travelled = 0, px = start.x, pz = start.z;
  for (let t = 0; t < r.T; t++) {
    const i = (b * r.T + t) * 3;
    travelled += Math.hypot(r.roots[i] - px, r.roots[i + 1] - pz);
    px = r.roots[i];
    pz = r.roots[i + 1];
  }
  const speed = (travelled * fps) / r.T;
  const direction = angleDifference(r.roots[last + 2], goal.heading);
  return ((speed - goal.speed) / SPEED_SIGMA) ** 2 + (direction / DIRECTION_SIGMA) ** 2;
}

export interface ScheduleEntry extends ControlTarget {
  /** Seconds from the start at which this target takes over. */
  t: number;
}

/** Checks a control schedule: a non-empty list of { t, speed, heading }, t ≥ 0 and increasing, the first at t = 0. */
export function checkSchedule(schedule: unknown): ScheduleEntry[] {
  if (!Array.isArray(schedule) || schedule.length === 0) throw new TypeError(`schedule must be a non-empty array of { t, speed, heading }, got ${describeValue(schedule)}`);
  checkNoHoles(schedule, 'schedule');
  return schedule.map((e, i) => {
    if (typeof e !== 'object' || e === null) throw new TypeError(`schedule[${i}] must be an object { t, speed, heading }, got ${describeValue(e)}`);
    const { t, speed, heading } = e as Record<string, unknown>;
    if (typeof t !== 'number' || !Number.isFinite(t) || t < 0) throw new RangeError(`schedule[${i}].t must be a number of seconds ≥ 0, got ${describeValue(t)}`);
    if (i === 0 && t !== 0) throw new RangeError(`schedule[0].t must be 0 (the target at the start), got ${describeValue(t)}`);
    if (i > 0 && t <= (schedule[i - 1] as ScheduleEntry).t) throw new RangeError(`schedule[${i}].t (${t}) must be later than schedule[${i - 1}].t`);
    try {
      checkTarget({ speed, heading } as ControlTarget);
    } catch (err) {
      throw new RangeError(`schedule[${i}].${(err as Error).message}`);
    }
    return { t, speed: speed as number, heading: heading as number };
  });
}

export interface SimulatedControl {
  chunks: ControlChunk[];
  /** Every frame's target, for the report. */
  targets: ControlTarget[];
}

/**
 * The live loop driven by a script: every batch optimises toward the schedule's target in force at the
 * batch's first frame, exactly as the page does with the user's input at that moment.
 */
export async function simulateControl(controller: LiveController, schedule: ScheduleEntry[], seconds: number, fps: number, onProgress?: (fraction: number) => void): Promise<SimulatedControl> {
  // At least one frame: every accepted length (any seconds above 0) gives a motion show and exportBVH take.
  const total = Math.max(1, Math.round(seconds * fps));
  const chunks: ControlChunk[] = [];
  const targets: ControlTarget[] = [];
  let done = 0;
  while (done < total) {
    const now = done / fps;
    const goal = [...schedule].reverse().find((e) => e.t <= now + 1e-9) ?? schedule[0];
    const chunk = await controller.advance({ speed: goal.speed, heading: goal.heading }, Math.min(CONTROL_BATCH, total - done));
    chunks.push(chunk);
    for (let f = 0; f < chunk.frames; f++) targets.push({ speed: goal.speed, heading: goal.heading });
    done += chunk.frames;
    onProgress?.(done / total);
  }
  return { chunks, targets };
}
