// The generator (LSTM + Gaussian mixture with contacts, Wang, Chai, Xia §4) as the page offers it: generate
// (with the refiner behind it on request), Random walk, the MAP optimiser's path following and live control
// (§5.2–5.3), and the MAP and low-pass clean-up (§5.4), all in its one worker.

import { checkFitSigma, optional } from '../../optimizer/options';
import { describeValue } from '../../motion/describe';
import { checkStyleOption, clientFiles, motionOf, pathStatsOf, type ModelDescriptor } from '../descriptor';
import { GeneratorClient } from './generatorClient';

/** Sampling temperature when generate's is left out (docs/api.md). */
export const GENERATE_DEFAULT_TEMPERATURE = 0.5;
/** followPath's fitTolerance when left out, metres. */
const DEFAULT_FIT_SIGMA = 0.1;

export const descriptor: ModelDescriptor<GeneratorClient> = {
  kind: 'lstm-gmm',
  shortName: 'generator',
  labels: { generator: 'Generator + MAP optimiser' },
  capabilities: ['generate', 'walk', 'followPath', 'liveControl', 'cleanup'],
  createClient: (entry, threads) => new GeneratorClient(clientFiles(entry, threads)),

  generate: {
    options: ['model', 'frames', 'seed', 'temperature', 'refine', 'style'],
    check(o, entry, models) {
      const temperature = optional(o.temperature, GENERATE_DEFAULT_TEMPERATURE);
      if (typeof temperature !== 'number' || !Number.isFinite(temperature) || temperature < 0 || temperature > 2) {
        throw new RangeError(`temperature must be a number from 0 to 2, got ${describeValue(temperature)}`);
      }
      if (o.refine !== undefined && typeof o.refine !== 'boolean') throw new TypeError(`refine must be true or false, got ${describeValue(o.refine)}`);
      const refine = o.refine === true;
      if (refine && !models.some((m) => m.kind === 'refiner')) throw new Error('refine is not available: no refiner model is listed in models/index.json');
      // A style generator (its entry lists styles) takes one of them, default its first; any other generator none.
      const styles = entry.styles ?? [];
      const style = checkStyleOption(o.style, entry);
      if (refine && styles.length) throw new TypeError(`refine is not available for model "${entry.id}": the refiner learnt from the CMU-only generator; leave it out`);
      return { temperature, refine, ...(styles.length ? { style: style ?? styles[0] } : {}) };
    },
    async run(client, call, { signal }) {
      const refine = call.refine === true;
      const style = typeof call.style === 'string' ? { style: call.style } : {};
      const m = await client.generate({ frames: call.frames, seed: call.seed, temperature: call.temperature as number, ...(refine ? { refine: true } : {}), ...style }, { signal });
      const shown = refine ? m.refined : m;
      if (!shown) throw new Error('the generator worker returned no refined frames');
      return motionOf(m, shown.positions, shown.contacts);
    },
  },

  followPath: {
    options: ['fitTolerance'],
    check: (o) => ({ fitSigma: checkFitSigma(optional(o.fitTolerance, DEFAULT_FIT_SIGMA), 'fitTolerance') }),
    async run(client, { points, gait, seed, fitSigma, footLock, stroke, style }, options) {
      const m = await client.followPath({ points, gait, seed, fitSigma, ...(footLock === undefined ? {} : { footLock }), ...(stroke ? { stroke } : {}), ...(style ? { style } : {}) }, options);
      return { motion: motionOf(m), path: m.path, stats: pathStatsOf(m.stats) };
    },
    working: (gait) => `finding a ${gait} along the path`,
  },

  liveControl: {
    particles: true,
    start: (client, params, options) => client.controlStart(params, options),
    switchStyle: (client, style, options) => client.controlStyle(style, options),
    pull: (client, frames, target, options) => client.controlPull(frames, target, options),
    async simulate(client, request, options) {
      const m = await client.simulateControl(request, options);
      return { ...motionOf(m), speed: m.speed, heading: m.heading, computeMs: m.computeMs };
    },
  },

  cleanup: {
    methods: ['map', 'lowpass'],
    loading: 'generator',
    run: (client, params, options) => client.denoise(params, options),
  },
};
