// A batch of particles run through the generator together (one ONNX call per frame for all of them).
// Each particle's frame is a MAP choice under the model, not a free draw: the sampling variables
// (component choice u, per-dimension normal z, input noise d; Wang, Chai, Xia §5.2) give the model's
// proposal, then the root channels (Δtx, Δtz, Δry) are moved toward a steering target by the closed-form
// maximum of  N(x; proposal, σ²) · N(target; x, q²)  — the product of the model's component and a
// quadratic control term, x = proposal + a·(target − proposal) with a = σ²/(σ² + q²). The steering
// states a directly (its "authority" per channel), which fixes q relative to the model's own σ, and a
// reach: the move is clipped to that many model σ, because the model is sure of its next root step (σ
// of a few cm/s) and a change of pace has to be spread over many frames to stay likely. The window objective (prior NLL, noise prior, control and contact terms)
// then ranks whole particles.
import { integrateRoot, type RootStart } from '../model/featureDecode';
import type { GeneratorInfo, GeneratorSeed, StepOutputs } from '../model/generatorInfo';
import { chooseComponent, denormalise, heldNormal, snapContacts } from '../model/sampler';
import { repeatState, stateRow } from '../model/lstmState';

/**
 * The root channels Δtx, Δtz, Δry, which steering moves (steerRoot). Their normals are drawn fresh every frame even
 * when the pose's are held: a held root normal carries the last frames' step into the proposal and slows a change
 * of pace (measured with 5 seeds a case in control.md: held everywhere, one of 10 speed changes missed 0.2 m/s
 * after 1 s, and the lowest foot point slid 0.229 m/s against 0.199).
 */
const STEERED_CHANNELS = 3;

/** The paper's input-noise prior: d ~ N(0, 0.05²) on the normalised network input (eq. 16). */
export const INPUT_NOISE_SIGMA = 0.05;
const LOG_2PI = Math.log(2 * Math.PI);

/** One model step of `batch` rows; `frame`: which frame of the rollout it makes (0 = the first after the start state), where known. */
export type StepFn = (batch: number, x: Float32Array, h: Float32Array, c: Float32Array, frame?: number) => Promise<StepOutputs>;

/**
 * Where one stream stands: the next network input (normalised), the LSTM state, the root on the ground, and the
 * normals its last frame was drawn with (held over frames as the sampler holds them; absent before the first frame).
 */
export interface StreamState {
  x: Float32Array;
  h: Float32Array;
  c: Float32Array;
  root: RootStart;
  held?: Float64Array;
}

/** A stream at `root` from one of the generator's seed states (copied, so the seed stays as it is). */
export function seedStreamState(seed: GeneratorSeed, root: RootStart): StreamState {
  return { x: Float32Array.from(seed.x), h: Float32Array.from(seed.h), c: Float32Array.from(seed.c), root: { ...root } };
}

/** The sampling variables of P particles over T frames. */
export interface Variables {
  P: number;
  T: number;
  /** P×T uniforms choosing the mixture component. */
  u: Float64Array;
  /**
   * P×T×D standard normals for the component's draw: with a noise correlation ρ those of the pose channels are the
   * innovations of held normals (frame t draws with ρ·previous + √(1−ρ²)·z), so every variable keeps its N(0, 1) prior.
   */
  z: Float32Array;
  /** P×T×D standard normals; the input noise is INPUT_NOISE_SIGMA times these. */
  d: Float32Array;
}

/** What steering asks of one frame's root channels Δtx, Δtz (m, previous frame's heading frame), Δry (rad). */
export interface SteerRequest {
  target: Float64Array;
  /** 0 leaves a channel to the model, 1 imposes the target. */
  authority: Float64Array;
  /** Largest move from the model's proposal, in the chosen component's σ (Infinity: no limit). */
  reach: Float64Array;
}

export interface Steering {
  /** Fills `out` for particle b's frame t; (x, z, heading) is where the particle stands before it. */
  target(b: number, t: number, x: number, z: number, heading: number, out: SteerRequest): void;
}

export interface RolloutResult {
  P: number;
  T: number;
  /** P×T×D frames in physical units. */
  features: Float32Array;
  /** P×T×3 root after each frame: x, z, heading (unwrapped). */
  roots: Float64Array;
  /** Per particle: Σ mixture NLL (normalised units) and Σ input-noise prior, over the frames. */
  priorCost: Float64Array;
  noiseCost: Float64Array;
  /** Per particle, the stream state after frame `commit` − 1 (to continue from). */
  states: StreamState[];
}

export interface RolloutOptions {
  step: StepFn;
  info: GeneratorInfo;
  mean: Float32Array;
  std: Float32Array;
  start: StreamState;
  variables: Variables;
  steering: Steering;
  /** Sampling temperature for the proposal (scales σ and sharpens the weights, as in the sampler). */
  temperature: number;
  /** Frames after which each particle's state is kept (1…T). */
  commit: number;
  /**
   * Scale of the input-noise draws (default 1: d = σ_noise·N(0, 1)). Below 1 the search explores closer
   * to the noise prior's mode: with hundreds of noise dimensions per particle, full-size draws make the
   * noise term's spread across particles (σ ≈ 20 over 12 frames) swamp the control terms.
   */
  noiseScale?: number;
  /**
   * ρ of the normals held over frames (generator.json sampling.noise_correlation; default 0, fresh every frame), so
   * optimised motion is drawn the way free generation draws it; the held normals carry over from `start.held`.
   */
  noiseCorrelation?: number;
}

/**
 * MAP of the root channels (normalised `row`) under proposal × control: the precision-weighted blend,
 * in physical units, its move clipped to `reach` of the chosen component's σ.
 */
function steerRoot(row: Float32Array, sigma: Float32Array, request: SteerRequest, mean: Float32Array, std: Float32Array): void {
  for (let k = 0; k < STEERED_CHANNELS; k++) {
    const proposal = row[k] * std[k] + mean[k];
    const limit = request.reach[k] * sigma[k] * std[k];
    const move = Math.max(-limit, Math.min(limit, request.authority[k] * (request.target[k] - proposal)));
    row[k] = (proposal + move - mean[k]) / std[k];
  }
}

/** −log density of `row` (normalised units) under batch row b's full mixture; `logp` is M values of scratch. */
function mixtureNll(out: StepOutputs, b: number, row: Float32Array, M: number, D: number, logp: Float64Array): number {
  let best = -Infinity;
  for (let k = 0; k < M; k++) {
    const m = out.mu.subarray((b * M + k) * D, (b * M + k + 1) * D);
    const sg = out.sigma.subarray((b * M + k) * D, (b * M + k + 1) * D);
    let lp = Math.log(Math.max(out.weights[b * M + k], 1e-30));
    for (let q = 0; q < D; q++) {
      const e = (row[q] - m[q]) / sg[q];
      lp -= Math.log(sg[q]) + 0.5 * e * e;
    }
    logp[k] = lp;
    best = Math.max(best, lp);
  }
  let sum = 0;
  for (let k = 0; k < M; k++) sum += Math.exp(logp[k] - best);
  return -(best + Math.log(sum)) + 0.5 * D * LOG_2PI;
}

/** Runs all particles for T frames from the same start state. */
export async function rollout(o: RolloutOptions): Promise<RolloutResult> {
  const { info, mean, std, variables: v, steering, temperature, commit } = o;
  const { P, T } = v;
  const { layers: L, hidden: H, mixtures: M, dim: D } = info.onnx;
  if (!(commit >= 1 && commit <= T)) throw new Error(`rollout: commit ${commit} is outside 1…${T}`);
  const tau = Math.max(temperature, 1e-3);
  const noiseScale = o.noiseScale ?? 1;
  const rho = o.noiseCorrelation ?? 0;
  if (!(rho >= 0 && rho < 1)) throw new Error(`rollout: noise correlation ${rho} is outside [0, 1)`);
  // Each particle's normals of its previous frame (all the start's to begin with), once there is a previous frame.
  const held = new Float64Array(rho > 0 ? P * D : 0);
  let holding = false;
  if (rho > 0 && o.start.held) {
    if (o.start.held.length !== D) throw new Error(`rollout: the start holds ${o.start.held.length} normals, expected ${D}`);
    for (let b = 0; b < P; b++) held.set(o.start.held, b * D);
    holding = true;
  }
  const drawn = new Float64Array(P * D);

  // Every particle starts from the same state.
  let h = repeatState(o.start.h, L, P, H), c = repeatState(o.start.c, L, P, H);
  const x = new Float32Array(P * D);
  for (let b = 0; b < P; b++) x.set(o.start.x, b * D);
  const input = new Float32Array(P * D);
  const features = new Float32Array(P * T * D);
  const roots = new Float64Array(P * T * 3);
  const root: RootStart[] = Array.from({ length: P }, () => ({ ...o.start.root }));
  const priorCost = new Float64Array(P);
  const noiseCost = new Float64Array(P);
  const states: StreamState[] = [];
  const request: SteerRequest = { target: new Float64Array(3), authority: new Float64Array(3), reach: new Float64Array(3).fill(Infinity) };
  const scratch = new Float64Array(M);
  const logp = new Float64Array(M);

  for (let t = 0; t < T; t++) {
    for (let b = 0; b < P; b++) {
      const dz = v.d.subarray((b * T + t) * D, (b * T + t + 1) * D);
      let n2 = 0;
      for (let k = 0; k < D; k++) {
        input[b * D + k] = x[b * D + k] + INPUT_NOISE_SIGMA * noiseScale * dz[k];
        n2 += dz[k] * dz[k];
      }
      noiseCost[b] += 0.5 * noiseScale * noiseScale * n2; // = Σ d²/(2σ²) with d = σ·noiseScale·dz
    }
    const out = await o.step(P, input, h, c, t);
    for (let b = 0; b < P; b++) {
      const w = out.weights.subarray(b * M, (b + 1) * M);
      const comp = chooseComponent(w, tau, v.u[b * T + t], scratch);
      const mu = out.mu.subarray((b * M + comp) * D, (b * M + comp + 1) * D);
      const sigma = out.sigma.subarray((b * M + comp) * D, (b * M + comp + 1) * D);
      const zz = v.z.subarray((b * T + t) * D, (b * T + t + 1) * D);
      const row = x.subarray(b * D, (b + 1) * D);
      const normals = drawn.subarray(b * D, (b + 1) * D);
      for (let k = 0; k < D; k++) {
        normals[k] = holding && k >= STEERED_CHANNELS ? heldNormal(held[b * D + k], zz[k], rho) : zz[k];
        row[k] = mu[k] + sigma[k] * temperature * normals[k];
      }

      steering.target(b, t, root[b].x, root[b].z, root[b].heading, request);
      steerRoot(row, sigma, request, mean, std);
      // Contacts are bits, as in free generation.
      snapContacts(row, D, mean, std);
      // Prior: the chosen frame's NLL under the full (untempered) mixture.
      priorCost[b] += mixtureNll(out, b, row, M, D, logp);

      // Physical frame and root integration.
      const f = (b * T + t) * D;
      denormalise(row, mean, std, features.subarray(f, f + D));
      integrateRoot(root[b], features[f], features[f + 1], features[f + 2]);
      roots.set([root[b].x, root[b].z, root[b].heading], (b * T + t) * 3);
    }
    h = out.h_out;
    c = out.c_out;
    if (rho > 0) {
      held.set(drawn);
      holding = true;
    }
    if (t === commit - 1) {
      for (let b = 0; b < P; b++) {
        states.push({
          x: x.slice(b * D, (b + 1) * D),
          h: stateRow(h, L, P, H, b),
          c: stateRow(c, L, P, H, b),
          root: { ...root[b] },
          ...(holding ? { held: held.slice(b * D, (b + 1) * D) } : {}),
        });
      }
    }
  }
  return { P, T, features, roots, priorCost, noiseCost, states };
}
