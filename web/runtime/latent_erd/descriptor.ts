// The latent ERD (Yearsley: a recurrent controller in the latent space of a convolutional motion
// autoencoder, Holden et al.) as the page offers it: generate under a control signal, closed-loop path
// following and live control (a control signal from where the character stands, every latent step), and
// the autoencoder's manifold clean-up, all in its one worker.

import { checkControlSignal } from '../../model/latentErdInfo';
import { optional } from '../../optimizer/options';
import type { Motion } from '../../motion/types';
import type { Gait } from '../../optimizer/pathFollower';
import { clientFiles, motionOf, pathStatsOf, type ModelClientBase, type ModelDescriptor, type PathStats } from '../descriptor';
import type { ProgressOptions, RequestOptions } from '../worker/workerClient';
import { LatentErdClient } from './latentErdClient';
import { checkPathSpeed, LATENT_PATH_SPEED } from './latentErdRequests';

/** One latent step of 4 frames per live pull, and 8 frames (0.27 s) kept ready: a step takes a few ms. */
const LIVE_CHUNK = 4;
const LIVE_AHEAD = 8;

/** What the clients of models driven by a control signal (the latent ERD, the VAE-LSTM) answer alike. */
interface ControlledClient extends ModelClientBase {
  generate(params: { seed: number; frames: number; control?: Float64Array }, options: RequestOptions): Promise<Motion>;
  followPath(
    params: { points: [number, number][]; gait: Gait; seed: number; speed?: number; footLock?: boolean; stroke?: boolean },
    options: ProgressOptions,
  ): Promise<Motion & { path: Float32Array; stats: PathStats }>;
}

/**
 * generate and followPath of a model driven by a control signal: generate takes an optional per-frame control,
 * followPath a speed; `working` is Path mode's progress line.
 */
export function controlledModel<C extends ControlledClient>(working: string): Required<Pick<ModelDescriptor<C>, 'generate' | 'followPath'>> {
  return {
    generate: {
      options: ['model', 'frames', 'seed', 'control'],
      check: (o) => (o.control === undefined ? {} : { control: checkControlSignal(o.control, o.frames as number) }),
      async run(client, { seed, frames, control }, { signal }) {
        return motionOf(await client.generate({ seed, frames, ...(control ? { control: control as Float64Array } : {}) }, { signal }));
      },
    },
    followPath: {
      options: ['speed'],
      check: (o, gait) => ({ speed: checkPathSpeed(optional(o.speed, LATENT_PATH_SPEED[gait])) }),
      defaultSpeed: LATENT_PATH_SPEED,
      async run(client, { points, gait, seed, speed, footLock, stroke }, options) {
        const m = await client.followPath({ points, gait, seed, speed, ...(footLock === undefined ? {} : { footLock }), ...(stroke ? { stroke } : {}) }, options);
        return { motion: motionOf(m), path: m.path, stats: pathStatsOf(m.stats) };
      },
      working: () => working,
    },
  };
}

export const descriptor: ModelDescriptor<LatentErdClient> = {
  kind: 'latent-erd',
  shortName: 'latent ERD',
  labels: { 'latent-erd': 'Latent ERD' },
  capabilities: ['generate', 'followPath', 'liveControl', 'cleanup'],
  createClient: (entry, threads) => new LatentErdClient(clientFiles(entry, threads)),

  ...controlledModel<LatentErdClient>('the latent ERD walks the path'),

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
