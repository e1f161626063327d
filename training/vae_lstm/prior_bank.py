"""The z1 prior a shipped VAE-LSTM draws from (its JSON's sampling.z1_prior; generation.draw_z1): the posteriors of
K random starts of the training clips, each the mean of q(z1 | 4 frames) as the free mode was trained from
(generation.seed_window), and one sigma per dimension, the root mean square of those posteriors' own sigmas.

Why not N(0, I) (Algorithm 1): the posteriors of real starts spread wider (sd about 1.3 a dimension, their norm
14.3 against N(0, I)'s 11.3), so N(0, I) draws fall near the middle of what the cell was trained on and decode to
motions alike (docs/models/vae-lstm.md, "Variations from the prior"). A draw from this mixture of posteriors is
a draw from the aggregate posterior the prior stands for, and its K means are numbers, not motions: the page
keeps no clip.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..data.windows import WindowCorpus
from ..onnx.sessions import cpu_session
from .generation import SEED_FRAMES, SEED_PAD

PRIOR_STARTS = 64  # K: enough that ten Vary presses rarely meet the same start (measured: 32 gave less spread)
PRIOR_SEED = 0


def posterior_prior(inference_graph: Path, corpus: WindowCorpus, starts: int = PRIOR_STARTS, seed: int = PRIOR_SEED) -> dict:
    """sampling.z1_prior for the model whose inference graph is `inference_graph`, from `starts` random 4-frame
    starts of the corpus's training rows (normalised, as the graph reads them)."""
    session = cpu_session(inference_graph)
    rng = np.random.default_rng(seed)
    means, variances = [], []
    for k in rng.choice(len(corpus.train), starts, replace=False):
        rows = corpus.train[k]
        a = int(rng.integers(0, len(rows) - SEED_FRAMES + 1))
        start = rows[a:a + SEED_FRAMES]
        x = np.concatenate([start, np.repeat(start[-1:], SEED_PAD - SEED_FRAMES, 0)]).astype(np.float32)
        mean, log_var = session.run(["mean", "log_var"], {"rows": x[None]})
        means.append(mean[0, 0])
        variances.append(np.exp(log_var[0, 0]))
    sigma = np.sqrt(np.mean(variances, axis=0))
    return {"kind": "posteriors", "starts": starts, "seed": seed,
            "about": "z1 = means[k] + sigma * n: k = floor(u * K) for the seed's first uniform, n its next normals "
                     "(the posterior means of K random 4-frame starts of the training clips; sigma their own, root mean square)",
            "means": np.round(np.array(means, np.float64), 4).tolist(), "sigma": np.round(sigma.astype(np.float64), 4).tolist()}
