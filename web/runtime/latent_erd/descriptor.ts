// The latent ERD (Yearsley: a recurrent controller in the latent space of a convolutional motion
// autoencoder, Holden et al.) as the page offers it: generate under a control signal, closed-loop path
// following and live control (a control signal from where the character stands, every latent step), and
// the autoencoder's manifold clean-up, all in its one worker.

import { checkControlSignal } from '../../model/latentErdInfo';
import { optional } from '../../optimizer/options';
import { motionOf, pathStatsOf, type ModelDescriptor } from '../descriptor';
import { LatentErdClient } from './latentErdClient';
import { checkPathSpeed, LATENT_PATH_SPEED } from './latentErdRequests';

/** One latent step of 4 frames per live pull, and 8 frames (0.27 s) kept ready: a step takes a few ms. */
const LIVE_CHUNK = 4;
const LIVE_AHEAD = 8;

/** generate's and followPath's options of a model driven by a control signal (the latent ERD, the VAE-LSTM). */
export const controlledOptions = {
  generate: {
    options: ['model', 'frames', 'seed', 'control'],
    check: (o: Record<string, unknown>) => (o.control === undefined ? {} : { control: checkControlSignal(o.control, o.frames as number) }),
  },
  followPath: {
    options: ['speed'],
    check: (o: Record<string, unknown>, gait: 'walk' | 'run') => ({ speed: checkPathSpeed(optional(o.speed, LATENT_PATH_SPEED[gait])) }),
  },
} as const;

export const descriptor: ModelDescriptor<LatentErdClient> = {
  kind: 'latent-erd',
  shortName: 'latent ERD',
  labels: { 'latent-erd': 'Latent ERD' },
  capabilities: ['generate', 'followPath', 'liveControl', 'cleanup'],
  createClient: (entry, threads) => new LatentErdClient({ threads, modelUrl: `models/${entry.id}.onnx`, infoUrl: `models/${entry.id}.json` }),

  generate: {
    ...controlledOptions.generate,
    async run(client, { seed, frames, control }, { signal }) {
      const m = await client.generate({ seed, frames, ...(control ? { control: control as Float64Array } : {}) }, { signal });
      return motionOf(m);
    },
  },

  followPath: {
    ...controlledOptions.followPath,
    async run(client, { points, gait, seed, speed, footLock, stroke }, options) {
      const m = await client.followPath({ points, gait, seed, speed, ...(footLock === undefined ? {} : { footLock }), ...(stroke ? { stroke } : {}) }, options);
      return { motion: motionOf(m), path: m.path, stats: pathStatsOf(m.stats) };
    },
    working: () => 'the latent ERD walks the path',
  },

  liveControl: {
    chunk: LIVE_CHUNK,
    ahead: LIVE_AHEAD,
    particles: false,
    start: (client, params, options) => client.controlStart(params, options),
    pull: (client, frames, { speed, heading }, options) => client.controlPull(frames, { speed, heading }, options),
    async simulate(client, request, options) {
      const m = await client.simulateControl(request, options);
      return { ...motionOf(m), speed: m.speed, heading: m.heading, computeMs: m.computeMsPerFrame };
    },
  },

  cleanup: {
    methods: ['manifold'],
    loading: 'motion autoencoder',
    run: (client, params, options) => client.denoise(params, options),
  },
};
