// The acLSTM (Zhou et al.: an auto-conditioned LSTM for endless dance) as the page offers it (and any dance model
// of this kind, e.g. a dropped dance pack): generate in a style, and Dance mode's endless stream. Deterministic models: the seed picks
// the seed motion; a sampled one (head "mdn", issue 42) also seeds its random draws with it.

import { describeValue } from '../../motion/describe';
import { clientFiles, motionOf, type ModelDescriptor } from '../descriptor';
import { DanceClient } from './danceClient';

export const descriptor: ModelDescriptor<DanceClient> = {
  kind: 'aclstm',
  shortName: 'acLSTM',
  labels: { 'aclstm-mdn': 'acLSTM, phrase sampling', aclstm: 'acLSTM (deterministic)' },
  capabilities: ['generate', 'dance'],
  createClient: (entry, threads) => new DanceClient({ ...clientFiles(entry, threads), model: entry.id }),

  generate: {
    options: ['model', 'style', 'frames', 'seed'],
    // No temperature (a sampled model has its own per-style settings) and no refiner: say so rather than silently ignoring the option.
    refused: {
      temperature:
        'temperature is not meaningful for acLSTM models: a deterministic one has no randomness (the seed only picks the seed motion), ' +
        'a sampled one draws with its own per-style settings (the seed also seeds the draws); leave it out',
      refine: 'refine is not available for acLSTM models (there is no refiner for dance); leave it out',
    },
    check(o, entry) {
      const styles = entry.styles ?? [];
      if (o.style === undefined) throw new TypeError(`style is required for model "${entry.id}" (styles: ${styles.join(', ')})`);
      if (typeof o.style !== 'string' || !styles.includes(o.style)) {
        throw new RangeError(`unknown style ${describeValue(o.style)} for model "${entry.id}" (styles: ${styles.join(', ')})`);
      }
      return { style: o.style };
    },
    async run(client, { style, seed, frames }, { signal }) {
      return motionOf(await client.generate({ style: style as string, seed, frames }, { signal }));
    },
  },
};
