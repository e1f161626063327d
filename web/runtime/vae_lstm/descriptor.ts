// The VAE-LSTM (Habibie et al.: the motion for a whole control signal, from a latent sample) as the page
// offers it: generate under a control signal, and a drawn path turned into one control signal and walked in
// one pass (Vary draws another sample). It takes no live control.

import { motionOf, pathStatsOf, type ModelDescriptor } from '../descriptor';
import { controlledOptions } from '../latent_erd/descriptor';
import { VaeLstmClient } from './vaeLstmClient';

/** Its runs stop stepping after about this long (docs/models/vae-lstm.md: the corpus's runs are no longer). */
const RUN_SECONDS = 2;

export const descriptor: ModelDescriptor<VaeLstmClient> = {
  kind: 'vae-lstm',
  shortName: 'VAE-LSTM',
  labels: { 'vae-lstm': 'VAE-LSTM' },
  capabilities: ['generate', 'followPath'],
  createClient: (entry, threads) => new VaeLstmClient({ threads, modelUrl: `models/${entry.id}.onnx`, infoUrl: `models/${entry.id}.json` }),

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
    immediate: true,
    varies: true,
    working: () => 'the VAE-LSTM walks the path',
    limit: (gait, seconds) =>
      gait === 'run' && seconds > RUN_SECONDS ? `its runs stop stepping after about ${RUN_SECONDS} s (the captured runs it learned from are that short)` : null,
  },

  noLiveControl: 'the VAE-LSTM makes the whole motion for a whole control signal and takes no live control: use followPath or generate({ model: "vae-lstm", control })',
};
