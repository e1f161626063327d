// The VAE-LSTM (Habibie et al.: the motion for a whole control signal, from a latent sample) as the page
// offers it: generate under a control signal, and a drawn path turned into one control signal and walked in
// one pass (Vary draws another sample). It takes no live control.

import { clientFiles, type ModelDescriptor } from '../descriptor';
import { controlledModel } from '../latent_erd/descriptor';
import { VaeLstmClient } from './vaeLstmClient';

/** Its runs stop stepping after about this long (docs/models/vae-lstm.md: the corpus's runs are no longer). */
const RUN_SECONDS = 2;

const controlled = controlledModel<VaeLstmClient>('the VAE-LSTM walks the path');

export const descriptor: ModelDescriptor<VaeLstmClient> = {
  kind: 'vae-lstm',
  shortName: 'VAE-LSTM',
  labels: { 'vae-lstm': 'VAE-LSTM' },
  capabilities: ['generate', 'followPath'],
  createClient: (entry, threads) => new VaeLstmClient(clientFiles(entry, threads)),

  generate: controlled.generate,
  followPath: {
    ...controlled.followPath,
    immediate: true,
    varies: true,
    limit: (gait, seconds) =>
      gait === 'run' && seconds > RUN_SECONDS ? `its runs stop stepping after about ${RUN_SECONDS} s (the captured runs it learned from are that short)` : null,
  },

  noLiveControl: 'the VAE-LSTM makes the whole motion for a whole control signal and takes no live control: use followPath or generate({ model: "vae-lstm", control })',
};
