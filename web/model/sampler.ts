// Drawing the generator's next frame from its Gaussian mixture output, deterministically from a seed.
// Mirrors training/generator/sampling.py (draw_mixture and snap_contacts); tests/unit/mixtureParity.test.ts
// checks the two against a fixture written by python -m training.fixtures.mixture.

/** Where the sampler's random numbers come from: the seeded Rng, or given values (the parity test). */
export interface RandomSource {
  /** Uniform in [0, 1). */
  uniform(): number;
  /** Standard normal N(0, 1). */
  normal(): number;
}

export { Rng } from '../motion/random';

/** One ONNX step's mixture output for a batch: weights (B×M), mu and sigma (B×M×D). */
export interface MixtureBatch {
  weights: Float32Array;
  mu: Float32Array;
  sigma: Float32Array;
  batch: number;
  mixtures: number;
  dim: number;
}

/**
 * The mixture component a uniform u in [0, 1) picks when component k has probability ∝ w_k^(1/τ), τ > 0:
 * the cumulative walk over the tempered weights. `scratch` (≥ weights.length values) saves an allocation.
 */
export function chooseComponent(weights: ArrayLike<number>, temperature: number, u: number, scratch = new Float64Array(weights.length)): number {
  const M = weights.length;
  // w^(1/τ) through logs, shifted by the largest, so small τ cannot underflow every weight to 0.
  let largest = -Infinity;
  for (let i = 0; i < M; i++) {
    scratch[i] = Math.log(Math.max(weights[i], 1e-12)) / temperature;
    largest = Math.max(largest, scratch[i]);
  }
  let total = 0;
  for (let i = 0; i < M; i++) total += scratch[i] = Math.exp(scratch[i] - largest);
  let left = u * total;
  for (let i = 0; i < M; i++) {
    left -= scratch[i];
    if (left < 0) return i;
  }
  return M - 1;
}

/**
 * Normals held over a stream's frames (generator.json "sampling"): each frame's normal is
 * correlation·previous + sqrt(1 − correlation²)·fresh, so the noise drifts instead of jumping every frame and
 * each value is still N(0, 1). Mirrors training/generator/sampling.py held_normals.
 */
export interface HeldNoise {
  correlation: number;
  /** batch × dim normals of the last draw; undefined before a stream's first frame (which takes the fresh ones). */
  previous?: Float64Array;
}

export function heldNormal(previous: number, fresh: number, correlation: number): number {
  return correlation * previous + Math.sqrt(1 - correlation * correlation) * fresh;
}

/**
 * One draw per batch row: component k with probability ∝ w_k^(1/τ), then mu_k + sigma_k·τ·z per dimension with
 * z standard normals (fresh, or held over frames with `held`, which is updated); a row takes one uniform, then D
 * fresh normals. τ ≤ 0 takes the heaviest component's mean and uses no random numbers.
 */
export function sampleMixture(m: MixtureBatch, temperature: number, rng: RandomSource, out = new Float32Array(m.batch * m.dim), held?: HeldNoise): Float32Array {
  const { batch, mixtures: M, dim: D } = m;
  if (m.weights.length !== batch * M || m.mu.length !== batch * M * D || m.sigma.length !== batch * M * D) {
    throw new Error(`sampleMixture: output sizes (${m.weights.length}, ${m.mu.length}, ${m.sigma.length}) do not fit batch ${batch}, ${M} mixtures, dim ${D}`);
  }
  if (out.length !== batch * D) throw new Error(`sampleMixture: out has ${out.length} values, expected ${batch * D}`);
  const scratch = new Float64Array(M);
  const previous = held?.previous;
  if (previous && previous.length !== batch * D) throw new Error(`sampleMixture: ${previous.length} held normals, expected ${batch * D}`);
  const normals = held && temperature > 0 ? new Float64Array(batch * D) : undefined;
  for (let b = 0; b < batch; b++) {
    const w = m.weights.subarray(b * M, (b + 1) * M);
    let k = 0;
    if (temperature <= 0) {
      for (let i = 1; i < M; i++) if (w[i] > w[k]) k = i;
    } else {
      k = chooseComponent(w, temperature, rng.uniform(), scratch);
    }
    const src = (b * M + k) * D;
    for (let d = 0; d < D; d++) {
      if (temperature <= 0) {
        out[b * D + d] = m.mu[src + d];
        continue;
      }
      const fresh = rng.normal();
      const z = previous ? heldNormal(previous[b * D + d], fresh, held!.correlation) : fresh;
      if (normals) normals[b * D + d] = z;
      out[b * D + d] = m.mu[src + d] + m.sigma[src + d] * temperature * z;
    }
  }
  if (held && normals) held.previous = normals;
  return out;
}

/**
 * Contacts are bits: sets the last two (normalised) dimensions of each row to the normalised value of
 * exactly 0 or 1, whichever the de-normalised value is nearer to (threshold 0.5).
 */
export function snapContacts(x: Float32Array, dim: number, mean: ArrayLike<number>, std: ArrayLike<number>): void {
  for (let row = 0; row < x.length; row += dim) {
    for (let d = dim - 2; d < dim; d++) {
      const on = x[row + d] * std[d] + mean[d] > 0.5;
      x[row + d] = ((on ? 1 : 0) - mean[d]) / std[d];
    }
  }
}

/** Physical units from normalised features: x·std + mean, per dimension. */
export function denormalise(x: Float32Array, mean: ArrayLike<number>, std: ArrayLike<number>, out = new Float32Array(x.length)): Float32Array {
  const D = mean.length;
  for (let i = 0; i < x.length; i++) out[i] = x[i] * std[i % D] + mean[i % D];
  return out;
}
