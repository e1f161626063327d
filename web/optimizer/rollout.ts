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
import type { GeneratorInfo, StepOutputs } from '../model/generatorInfo';
import type { Rng } from '../model/sampler';

/** The paper's input-noise prior: d ~ N(0, 0.05²) on the normalised network input (eq. 16). */
export const INPUT_NOISE_SIGMA = 0.05;
const LOG_2PI = Math.log(2 * Math.PI);

export type StepFn = (batch: number, x: Float32Array, h: Float32Array, c: Float32Array) => Promise<StepOutputs>;

/** Where one stream stands: the next network input (normalised), the LSTM state, the root on the ground. */
export interface StreamState {
  x: Float32Array;
  h: Float32Array;
  c: Float32Array;
  root: { x: number; z: number; heading: number };
}

/** The sampling variables of P particles over T frames. */
export interface Variables {
  P: number;
  T: number;
  /** P×T uniforms choosing the mixture component. */
  u: Float64Array;
  /** P×T×D standard normals for the component's draw. */
  z: Float32Array;
  /** P×T×D standard normals; the input noise is INPUT_NOISE_SIGMA times these. */
  d: Float32Array;
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
}

/** Copies one batch row of the L×B×H state layout. */
function stateRow(src: Float32Array, L: number, B: number, H: number, b: number): Float32Array {
  const out = new Float32Array(L * H);
  for (let l = 0; l < L; l++) out.set(src.subarray((l * B + b) * H, (l * B + b + 1) * H), l * H);
  return out;
}

/** Runs all particles for T frames from the same start state. */
export async function rollout(o: RolloutOptions): Promise<RolloutResult> {
  const { info, mean, std, variables: v, steering, temperature, commit } = o;
  const { P, T } = v;
  const { layers: L, hidden: H, mixtures: M, dim: D } = info.onnx;
  if (!(commit >= 1 && commit <= T)) throw new Error(`rollout: commit ${commit} is outside 1…${T}`);
  const tau = Math.max(temperature, 1e-3);
  const noiseScale = o.noiseScale ?? 1;

  // Every particle starts from the same state.
  let h: Float32Array = new Float32Array(L * P * H), c: Float32Array = new Float32Array(L * P * H);
  for (let l = 0; l < L; l++) {
    for (let b = 0; b < P; b++) {
      h.set(o.start.h.subarray(l * H, (l + 1) * H), (l * P + b) * H);
      c.set(o.start.c.subarray(l * H, (l + 1) * H), (l * P + b) * H);
    }
  }
  const x = new Float32Array(P * D);
  for (let b = 0; b < P; b++) x.set(o.start.x, b * D);
  const input = new Float32Array(P * D);
  const features = new Float32Array(P * T * D);
  const roots = new Float64Array(P * T * 3);
  const rx = new Float64Array(P).fill(o.start.root.x);
  const rz = new Float64Array(P).fill(o.start.root.z);
  const rh = new Float64Array(P).fill(o.start.root.heading);
  const priorCost = new Float64Array(P);
  const noiseCost = new Float64Array(P);
  const states: StreamState[] = [];
  const request: SteerRequest = { target: new Float64Array(3), authority: new Float64Array(3), reach: new Float64Array(3).fill(Infinity) };
  const weightsTemp = new Float64Array(M);
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
    const out = await o.step(P, input, h, c);
    for (let b = 0; b < P; b++) {
      const w = out.weights.subarray(b * M, (b + 1) * M);
      // Component: k with probability ∝ w^(1/τ), chosen by this particle's uniform.
      let largest = -Infinity;
      for (let k = 0; k < M; k++) largest = Math.max(largest, (weightsTemp[k] = Math.log(Math.max(w[k], 1e-12)) / tau));
      let total = 0;
      for (let k = 0; k < M; k++) total += weightsTemp[k] = Math.exp(weightsTemp[k] - largest);
      let u = v.u[b * T + t] * total, comp = M - 1;
      for (let k = 0; k < M; k++) {
        u -= weightsTemp[k];
        if (u < 0) {
          comp = k;
          break;
        }
      }
      const mu = out.mu.subarray((b * M + comp) * D, (b * M + comp + 1) * D);
      const sigma = out.sigma.subarray((b * M + comp) * D, (b * M + comp + 1) * D);
      const zz = v.z.subarray((b * T + t) * D, (b * T + t + 1) * D);
      const row = x.subarray(b * D, (b + 1) * D);
      for (let k = 0; k < D; k++) row[k] = mu[k] + sigma[k] * temperature * zz[k];

      // MAP of the root channels under proposal × control: precision-weighted blend, in physical units.
      steering.target(b, t, rx[b], rz[b], rh[b], request);
      for (let k = 0; k < 3; k++) {
        const proposal = row[k] * std[k] + mean[k];
        const limit = request.reach[k] * sigma[k] * std[k];
        const move = Math.max(-limit, Math.min(limit, request.authority[k] * (request.target[k] - proposal)));
        row[k] = (proposal + move - mean[k]) / std[k];
      }
      // Contacts are bits, as in free generation.
      for (let k = D - 2; k < D; k++) row[k] = ((row[k] * std[k] + mean[k] > 0.5 ? 1 : 0) - mean[k]) / std[k];

      // Prior: the chosen frame's NLL under the full (untempered) mixture.
      let best = -Infinity;
      for (let k = 0; k < M; k++) {
        const m = out.mu.subarray((b * M + k) * D, (b * M + k + 1) * D);
        const sg = out.sigma.subarray((b * M + k) * D, (b * M + k + 1) * D);
        let lp = Math.log(Math.max(w[k], 1e-30));
        for (let q = 0; q < D; q++) {
          const e = (row[q] - m[q]) / sg[q];
          lp -= Math.log(sg[q]) + 0.5 * e * e;
        }
        logp[k] = lp;
        best = Math.max(best, lp);
      }
      let sum = 0;
      for (let k = 0; k < M; k++) sum += Math.exp(logp[k] - best);
      priorCost[b] += -(best + Math.log(sum)) + 0.5 * D * LOG_2PI;

      // Physical frame and root integration (as featureDecode.ts).
      const f = (b * T + t) * D;
      for (let k = 0; k < D; k++) features[f + k] = row[k] * std[k] + mean[k];
      const cs = Math.cos(rh[b]), sn = Math.sin(rh[b]);
      rx[b] += cs * features[f] + sn * features[f + 1];
      rz[b] += -sn * features[f] + cs * features[f + 1];
      rh[b] += features[f + 2];
      const r = (b * T + t) * 3;
      roots[r] = rx[b];
      roots[r + 1] = rz[b];
      roots[r + 2] = rh[b];
    }
    h = out.h_out;
    c = out.c_out;
    if (t === commit - 1) {
      for (let b = 0; b < P; b++) {
        states.push({
          x: x.slice(b * D, (b + 1) * D),
          h: stateRow(h, L, P, H, b),
          c: stateRow(c, L, P, H, b),
          root: { x: rx[b], z: rz[b], heading: rh[b] },
        });
      }
    }
  }
  return { P, T, features, roots, priorCost, noiseCost, states };
}
