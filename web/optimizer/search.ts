// The cross-entropy search the path follower and live control share (Wang, Chai, Xia §5.2–5.3): a round
// runs every particle — sampling variables plus the caller's steering knobs — through one batched rollout
// and ranks them by the caller's cost; the next round's particles are perturbations of the best few
// (the elites keep their knobs, the rest get jittered copies). The best particle of all rounds wins.
import type { Rng } from '../model/sampler';
import { rollout, type RolloutOptions, type RolloutResult, type Steering, type Variables } from './rollout';

export interface SearchOptions<Knobs> {
  /** Everything the rollout needs but what the search chooses: the particles' variables and steering. */
  rollout: Omit<RolloutOptions, 'variables' | 'steering'>;
  particles: number;
  /** Frames each particle runs. */
  frames: number;
  rounds: number;
  /** Share of a round's particles that seed the next (at least one). */
  eliteShare: number;
  /** β of the perturbation (perturbInto) that makes round `round` + 1 out of round `round`'s elites. */
  beta: (round: number) => number;
  rng: Rng;
  randomKnobs: (rng: Rng) => Knobs;
  /** Knobs for a non-elite particle of round `round` + 1, from its elite's. */
  jitterKnobs: (knobs: Knobs, round: number, rng: Rng) => Knobs;
  steering: (knobs: Knobs[]) => Steering;
  /** Cost of particle b of a round's rollout; lower is better, and a non-finite cost counts as Infinity. */
  cost: (result: RolloutResult, b: number) => number;
}

export interface SearchResult {
  /** The rollout the best particle came from, its index there and its cost. */
  result: RolloutResult;
  particle: number;
  cost: number;
  /** Generator evaluations (particles × frames) spent. */
  particleSteps: number;
}

export async function crossEntropySearch<Knobs>(o: SearchOptions<Knobs>): Promise<SearchResult> {
  const { particles: P, frames: T, rng } = o;
  const D = o.rollout.info.onnx.dim;
  const elites = Math.max(1, Math.round(P * o.eliteShare));
  let variables = randomVariables(P, T, D, rng);
  let knobs = Array.from({ length: P }, () => o.randomKnobs(rng));
  let best: SearchResult | null = null;
  for (let round = 0; round < o.rounds; round++) {
    const result = await rollout({ ...o.rollout, variables, steering: o.steering(knobs) });
    const costs = new Float64Array(P);
    for (let b = 0; b < P; b++) {
      costs[b] = o.cost(result, b);
      if (!Number.isFinite(costs[b])) costs[b] = Infinity;
      if (!best || costs[b] < best.cost) best = { result, particle: b, cost: costs[b], particleSteps: 0 };
    }
    if (round === o.rounds - 1) break;
    // Next round: every particle a perturbation of one of the elites.
    const top = lowest(costs, elites);
    const beta = o.beta(round);
    const next: Variables = { P, T, u: new Float64Array(P * T), z: new Float32Array(P * T * D), d: new Float32Array(P * T * D) };
    knobs = Array.from({ length: P }, (_, b) => {
      const from = top[b % top.length];
      perturbInto(variables, from, next, b, beta, rng, D);
      return b < top.length ? knobs[from] : o.jitterKnobs(knobs[from], round, rng);
    });
    variables = next;
  }
  if (!best) throw new Error('crossEntropySearch: no particle was evaluated (rounds must be at least 1)');
  best.particleSteps = o.rounds * P * T;
  return best;
}

/** Indices of the `count` lowest costs, best first. */
export function lowest(costs: ArrayLike<number>, count: number): number[] {
  return Array.from(costs, (_, i) => i)
    .sort((a, b) => costs[a] - costs[b])
    .slice(0, count);
}

export function randomVariables(P: number, T: number, D: number, rng: Rng): Variables {
  const v: Variables = { P, T, u: new Float64Array(P * T), z: new Float32Array(P * T * D), d: new Float32Array(P * T * D) };
  for (let i = 0; i < v.u.length; i++) v.u[i] = rng.uniform();
  for (let i = 0; i < v.z.length; i++) v.z[i] = rng.normal();
  for (let i = 0; i < v.d.length; i++) v.d[i] = rng.normal();
  return v;
}

/**
 * Particle `to` becomes a perturbation of particle `from` of `source` (preconditioned Crank–Nicolson:
 * √(1−β²)·old + β·new keeps the N(0, 1) prior; β = 1 is a fresh draw, small β a local move).
 * Component choices are redrawn with probability β².
 */
export function perturbInto(source: Variables, from: number, target: Variables, to: number, beta: number, rng: Rng, D: number): void {
  const T = source.T;
  const keep = Math.sqrt(1 - beta * beta);
  for (let t = 0; t < T; t++) {
    const i = from * T + t, j = to * T + t;
    target.u[j] = rng.uniform() < beta * beta ? rng.uniform() : source.u[i];
  }
  const n = T * D;
  const a = from * n, b = to * n;
  for (let k = 0; k < n; k++) {
    target.z[b + k] = keep * source.z[a + k] + beta * rng.normal();
    target.d[b + k] = keep * source.d[a + k] + beta * rng.normal();
  }
}
