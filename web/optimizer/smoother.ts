// Motion denoising as MAP under the generator (Wang, Chai, Xia §5.4, eq. 24), by an extended Kalman smoother.
//
// The state is one frame's feature row (normalised, contacts aside). The generator is the dynamics: given the
// cleaned previous frame it proposes a Gaussian mixture for the next; the chosen component's mean is the prediction
// and its σ the process noise, and the prediction's dependence on the previous frame (its Jacobian, by finite
// differences in one batched ONNX call) carries the uncertainty forward. The observation is what was captured:
// each canonical joint's world position with Gaussian noise σ_j (eq. 25's root and joint terms, measured where the
// noise is, on positions: a rotation read from noisy positions is far noisier than the positions, most of all for
// short segments). Forward, each frame is the Gauss–Newton MAP of prediction × observation (twice relinearised);
// a joint whose innovation is beyond OUTLIER_Z is discounted (Huber), so glitches do not drag the pose. Backward, a
// Rauch–Tung–Striebel pass lets every frame use the frames after it, so the result is the smoothed MAP of the whole
// motion, not a filter that lags. Contacts come from the chosen components (the input is unlabelled).
//
// Beyond the paper, the prior is the generator's prediction times a constant-velocity guess (a product of the two
// Gaussians): on held-out capture the generator alone predicts the next frame several centimetres off, and used alone
// it left the motion as jerky as its observations (docs/models/cleanup.md).
import { framePoser, type RootStart } from '../model/featureDecode';
import type { GeneratorInfo } from '../model/generatorInfo';
import { setStateRow, stateRow } from '../model/lstmState';
import { cholesky, choleskySolve, inverseSPD, matmul, sandwich, transpose } from './linalg';
import type { StepFn } from './rollout';

/** Innovation (in its predicted σ) beyond which a joint's observation is discounted. */
export const OUTLIER_Z = 3;
/** Finite-difference steps, normalised units: the generator's input, and the observation's linearisation. */
const DYNAMICS_STEP = 1e-2;
const OBSERVATION_STEP = 1e-3;
/** Gauss–Newton iterations of each frame's update. */
const UPDATE_ITERATIONS = 2;
/** σ (normalised feature units) of the constant-velocity guess's own error, beside the uncertainty it inherits. */
const CONSTANT_VELOCITY_SIGMA = 0.05;
/** Frames between two evaluations of the generator's Jacobian (each costs one call of batch D − 1). */
const JACOBIAN_EVERY = 3;
/** Prior spread (normalised) of the first frame around its observed encoding. */
const FIRST_FRAME_SIGMA = 0.5;

export interface SmootherInput {
  step: StepFn;
  info: GeneratorInfo;
  mean: ArrayLike<number>;
  std: ArrayLike<number>;
  /** frames × 25 × 3 observed canonical points (world, floor at y = 0), at the model's fps. */
  points: Float32Array;
  /** Per canonical point, σ of its observation (m). */
  sigma: ArrayLike<number>;
  /** frames × D observed feature rows (featureEncode.encodeFeatures). */
  encoded: Float32Array;
  /** Where the root stands after each frame (the observed hips' ground track and heading, smoothed), and before frame 0. */
  rootTrack: RootStart[];
  start: RootStart;
  /** joints × 3 offsets to decode with (the clip's own segment lengths). */
  offsets: ArrayLike<number>;
  onFrame?: (frame: number, frames: number) => void;
  /** A cancellation checkpoint, awaited between frames where no model step is (frame 0's update, the backward pass): it throws to stop. */
  pause?: () => Promise<void>;
}

export interface SmootherResult {
  /** frames × D physical feature rows of the smoothed motion; contacts 0/1 from the model. */
  features: Float32Array;
  seedIndex: number;
  /** Share of joint observations discounted as outliers. */
  outlierShare: number;
}

export async function smoothFeatures(a: SmootherInput): Promise<SmootherResult> {
  const { step, info, mean, std, points, sigma, encoded, offsets, rootTrack } = a;
  const { dim: D, mixtures: M, layers: L, hidden: H } = info.onnx;
  const n = D - 2; // the state: every feature but the contact bits
  const K = info.skeleton.joints.length;
  const m = K * 3;
  const frames = points.length / m;
  const wide = n + 1; // the prediction and one perturbed input per state dimension

  const normalise = (phys: ArrayLike<number>, out = new Float64Array(D)) => {
    for (let d = 0; d < D; d++) out[d] = (phys[d] - mean[d]) / std[d];
    return out;
  };
  const pose = framePoser(info, offsets);
  const row = new Float64Array(D);
  /** World positions (m values) of state `z` (normalised, D or n values) stepped from `root`. */
  const observe = (z: ArrayLike<number>, root: RootStart) => {
    for (let d = 0; d < D; d++) row[d] = (d < z.length ? z[d] : 0) * std[d] + mean[d];
    return pose(row, root);
  };

  // The seed state whose first frame is nearest the motion's first frame.
  const first = normalise(encoded.subarray(0, D));
  let seedIndex = 0, nearest = Infinity;
  info.seeds.forEach((s, i) => {
    let d2 = 0;
    for (let d = 4; d < n; d++) d2 += (s.x[d] - first[d]) ** 2;
    if (d2 < nearest) [nearest, seedIndex] = [d2, i];
  });
  const seed = info.seeds[seedIndex];
  // The stream's LSTM state (layers × hidden), repeated over a call's batch.
  let hRow: Float32Array = Float32Array.from(seed.h);
  let cRow: Float32Array = Float32Array.from(seed.c);

  const R = new Float64Array(m);
  for (let k = 0; k < K; k++) for (let i = 0; i < 3; i++) R[k * 3 + i] = Math.max(1e-6, sigma[k] ** 2);

  // Forward pass: filtered means and covariances, predictions and their covariances, dynamics Jacobians.
  const xf: Float64Array[] = [], Pf: Float64Array[] = [], xp: Float64Array[] = [], Pp: Float64Array[] = [], F: Float64Array[] = [];
  const contactRows: Float64Array[] = [];
  let discounted = 0, observations = 0;

  /** Gauss–Newton MAP of N(prior, P) × the frame's observation; returns the mean and covariance. */
  const update = (prior: Float64Array, P: Float64Array, f: number, root: RootStart, Pinv = inverseSPD(P, n)): { x: Float64Array; cov: Float64Array } => {
    let x: Float64Array = Float64Array.from(prior);
    let cov: Float64Array = P;
    const obs = points.subarray(f * m, (f + 1) * m);
    for (let it = 0; it < UPDATE_ITERATIONS; it++) {
      const base = Float32Array.from(observe(x, root)); // observe reuses its buffer
      const Hm = new Float64Array(m * n);
      for (let d = 0; d < n; d++) {
        const z = Float64Array.from(x);
        z[d] += OBSERVATION_STEP;
        const moved = observe(z, root);
        for (let i = 0; i < m; i++) Hm[i * n + d] = (moved[i] - base[i]) / OBSERVATION_STEP;
      }
      // Per joint: innovation against its predicted spread; a glitch widens that joint's noise (Huber).
      const HP = matmul(Hm, P, m, n, n);
      const r = Float64Array.from(R);
      let flagged = 0;
      for (let k = 0; k < K; k++) {
        let z2 = 0;
        for (let i = k * 3; i < k * 3 + 3; i++) {
          let s = R[i];
          for (let d = 0; d < n; d++) s += HP[i * n + d] * Hm[i * n + d];
          z2 += (obs[i] - base[i]) ** 2 / s;
        }
        const z = Math.sqrt(z2 / 3);
        if (z > OUTLIER_Z) {
          flagged++;
          for (let i = k * 3; i < k * 3 + 3; i++) r[i] *= (z / OUTLIER_Z) ** 2;
        }
      }
      if (it === UPDATE_ITERATIONS - 1) {
        discounted += flagged;
        observations += K;
      }
      // Information form: (P⁻¹ + Hᵀ R⁻¹ H) x = P⁻¹ prior + Hᵀ R⁻¹ (obs − h(x) + H x).
      const Ht = transpose(Hm, m, n);
      const A = Float64Array.from(Pinv);
      const rhs = matmul(Pinv, prior, n, n, 1);
      for (let i = 0; i < m; i++) {
        const w = 1 / r[i];
        let hx = 0;
        for (let d = 0; d < n; d++) hx += Hm[i * n + d] * x[d];
        const y = (obs[i] - base[i] + hx) * w;
        for (let d = 0; d < n; d++) rhs[d] += Ht[d * m + i] * y;
      }
      for (let d = 0; d < n; d++) {
        for (let e = 0; e <= d; e++) {
          let s = 0;
          for (let i = 0; i < m; i++) s += Ht[d * m + i] * Ht[e * m + i] / r[i];
          A[d * n + e] += s;
          if (e !== d) A[e * n + d] += s;
        }
      }
      const l = cholesky(A, n);
      x = choleskySolve(l, rhs, n);
      if (it === UPDATE_ITERATIONS - 1) cov = inverseSPD(A, n);
    }
    return { x, cov };
  };

  // Frame 0: its own observation with a broad prior around its encoding.
  const root0: RootStart = { ...a.start };
  const P0 = new Float64Array(n * n);
  for (let d = 0; d < n; d++) P0[d * n + d] = FIRST_FRAME_SIGMA ** 2;
  await a.pause?.();
  const u0 = update(first.slice(0, n), P0, 0, root0);
  xf.push(u0.x); Pf.push(u0.cov); xp.push(u0.x); Pp.push(P0); F.push(new Float64Array(0));
  contactRows.push(first.slice(n));

  let Fk = new Float64Array(n * n);
  for (let f = 1; f < frames; f++) {
    const prev = xf[f - 1];
    const bits = contactRows[f - 1];
    // The dynamics' Jacobian every JACOBIAN_EVERY frames (it changes slowly); between, the last one.
    const withJacobian = (f - 1) % JACOBIAN_EVERY === 0;
    const B = withJacobian ? wide : 1;
    const input = new Float32Array(B * D);
    const h = new Float32Array(L * B * H), c = new Float32Array(L * B * H);
    for (let b = 0; b < B; b++) {
      setStateRow(h, L, B, H, b, hRow);
      setStateRow(c, L, B, H, b, cRow);
    }
    for (let b = 0; b < B; b++) {
      for (let d = 0; d < n; d++) input[b * D + d] = prev[d] + (b > 0 && b - 1 === d ? DYNAMICS_STEP : 0);
      input[b * D + n] = bits[0];
      input[b * D + n + 1] = bits[1];
    }
    const out = await step(B, input, h, c);
    a.onFrame?.(f, frames);
    // Each frame is placed from where the root track stands before it, so root errors cannot pile up; the component
    // the observation favours is chosen on the prediction's spread alone.
    const root = rootTrack[f - 1];
    const obs = points.subarray(f * m, (f + 1) * m);
    let best = 0, bestScore = -Infinity;
    for (let k = 0; k < M; k++) {
      const mu = out.mu.subarray(k * D, (k + 1) * D);
      const pos = observe(mu, root);
      let score = Math.log(Math.max(out.weights[k], 1e-12));
      for (let i = 0; i < m; i++) score -= 0.5 * (obs[i] - pos[i]) ** 2 / (R[i] * 4);
      if (score > bestScore) [bestScore, best] = [score, k];
    }
    const mu = Float64Array.from(out.mu.subarray(best * D, best * D + n));
    if (withJacobian) {
      Fk = new Float64Array(n * n);
      for (let d = 0; d < n; d++) {
        for (let e = 0; e < n; e++) Fk[e * n + d] = (out.mu[((d + 1) * M + best) * D + e] - out.mu[best * D + e]) / DYNAMICS_STEP;
      }
    }
    // P⁻ = F P Fᵀ + diag(σ²).
    let P: Float64Array = sandwich(Fk, Pf[f - 1], n);
    for (let d = 0; d < n; d++) P[d * n + d] += out.sigma[best * D + d] ** 2;
    let prior: Float64Array = mu;
    let Feff: Float64Array = Fk;
    if (f >= 2) {
      // The generator's prediction times a constant-velocity guess N(2 x_{t-1} − x_{t-2}, 4 P_{t-1} + P_{t-2} + c² I):
      // held-out capture's next frame is 3–6 times closer to the guess than to the generator's mean (cleanup.md).
      const cv = Float64Array.from(xf[f - 1], (v, d) => 2 * v - xf[f - 2][d]);
      const Pc = new Float64Array(n * n);
      for (let i = 0; i < n * n; i++) Pc[i] = 4 * Pf[f - 1][i] + Pf[f - 2][i];
      for (let d = 0; d < n; d++) Pc[d * n + d] += CONSTANT_VELOCITY_SIGMA ** 2;
      // The product of N(μ, P) and N(cv, Pc): K = P (P + Pc)⁻¹, mean μ + K (cv − μ), covariance P − K P; its dependence
      // on x_{t-1} is (I − K) F + 2 K (the x_{t-2} term is left out of the backward pass).
      const S = new Float64Array(n * n);
      for (let i = 0; i < n * n; i++) S[i] = P[i] + Pc[i];
      const K = transpose(choleskySolve(cholesky(S, n), P, n, n), n, n);
      prior = Float64Array.from(mu, (v, d) => {
        let s2 = v;
        for (let e = 0; e < n; e++) s2 += K[d * n + e] * (cv[e] - mu[e]);
        return s2;
      });
      const KP = matmul(K, P, n, n, n);
      const Pcomb = new Float64Array(n * n);
      for (let i = 0; i < n; i++) for (let j = 0; j < n; j++) Pcomb[i * n + j] = P[i * n + j] - (KP[i * n + j] + KP[j * n + i]) / 2;
      const IK = new Float64Array(n * n);
      for (let i = 0; i < n * n; i++) IK[i] = -K[i];
      for (let d = 0; d < n; d++) IK[d * n + d] += 1;
      Feff = matmul(IK, Fk, n, n, n);
      for (let i = 0; i < n * n; i++) Feff[i] += 2 * K[i];
      P = Pcomb;
    }
    const u = update(prior, P, f, root);
    xf.push(u.x); Pf.push(u.cov); xp.push(prior); Pp.push(P); F.push(Feff);
    const contact = new Float64Array(2);
    for (let i = 0; i < 2; i++) {
      const on = out.mu[best * D + n + i] * std[n + i] + mean[n + i] > 0.5;
      contact[i] = ((on ? 1 : 0) - mean[n + i]) / std[n + i];
    }
    contactRows.push(contact);
    // The next call continues from the unperturbed row's state.
    hRow = stateRow(out.h_out, L, B, H, 0);
    cRow = stateRow(out.c_out, L, B, H, 0);
  }

  // Backward pass (Rauch–Tung–Striebel): x_t|T = x_t|t + P_t|t Fᵀ_{t+1} P⁻¹_{t+1|t} (x_{t+1|T} − x_{t+1|t}).
  const xs: Float64Array[] = new Array(frames);
  xs[frames - 1] = xf[frames - 1];
  for (let f = frames - 2; f >= 0; f--) {
    if (f % 16 === 0) await a.pause?.();
    const diff = new Float64Array(n);
    for (let d = 0; d < n; d++) diff[d] = xs[f + 1][d] - xp[f + 1][d];
    const g = choleskySolve(cholesky(Pp[f + 1], n), diff, n); // P⁻¹ (x_s − x_p)
    const ft = matmul(transpose(F[f + 1], n, n), g, n, n, 1);
    const corr = matmul(Pf[f], ft, n, n, 1);
    xs[f] = Float64Array.from(xf[f], (v, d) => v + corr[d]);
  }

  const features = new Float32Array(frames * D);
  for (let f = 0; f < frames; f++) {
    for (let d = 0; d < n; d++) features[f * D + d] = xs[f][d] * std[d] + mean[d];
    // The root steps are the root track's, so decoding from `start` walks it exactly.
    const from = f === 0 ? a.start : rootTrack[f - 1], to = rootTrack[f];
    const dx = to.x - from.x, dz = to.z - from.z, cs = Math.cos(from.heading), sn = Math.sin(from.heading);
    features[f * D] = cs * dx - sn * dz;
    features[f * D + 1] = sn * dx + cs * dz;
    features[f * D + 2] = to.heading - from.heading;
    for (let i = 0; i < 2; i++) features[f * D + n + i] = contactRows[f][i] * std[n + i] + mean[n + i];
  }
  return { features, seedIndex, outlierShare: observations ? discounted / observations : 0 };
}

