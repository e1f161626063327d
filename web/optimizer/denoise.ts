// Motion denoising as MAP under the generator (Wang, Chai, Xia §5.4, eqs. 24–25), solved frame by frame in closed form.
//
// The observation is the noisy motion's own feature row, with Gaussian noise σ_root on the root (its position and
// height) and σ_angle on every rotation (heading change, tilt, joint rotation vectors): eq. 25. The prior is the
// generator's mixture for the next frame given the cleaned frames so far. For each component the product of its
// Gaussian with the observation's is again Gaussian, with the precision-weighted mean; the frame takes the mean of
// the component with the largest evidence w_k N(o; μ_k, σ_k² + s²), and that frame is fed back into the network.
// The contact bits are not observed (the input is unlabelled): they come from the chosen component, so the result
// carries the model's contact labels (the paper's contact term then acts through the foot lock).
//
// Two things beyond the paper's Gaussian: outliers and the start.
//   - An observation far outside a component's spread (a marker glitch) would drag the frame with it. Each joint's
//     observation noise is widened by its own misfit beyond OUTLIER_Z (a Huber weight), so glitches are discounted
//     and ordinary jitter is not.
//   - The model's σ_k is its one-step uncertainty given an exact past; the cleaned past is itself uncertain. Used
//     alone, the prior is overconfident and the filter free-runs away from the observations. Each component's
//     variance is widened to the steady-state predicted variance of a Kalman filter with process noise σ_k² and
//     observation noise s²: P = (σ_k² + √(σ_k⁴ + 4σ_k²s²)) / 2.
//   - The generator's seed states come from other clips. All of them run side by side (one batched call per frame)
//     and the one whose run explains the observations best (total log evidence) is returned.
import { integrateRoot, type RootStart } from '../model/featureDecode';
import { JOINT_FEATURES_START, type GeneratorInfo } from '../model/generatorInfo';
import { setStateRow } from '../model/lstmState';
import type { StepFn } from './rollout';

/** Misfit (in σ of the component and the observation together, per dimension of a joint) beyond which a joint's observation is discounted. */
export const OUTLIER_Z = 3;
const LOG_2PI = Math.log(2 * Math.PI);

export interface DenoiseSettings {
  /** σ of the root observation: position steps and height (m). */
  sigmaRoot: number;
  /** σ of the rotation observations: heading change, tilt and joint rotation vectors (rad); one for all, or one per feature dimension (D values; root and contact entries unused). */
  sigmaAngle: number | ArrayLike<number>;
}

/**
 * Re-reads frame `frame`'s joint angles (tilt and rotation vectors, into `row`, physical units) with the segments'
 * twists nearest the model's prediction `predicted` (a physical feature row): positions do not show twist, and a
 * twist that disagrees with the model would read as a large misfit on dimensions the data barely moves.
 */
export type Reobserve = (frame: number, predicted: Float32Array, row: Float32Array) => void;

export interface DenoiseResult {
  /** frames × D physical feature rows of the cleaned motion (contacts 0/1 from the model). */
  features: Float32Array;
  /** Which seed state won, and the total log evidence of each seed's run. */
  seedIndex: number;
  logEvidence: number[];
  /** Share of joint observations discounted as outliers in the winning run. */
  outlierShare: number;
}

/** Steady-state predicted variance of a scalar Kalman filter with process variance q and observation variance r. */
export function predictedVariance(q: number, r: number): number {
  return Number.isFinite(r) ? (q + Math.sqrt(q * q + 4 * q * r)) / 2 : q;
}

/** Feature groups of a row: the root position (Δtx, Δtz, ty), the heading change, the tilt, each joint; contacts are not observed. */
function groups(info: GeneratorInfo): number[][] {
  const out = [[0, 1, 3], [2], [4, 5, 6]];
  info.features.joints.forEach((_, k) => out.push([0, 1, 2].map((a) => JOINT_FEATURES_START + 3 * k + a)));
  return out;
}

/**
 * The MAP filter over `observed` (frames × D physical rows from featureEncode.encodeFeatures; their root steps are
 * ignored: each frame's root is observed as the absolute position it implies, relative to where the cleaned root
 * stands). `start` is the root state before frame 0. `onFrame` reports progress and may throw to cancel.
 */
export async function denoiseFeatures(args: {
  step: StepFn;
  info: GeneratorInfo;
  mean: ArrayLike<number>;
  std: ArrayLike<number>;
  observed: Float32Array;
  start: RootStart;
  settings: DenoiseSettings;
  reobserve?: Reobserve;
  onFrame?: (frame: number, frames: number) => void;
}): Promise<DenoiseResult> {
  const { step, info, mean, std, observed, start, settings } = args;
  const { dim: D, mixtures: M, layers: L, hidden: H } = info.onnx;
  const frames = observed.length / D;
  const seeds = info.seeds;
  const B = seeds.length;
  const featureGroups = groups(info);

  // The observed absolute root track, and heading, from the rows.
  const obsRoot: RootStart[] = [];
  const walker = { ...start };
  for (let f = 0; f < frames; f++) {
    integrateRoot(walker, observed[f * D], observed[f * D + 1], observed[f * D + 2]);
    obsRoot.push({ ...walker });
  }

  const s2 = new Float64Array(D); // observation variance per dimension, normalised units
  for (let d = 0; d < D; d++) {
    const angle = typeof settings.sigmaAngle === 'number' ? settings.sigmaAngle : settings.sigmaAngle[d];
    const sigma = d === 0 || d === 1 || d === 3 ? settings.sigmaRoot : d >= D - 2 ? Infinity : angle;
    s2[d] = (sigma / std[d]) ** 2;
  }

  // Frame 0 is taken as observed (the seed states carry no knowledge of it); every seed starts from it.
  const x = new Float32Array(B * D);
  const first = new Float32Array(D);
  for (let d = 0; d < D; d++) first[d] = (observed[d] - mean[d]) / std[d];
  for (let b = 0; b < B; b++) x.set(first, b * D);
  let h: Float32Array = new Float32Array(L * B * H);
  let c: Float32Array = new Float32Array(L * B * H);
  seeds.forEach((seed, b) => {
    setStateRow(h, L, B, H, b, seed.h);
    setStateRow(c, L, B, H, b, seed.c);
  });
  const out = new Float32Array(B * frames * D);
  for (let b = 0; b < B; b++) out.set(observed.subarray(0, D), b * frames * D);
  const roots: RootStart[] = seeds.map(() => ({ ...obsRoot[0] }));
  const evidence = new Float64Array(B);
  const discounted = new Float64Array(B);

  const o = new Float64Array(D);
  const inflate = new Float64Array(D);
  const predicted = new Float32Array(D);
  const angles = new Float32Array(D);
  for (let f = 1; f < frames; f++) {
    const r = await step(B, x, h, c);
    args.onFrame?.(f, frames);
    for (let b = 0; b < B; b++) {
      // The observation in this stream's frame: the step from where its cleaned root stands to the observed root.
      const root = roots[b];
      const target = obsRoot[f];
      const dx = target.x - root.x, dz = target.z - root.z;
      const cs = Math.cos(root.heading), sn = Math.sin(root.heading);
      for (let d = 0; d < D; d++) o[d] = observed[f * D + d];
      if (args.reobserve) {
        let heaviest = 0;
        for (let k = 1; k < M; k++) if (r.weights[b * M + k] > r.weights[b * M + heaviest]) heaviest = k;
        for (let d = 0; d < D; d++) predicted[d] = r.mu[(b * M + heaviest) * D + d] * std[d] + mean[d];
        args.reobserve(f, predicted, angles);
        for (let d = 4; d < D - 2; d++) o[d] = angles[d];
      }
      o[0] = cs * dx - sn * dz;
      o[1] = sn * dx + cs * dz;
      o[2] = wrapAngle(target.heading - root.heading);
      for (let d = 0; d < D; d++) o[d] = (o[d] - mean[d]) / std[d];

      let best = -1, bestScore = -Infinity;
      for (let k = 0; k < M; k++) {
        const base = (b * M + k) * D;
        let score = Math.log(Math.max(r.weights[b * M + k], 1e-12));
        for (const g of featureGroups) {
          let z2 = 0;
          for (const d of g) {
            const v = predictedVariance(r.sigma[base + d] ** 2, s2[d]) + s2[d];
            z2 += (o[d] - r.mu[base + d]) ** 2 / v;
          }
          const z = Math.sqrt(z2 / g.length);
          const widen = z > OUTLIER_Z ? (z / OUTLIER_Z) ** 2 : 1;
          for (const d of g) {
            const v = predictedVariance(r.sigma[base + d] ** 2, s2[d]) + s2[d] * widen;
            score += -0.5 * ((o[d] - r.mu[base + d]) ** 2 / v + Math.log(v) + LOG_2PI);
          }
        }
        if (score > bestScore) {
          bestScore = score;
          best = k;
        }
      }
      evidence[b] += bestScore;

      const base = (b * M + best) * D;
      const row = new Float32Array(D);
      for (const g of featureGroups) {
        let z2 = 0;
        for (const d of g) z2 += (o[d] - r.mu[base + d]) ** 2 / (predictedVariance(r.sigma[base + d] ** 2, s2[d]) + s2[d]);
        const z = Math.sqrt(z2 / g.length);
        const widen = z > OUTLIER_Z ? (z / OUTLIER_Z) ** 2 : 1;
        if (widen > 1) discounted[b] += 1;
        for (const d of g) inflate[d] = widen;
      }
      for (let d = 0; d < D; d++) {
        const p = predictedVariance(r.sigma[base + d] ** 2, s2[d]);
        const s = s2[d] * inflate[d];
        row[d] = Number.isFinite(s) ? (r.mu[base + d] * s + o[d] * p) / (p + s) : r.mu[base + d];
      }
      // Contacts are bits, as in generation.
      for (let d = D - 2; d < D; d++) row[d] = ((row[d] * std[d] + mean[d] > 0.5 ? 1 : 0) - mean[d]) / std[d];
      x.set(row, b * D);
      const phys = out.subarray((b * frames + f) * D, (b * frames + f + 1) * D);
      for (let d = 0; d < D; d++) phys[d] = row[d] * std[d] + mean[d];
      integrateRoot(root, phys[0], phys[1], phys[2]);
    }
    h = r.h_out;
    c = r.c_out;
  }
  let winner = 0;
  for (let b = 1; b < B; b++) if (evidence[b] > evidence[winner]) winner = b;
  return {
    features: out.slice(winner * frames * D, (winner + 1) * frames * D),
    seedIndex: winner,
    logEvidence: Array.from(evidence),
    outlierShare: frames > 1 ? discounted[winner] / ((frames - 1) * featureGroups.length) : 0,
  };
}

function wrapAngle(a: number): number {
  return a - 2 * Math.PI * Math.round(a / (2 * Math.PI));
}
