// generate's checks for the latent ERD (docs/api.md): its options, the control signal handed on flattened,
// and models that are not its kind.
import { describe, expect, it } from 'vitest';
import { checkGenerate, type ModelInfo } from '../../web/api/playground';
import { messageOf } from './messageOf';

const MODELS: ModelInfo[] = [
  { id: 'generator', kind: 'lstm-gmm', skeleton: 'cmu-canonical', fps: 30, bytes: 1 },
  { id: 'latent-erd', kind: 'latent-erd', skeleton: 'cmu-canonical', fps: 30, bytes: 1 },
  { id: 'manifold', kind: 'autoencoder', skeleton: 'cmu-canonical', fps: 30, bytes: 1 },
];

describe('checkGenerate for the latent ERD', () => {
  it('takes frames, seed and an optional per-frame control, flattened', () => {
    expect(checkGenerate({ model: 'latent-erd', frames: 2, seed: 3 }, MODELS)).toEqual({ kind: 'latent-erd', model: 'latent-erd', frames: 2, seed: 3 });
    const o = checkGenerate({ model: 'latent-erd', frames: 2, seed: 0, control: [[1, 0, 0.5], [1.5, -0.1, 0], [0, 0, 0]] }, MODELS);
    expect(o.kind).toBe('latent-erd');
    expect(Array.from(o.control as Float64Array)).toEqual([1, 0, 0.5, 1.5, -0.1, 0, 0, 0, 0]);
  });

  it('refuses options of the other models, bad control and the autoencoder as a model', () => {
    expect(messageOf(() => checkGenerate({ model: 'latent-erd', frames: 2, seed: 0, refine: true }, MODELS))).toBe('unknown option "refine" for model "latent-erd" (known: model, frames, seed, control, signal)');
    expect(messageOf(() => checkGenerate({ model: 'latent-erd', frames: 2, seed: 0, control: null }, MODELS))).toMatch(/^control must be an array of .* got null$/);
    expect(messageOf(() => checkGenerate({ model: 'latent-erd', frames: 3, seed: 0, control: [[1, 0, 0]] }, MODELS))).toBe('control has 1 frames; it needs at least one per frame (3)');
    expect(messageOf(() => checkGenerate({ model: 'latent-erd', frames: 1, seed: 0, control: [[1, 0, Infinity]] }, MODELS))).toMatch(/control\[0\] must be a triple of finite numbers .*got \[1, 0, Infinity\]$/);
    expect(messageOf(() => checkGenerate({ model: 'manifold', frames: 1, seed: 0 }, MODELS))).toBe('unknown model "manifold" (available: generator, latent-erd)');
    expect(messageOf(() => checkGenerate({ model: 'generator', frames: 1, seed: 0, control: [[0, 0, 0]] }, MODELS))).toMatch(/^unknown option "control" for model "generator"/);
  });
});
