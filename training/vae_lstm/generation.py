"""How the VAE-LSTM makes motion (the page does the same with the exported graphs, web/runtime/vae_lstm/vaeLstmCore.ts):

- From the prior (Algorithm 1): z_1 ~ N(0, I) drawn from a seed, the control signal encoded in one pass, the
  cell run on its own state for every step, the canvas decoded in one pass. A model whose JSON's sampling has a
  `z1_prior` draws z_1 from that instead: the posteriors of K real training starts, one picked by the seed, plus
  N(0, sigma²) (draw_z1; prior_bank.py). The posteriors spread wider than N(0, I) (sd 1.3 a dimension), so N(0, I)
  draws sit near their middle and make motions alike; this mixture of posteriors draws what the cell was trained on.
- Or (the paper's other way, §3.3: "we could also consider sampling a latent variable z_t for each frame"):
  a latent per step in teacher mode, drawn as an AR(1) sequence with N(0, I) marginals and lag-one
  correlation rho (the posterior's own latents are correlated from step to step). Which a shipped model uses is
  in its JSON (`sampling`), chosen by measurement (docs/models/vae-lstm.md).
- A model trained with --free-mix also reads z_1 in every step of its free mode (free_latents; its JSON's sampling
  {"mode": "z1", "mix": …}), for prior samples and starts from 4 frames alike: the cell then cannot forget it.
- From the posterior: z_1 is the mean of q(z_1 | 4 initial frames). The inference network is convolutional
  and reads about 1.2 s around the first step, so the 4 frames are padded to SEED_PAD frames by repeating the
  last (a held pose), the same in training (free mode) and at test time.
- Long signals: the control encoder and the decoder are convolutional along time and take any length, and the
  cell carries its state from step to step, so a path of any length runs in one pass. The page runs the cell
  in chunks of CHUNK_STEPS steps (the 4 s training window), carrying the state between chunks; the report
  measures the seams at the chunk boundaries.
"""
from __future__ import annotations

import math

import numpy as np
import torch

from ..control import Rng

SEED_FRAMES = 4
SEED_PAD = 40  # frames: the first step's receptive field in the inference network reaches 39 frames ahead
CHUNK_STEPS = 30  # one 4 s window of 4-frame steps


def seed_window(frames: torch.Tensor) -> torch.Tensor:
    """The 4 initial frames (batch, 4, dim) padded to SEED_PAD frames by repeating the last."""
    return torch.cat([frames, frames[:, -1:].expand(-1, SEED_PAD - frames.shape[1], -1)], dim=1)


def pad_to_steps(control: torch.Tensor) -> tuple[torch.Tensor, int]:
    """The control (batch, frames, 3) padded by repeating its last frame to a multiple of 4 frames, and the
    original length."""
    n = control.shape[1]
    extra = -n % 4
    if extra:
        control = torch.cat([control, control[:, -1:].expand(-1, extra, -1)], dim=1)
    return control, n


def free_latents(z1: np.ndarray, steps: int, sampling: dict) -> tuple[np.ndarray | None, float]:
    """What the cell's free mode reads besides its state, for a model whose sampling (its JSON's) is "z1": the
    per-step latents and mix of a model trained with z1 in every step's content (`mix`, the training's
    --free-mix: mix · z1 + (1 − mix) · the previous state), else none (Algorithm 1)."""
    mix = float(sampling.get("mix", 0.0)) if sampling["mode"] == "z1" else 0.0
    return (np.repeat(np.asarray(z1, np.float32)[None], steps, 0), mix) if mix > 0 else (None, 0.0)


def draw_z1(rng: Rng, latent: int, z1_prior: dict | None = None) -> np.ndarray:
    """z1 (latent,): `latent` normals of `rng`, or with a `z1_prior` (the JSON's sampling.z1_prior: K "means" and one
    "sigma" per dimension) one uniform picks mean k = floor(u·K), then means[k] + sigma · the normals."""
    if z1_prior is None:
        return np.array([rng.normal() for _ in range(latent)], np.float32)
    means, sigma = z1_prior["means"], z1_prior["sigma"]
    k = min(int(rng.uniform() * len(means)), len(means) - 1)
    return np.array([means[k][i] + sigma[i] * rng.normal() for i in range(latent)], np.float32)


def prior_latents(seed: int, latent: int, steps: int = 0, rho: float = 0.0, z1_prior: dict | None = None) -> tuple[np.ndarray, np.ndarray | None]:
    """z1 (latent,) drawn from `seed` by the page's random source (control.Rng; draw_z1), and with `steps` the
    per-step latents (steps, latent): z1 first, then rho · previous + sqrt(1 − rho²) · a new draw, in the
    same stream (web/runtime/vae_lstm/vaeLstmCore.ts priorLatents draws the same)."""
    rng = Rng(seed)
    z1 = draw_z1(rng, latent, z1_prior)
    if not steps:
        return z1, None
    zs = np.empty((steps, latent), np.float32)
    zs[0] = z1
    keep, new = rho, math.sqrt(1 - rho * rho)
    for t in range(1, steps):
        zs[t] = [keep * float(zs[t - 1, i]) + new * rng.normal() for i in range(latent)]
    return z1, zs
