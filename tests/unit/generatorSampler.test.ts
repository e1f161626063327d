// The mixture sampler: seeded determinism, τ = 0, draw statistics against the analytic moments of a
// known mixture, temperature sharpening, and contact snapping.
import { describe, expect, it } from 'vitest';
import { chooseComponent, denormalise, Rng, sampleMixture, snapContacts, type HeldNoise, type MixtureBatch } from '../../web/model/sampler';

// Batch of 2 rows, 3 components, 2 dimensions.
const WEIGHTS = [0.2, 0.5, 0.3];
const MU = [
  [-2, 1],
  [1, 0],
  [4, -3],
];
const SIGMA = [
  [0.5, 1],
  [1, 0.25],
  [0.3, 2],
];
function knownMixture(batch: number): MixtureBatch {
  return {
    batch,
    mixtures: 3,
    dim: 2,
    weights: Float32Array.from({ length: batch * 3 }, (_, i) => WEIGHTS[i % 3]),
    mu: Float32Array.from({ length: batch * 6 }, (_, i) => MU[Math.floor(i / 2) % 3][i % 2]),
    sigma: Float32Array.from({ length: batch * 6 }, (_, i) => SIGMA[Math.floor(i / 2) % 3][i % 2]),
  };
}

describe('Rng', () => {
  it('repeats its sequence for the same seed and differs for another', () => {
    const a = new Rng(42), b = new Rng(42), c = new Rng(43);
    const seqA = Array.from({ length: 20 }, () => a.normal());
    expect(Array.from({ length: 20 }, () => b.normal())).toEqual(seqA);
    expect(Array.from({ length: 20 }, () => c.normal())).not.toEqual(seqA);
  });

  it('gives uniforms in [0, 1) and standard normals', () => {
    const rng = new Rng(7);
    let lo = 1, hi = 0, sum = 0, sumSq = 0;
    const n = 200_000;
    for (let i = 0; i < n; i++) {
      const u = rng.uniform();
      lo = Math.min(lo, u);
      hi = Math.max(hi, u);
      const z = rng.normal();
      sum += z;
      sumSq += z * z;
    }
    expect(lo).toBeGreaterThanOrEqual(0);
    expect(hi).toBeLessThan(1);
    expect(Math.abs(sum / n)).toBeLessThan(0.01);
    expect(Math.abs(sumSq / n - 1)).toBeLessThan(0.02);
  });
});

describe('sampleMixture', () => {
  it('is deterministic for a seed', () => {
    const m = knownMixture(2);
    const a = sampleMixture(m, 1, new Rng(5));
    const b = sampleMixture(m, 1, new Rng(5));
    expect(Array.from(b)).toEqual(Array.from(a));
    expect(Array.from(sampleMixture(m, 1, new Rng(6)))).not.toEqual(Array.from(a));
  });

  it('held normals: correlation 0 draws what fresh normals draw; a high correlation moves less from frame to frame but keeps the spread', () => {
    // One component, so every change between frames comes from the normals.
    const m: MixtureBatch = { batch: 2000, mixtures: 1, dim: 2, weights: new Float32Array(2000).fill(1), mu: new Float32Array(4000), sigma: new Float32Array(4000).fill(1) };
    const frames = (held: HeldNoise | undefined, seed: number) => {
      const rng = new Rng(seed);
      return Array.from({ length: 20 }, () => sampleMixture(m, 1, rng, undefined, held));
    };
    const fresh = frames(undefined, 3);
    const zero = frames({ correlation: 0 }, 3);
    zero.forEach((x, t) => expect(Array.from(x)).toEqual(Array.from(fresh[t])));
    const stats = (xs: Float32Array[]) => {
      let step = 0, square = 0, n = 0;
      for (let t = 1; t < xs.length; t++) for (let i = 0; i < xs[t].length; i++, n++) {
        step += (xs[t][i] - xs[t - 1][i]) ** 2;
        square += xs[t][i] ** 2;
      }
      return { step: step / n, variance: square / n };
    };
    const a = stats(fresh), b = stats(frames({ correlation: 0.9 }, 3));
    // E[(z_t − z_{t−1})²] = 2(1 − ρ): 2 for fresh normals, 0.2 at ρ = 0.9; the variance stays 1.
    expect(a.step).toBeGreaterThan(1.9);
    expect(b.step).toBeLessThan(0.25);
    expect(Math.abs(b.variance - 1)).toBeLessThan(0.05);
  });

  it('returns the heaviest component mean at τ = 0, per row', () => {
    const m = knownMixture(2);
    m.weights.set([0.1, 0.3, 0.6], 3); // row 1: component 2 is heaviest
    expect(Array.from(sampleMixture(m, 0, new Rng(1)))).toEqual([...MU[1], ...MU[2]]);
  });

  it('matches the mixture mean and variance over many draws', () => {
    const batch = 100_000;
    const x = sampleMixture(knownMixture(batch), 1, new Rng(123));
    for (let d = 0; d < 2; d++) {
      const mean = WEIGHTS.reduce((s, w, k) => s + w * MU[k][d], 0);
      const variance = WEIGHTS.reduce((s, w, k) => s + w * (SIGMA[k][d] ** 2 + MU[k][d] ** 2), 0) - mean ** 2;
      let sum = 0, sumSq = 0;
      for (let b = 0; b < batch; b++) {
        sum += x[b * 2 + d];
        sumSq += x[b * 2 + d] ** 2;
      }
      const sampleMean = sum / batch;
      const sampleVariance = sumSq / batch - sampleMean ** 2;
      // 5 standard errors of the mean; 3 % on the variance (its standard error here is below 1 %).
      expect(Math.abs(sampleMean - mean)).toBeLessThan(5 * Math.sqrt(variance / batch));
      expect(Math.abs(sampleVariance / variance - 1)).toBeLessThan(0.03);
    }
  });

  it('picks components with probability ∝ w^(1/τ) and scales sigma by τ', () => {
    const batch = 60_000;
    const tau = 0.5;
    // Spread the components far apart so each draw's component is recognisable from dimension 0.
    const m = knownMixture(batch);
    for (let b = 0; b < batch; b++) for (let k = 0; k < 3; k++) m.mu[(b * 3 + k) * 2] = 100 * k;
    const x = sampleMixture(m, tau, new Rng(9));
    const counts = [0, 0, 0];
    let spread = 0;
    for (let b = 0; b < batch; b++) {
      const k = Math.round(x[b * 2] / 100);
      counts[k]++;
      if (k === 1) spread += (x[b * 2] - 100) ** 2;
    }
    const sharpened = WEIGHTS.map((w) => w ** (1 / tau));
    const total = sharpened.reduce((a, b) => a + b);
    counts.forEach((n, k) => expect(Math.abs(n / batch - sharpened[k] / total)).toBeLessThan(0.01));
    expect(Math.sqrt(spread / counts[1])).toBeCloseTo(SIGMA[1][0] * tau, 1);
  });
});

describe('chooseComponent', () => {
  it('walks the cumulative tempered weights with the uniform (what sampleMixture and the optimiser both use)', () => {
    // τ = 1: boundaries at 0.2 and 0.7.
    expect([0, 0.19, 0.21, 0.69, 0.71, 0.9999].map((u) => chooseComponent(WEIGHTS, 1, u))).toEqual([0, 0, 1, 1, 2, 2]);
    // τ = 0.5: w² / Σw² = 0.105, 0.658, 0.237, so boundaries at 0.105 and 0.763.
    expect([0.1, 0.11, 0.76, 0.77].map((u) => chooseComponent(WEIGHTS, 0.5, u))).toEqual([0, 1, 1, 2]);
    // A tiny τ still picks the heaviest component rather than underflowing to the last.
    expect(chooseComponent(WEIGHTS, 1e-3, 0.5)).toBe(1);
  });
});

describe('contacts and normalisation', () => {
  it('snaps the two contact dimensions to the normalised 0 or 1', () => {
    const mean = [0, 0, 0.3, 0.7];
    const std = [1, 1, 0.5, 0.25];
    const x = Float32Array.from([5, 6, (0.51 - 0.3) / 0.5, (0.49 - 0.7) / 0.25]);
    snapContacts(x, 4, mean, std);
    expect(x[0]).toBe(5);
    expect(x[1]).toBe(6);
    expect(denormalise(x, mean, std)[2]).toBeCloseTo(1, 6);
    expect(denormalise(x, mean, std)[3]).toBeCloseTo(0, 6);
  });
});
