// Issue 43 #3: clean-up refuses frame rates and lengths it cannot handle before any work (the check the API and the
// worker share), and a cancelled `map` clean-up stops within about a model step wherever it is (before the first
// step, in the forward pass, in the backward pass and the work after it), not seconds later.
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { parseAMC } from '../../web/motion/asfamc';
import { addNoise } from '../../web/motion/noise';
import { parseGeneratorInfo } from '../../web/model/generatorInfo';
import { checkCleanupMotion, checkCleanupOptions, cleanUpOnCanonical, mapCleaner } from '../../web/runtime/cleanup/cleanup';
import { serveDenoise } from '../../web/runtime/cleanup/cleanupRequests';
import { GeneratorCore } from '../../web/runtime/generator/generatorCore';
import { CancelledError } from '../../web/runtime/worker/cancellation';
import { readCorpus, readRepoFile } from './corpus';
import { ort, shippedSession } from './shippedModel';

const info = parseGeneratorInfo(JSON.parse(readRepoFile('public/models/generator.json')), 'generator.json');
const clip = parseAMC(readCorpus('cmu/amc/35_13.amc.gz'), readCorpus('cmu/asf/35.asf'), { fps: 120 });
const noisy = addNoise(clip, { jitter: 0.02, outliers: 0.01, seed: 3 }).motion;


let core: GeneratorCore;
beforeAll(async () => {
  core = new GeneratorCore(await shippedSession(info.file), info, ort.Tensor);
});
afterAll(() => core?.release());

describe('denoise refuses frame rates and lengths clean-up cannot handle', () => {
  it.each([0.01, 1e-6, 0.5, 1001, 10000])('fps %s is refused with a short message naming the bounds', (fps) => {
    expect(() => checkCleanupMotion({ ...noisy, fps })).toThrow(/frame rate .*from 1 to 1000 fps/);
    try {
      checkCleanupMotion({ ...noisy, fps });
    } catch (e) {
      expect((e as Error).message.length).toBeLessThan(300);
      expect((e as Error).message).not.toMatch(/^denoise:/); // the API and the worker add their own prefix
    }
  });

  it('a capture longer than clean-up handles is refused (its frames at the model rate named)', () => {
    const frames = 120 * 3700; // about an hour at 120 fps
    const J = 1;
    const long = { fps: 120, frames, joints: ['Hips'], parents: [-1], positions: new Float32Array(frames * J * 3) };
    expect(() => checkCleanupMotion(long)).toThrow(/lasts 61.7 min; clean-up takes at most 60 min/);
    expect(() => checkCleanupMotion({ ...long, frames: 120 * 3500 })).not.toThrow();
  });

  it('real capture rates pass: 1, 30, 120, 1000 fps', () => {
    for (const fps of [1, 30, 120, 1000]) expect(() => checkCleanupMotion({ ...noisy, fps })).not.toThrow();
  });

  it('the worker refuses it too, before asking its model anything', async () => {
    let asked = false;
    const backend = { methods: ['map', 'lowpass'] as const, info: async () => { asked = true; return info; }, cleaner: () => async () => { asked = true; throw new Error('not reached'); } };
    await expect(serveDenoise({ motion: { ...noisy, fps: 0.01 }, options: { method: 'map' } }, backend, () => {})).rejects.toThrow(/frame rate/);
    await expect(serveDenoise({ motion: { ...noisy, fps: 0.01 }, options: { method: 'lowpass' } }, backend, () => {})).rejects.toThrow(/frame rate/);
    expect(asked).toBe(false);
  });
});

describe('messages carry one prefix (#12)', () => {
  it('the shared option check does not start with "denoise:" (the API and the worker add it: "denoise: denoise: …" before)', () => {
    for (const bad of [{ method: 'median' }, { method: 'map', sigma: 1 }, { method: 'map', sigmaAngle: -1 }, 'map']) {
      expect(() => checkCleanupOptions(bad)).toThrow();
      try {
        checkCleanupOptions(bad);
      } catch (e) {
        expect((e as Error).message).not.toMatch(/^denoise:/);
      }
    }
  });
});

describe('a cancelled map clean-up stops within about a model step', () => {
  /** Runs map clean-up and aborts when `when(fraction)` first holds (at a progress report), or from a timer at `afterMs`; returns ms from abort to rejection. */
  async function latency(at: { fraction?: number; afterMs?: number }): Promise<number> {
    const controller = new AbortController();
    const { signal } = controller;
    let abortedAt = 0;
    const abort = () => {
      if (abortedAt) return;
      abortedAt = performance.now();
      controller.abort();
    };
    const cleaner = mapCleaner({
      step: (b, x, h, c) => core.step(b, x, h, c, signal), info, mean: core.mean, std: core.std, options: { method: 'map' }, signal,
      onProgress: (p) => { if (at.fraction !== undefined && p >= at.fraction) abort(); },
    });
    if (at.afterMs !== undefined) setTimeout(abort, at.afterMs);
    const began = performance.now();
    const run = cleanUpOnCanonical(info, noisy, 'map', cleaner, signal);
    const error = await run.then(() => undefined, (e) => e);
    if (!(error instanceof CancelledError)) throw error;
    const now = performance.now();
    const ms = now - (at.afterMs !== undefined ? began + at.afterMs : abortedAt);
    console.log(`abort at ${JSON.stringify(at)}: stopped ${ms.toFixed(0)} ms after`);
    return ms;
  }

  it('at the first frames, mid-way and at the last frame of the forward pass (79 of 80), and just after the call', async () => {
    const worst = Math.max(await latency({ afterMs: 0 }), await latency({ fraction: 0.01 }), await latency({ fraction: 0.5 }), await latency({ fraction: 0.98 }));
    // Before the fix: 2.1 s at the start (the work before the first model step had no checkpoint) and never at the last
    // frame (nothing after the forward pass looked); after: tens of ms, a few hundred at most on a loaded machine (the frame's
    // own update and one wide Jacobian step).
    expect(worst).toBeLessThan(600);
  }, 120_000);
});
