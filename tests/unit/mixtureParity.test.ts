// Parity of the generator's mixture sampling: web/model/sampler.ts (chooseComponent, sampleMixture,
// snapContacts) against training/generator/sampling.py on tests/fixtures/mixture_parity.json
// (python -m training.fixtures.mixture): one real step of the shipped generator from every seed state, plus
// rows with spread weights, sampled at five temperatures from given uniforms and normals. Every value is stored
// as the float32 the page holds and both sides do the arithmetic in float64 in the same order, so the
// components and the float32 frames must be identical (no tolerance); the uniforms keep 1e-9 from any
// component boundary, so rounding in exp/log cannot flip a choice.
import { describe, expect, it } from 'vitest';
import { chooseComponent, sampleMixture, snapContacts, type HeldNoise, type MixtureBatch, type RandomSource } from '../../web/model/sampler';
import { readRepoFile } from './corpus';

interface Case {
  temperature: number;
  /** More uniforms on the spread rows and the components Python chose for them. */
  choices: { row: number; u: number[]; components: number[] }[];
  u: number[];
  z: number[];
  components: number[];
  x: number[];
  snapped_contacts: number[];
}
interface Fixture {
  rows: string[];
  batch: number;
  mixtures: number;
  dim: number;
  weights: number[];
  mu: number[];
  sigma: number[];
  mean: number[];
  std: number[];
  cases: Case[];
  /** Draws in a row with held normals: per step the uniforms, the fresh normals, the held ones and the frame. */
  held: { temperature: number; correlation: number; steps: { u: number[]; z: number[]; held: number[]; x: number[] }[] };
}

const fixture = JSON.parse(readRepoFile('tests/fixtures/mixture_parity.json')) as Fixture;
const { batch: B, mixtures: M, dim: D } = fixture;
const mixture: MixtureBatch = {
  batch: B,
  mixtures: M,
  dim: D,
  weights: Float32Array.from(fixture.weights),
  mu: Float32Array.from(fixture.mu),
  sigma: Float32Array.from(fixture.sigma),
};

/** Gives the fixture's numbers in the order sampleMixture asks for them: per row one uniform, then D normals. */
function replay(c: Pick<Case, 'u' | 'z'>): RandomSource & { left: () => number } {
  const values: number[] = [];
  for (let b = 0; b < B; b++) values.push(c.u[b], ...c.z.slice(b * D, (b + 1) * D));
  let i = 0;
  const next = () => {
    if (i >= values.length) throw new Error('the sampler asked for more random numbers than one per row and D per row');
    return values[i++];
  };
  return { uniform: next, normal: next, left: () => values.length - i };
}

describe('mixture sampling matches training/generator/sampling.py', () => {
  it('the fixture covers real rows, spread weights and every temperature', () => {
    expect(fixture.rows.length).toBe(B);
    expect(fixture.cases.map((c) => c.temperature)).toEqual([1, 0.5, 0.25, 0.05, 0]);
    // With spread weights the uniform decides: the rows do not all take their heaviest component.
    const heaviest = (b: number) => {
      const w = mixture.weights.subarray(b * M, (b + 1) * M);
      return w.indexOf(Math.max(...w));
    };
    const differs = fixture.cases.some((c) => c.components.some((k, b) => k !== heaviest(b)));
    expect(differs).toBe(true);
  });

  for (const c of fixture.cases) {
    it(`τ = ${c.temperature}: the same components, and the same float32 frame before and after contact snapping`, () => {
      if (c.temperature > 0) {
        const chosen = Array.from({ length: B }, (_, b) => chooseComponent(mixture.weights.subarray(b * M, (b + 1) * M), c.temperature, c.u[b]));
        expect(chosen).toEqual(c.components);
        for (const { row, u, components } of c.choices) {
          const weights = mixture.weights.subarray(row * M, (row + 1) * M);
          expect(u.map((v) => chooseComponent(weights, c.temperature, v)), fixture.rows[row]).toEqual(components);
        }
      }
      const rng = replay(c);
      const x = sampleMixture(mixture, c.temperature, rng);
      // τ > 0 uses every number given, τ = 0 none.
      expect(rng.left()).toBe(c.temperature > 0 ? 0 : B * (D + 1));
      expect(Array.from(x)).toEqual(Array.from(Float32Array.from(c.x)));
      snapContacts(x, D, Float32Array.from(fixture.mean), Float32Array.from(fixture.std));
      const contacts = Array.from({ length: B }, (_, b) => [x[b * D + D - 2], x[b * D + D - 1]]).flat();
      expect(contacts).toEqual(Array.from(Float32Array.from(c.snapped_contacts)));
    });
  }

  it('normals held over frames (generator.json sampling): the same held normals and the same float32 frames, step after step', () => {
    const { temperature, correlation, steps } = fixture.held;
    expect(correlation).toBeGreaterThan(0);
    expect(steps.length).toBeGreaterThan(1);
    const held: HeldNoise = { correlation };
    for (const step of steps) {
      const rng = replay(step);
      const x = sampleMixture(mixture, temperature, rng, undefined, held);
      expect(rng.left()).toBe(0);
      expect(Array.from(held.previous!)).toEqual(step.held);
      expect(Array.from(x)).toEqual(Array.from(Float32Array.from(step.x)));
    }
    // The first step took its fresh normals as they are; the later ones did not.
    expect(steps[0].held).toEqual(steps[0].z);
    expect(steps[1].held).not.toEqual(steps[1].z);
  });
});
