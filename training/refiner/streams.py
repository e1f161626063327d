"""Generated motion for training the refiner: streams sampled from the generator in torch (cached in
cache/refiner_generated_*.npz) and windows drawn from them or from real sequences."""
from __future__ import annotations

import argparse

import numpy as np
import torch
from tqdm import tqdm

from ..data.locomotion import Corpus
from ..generator.sampling import NOISE_CORRELATION
from ..models.generator import MixtureLSTM, StyledGenerator
from ..paths import DEFAULT_CACHE

TEMPERATURE = 0.5


def sample_torch(logits, mu, log_sigma, temperature: float, gen: torch.Generator, previous: torch.Tensor | None = None,
                 correlation: float = 0.0) -> tuple[torch.Tensor, torch.Tensor]:
    """generator/sampling's rule in torch: weights sharpened by 1/temperature, sigmas scaled by temperature, the normals
    held over frames (z = correlation * previous + sqrt(1 - correlation^2) * fresh, as sampling.held_normals).
    Returns the frames and the normals z to pass as `previous` next frame."""
    p = torch.softmax(torch.log_softmax(logits, -1) / temperature, -1)
    k = torch.multinomial(p, 1, generator=gen)[:, 0]
    rows = torch.arange(len(k))
    z = torch.randn(mu.shape[0], mu.shape[-1], generator=gen)
    if previous is not None:
        z = correlation * previous + (1.0 - correlation * correlation) ** 0.5 * z
    return mu[rows, k] + torch.exp(log_sigma[rows, k]) * temperature * z, z


@torch.no_grad()
def generate_streams(model: MixtureLSTM, corpus: Corpus, streams: int, frames: int, warmup: int,
                     temperature: float, seed: int, batch: int = 512, correlation: float = NOISE_CORRELATION,
                     pool: list[int] | None = None) -> np.ndarray:
    """(streams, frames + 1, D) normalised: frame 0 is the last real warm-up frame, then `frames` sampled ones.
    Each stream is teacher-forced on `warmup` real frames of a random training window (of the sequences `pool`
    names, default all), then runs free with the contact bits snapped to clean 0/1 and its normals held over frames
    with `correlation`, as generator/shipped.ShippedGenerator (and the page) sample."""
    rng = np.random.default_rng(seed)
    gen = torch.Generator().manual_seed(seed)
    mean, std = torch.tensor(corpus.mean, dtype=torch.float32), torch.tensor(corpus.std, dtype=torch.float32)
    lo, hi = (0 - mean[-2:]) / std[-2:], (1 - mean[-2:]) / std[-2:]
    out = np.zeros((streams, frames + 1, len(mean)), np.float32)
    long_enough = [k for k in (range(len(corpus.train)) if pool is None else pool) if len(corpus.train[k]) > warmup]
    p = corpus.weights[long_enough] / corpus.weights[long_enough].sum()
    for a in tqdm(range(0, streams, batch), desc="generating", unit="batch"):
        b = min(batch, streams - a)
        real = np.zeros((b, warmup, len(mean)), np.float32)
        for i, k in enumerate(rng.choice(long_enough, size=b, p=p)):
            s = rng.integers(0, len(corpus.train[k]) - warmup + 1)
            real[i] = corpus.train[k][s:s + warmup]
        x = torch.from_numpy(real)
        logits, mu, log_sigma, state = model(x)
        out[a:a + b, 0] = real[:, -1]
        logits, mu, log_sigma = logits[:, -1], mu[:, -1], log_sigma[:, -1]
        z = None
        for t in range(frames):
            x, z = sample_torch(logits, mu, log_sigma, temperature, gen, z, correlation)
            x[:, -2:] = torch.where(x[:, -2:] * std[-2:] + mean[-2:] > 0.5, hi, lo)
            out[a:a + b, t + 1] = x.numpy()
            logits, mu, log_sigma, state = model(x.unsqueeze(1), state)
            logits, mu, log_sigma = logits[:, 0], mu[:, 0], log_sigma[:, 0]
    return out


def generated_cache(model: MixtureLSTM, corpus: Corpus, args: argparse.Namespace, kind: str,
                    styles: int = 0, tag: str = "") -> list[np.ndarray]:
    """Cached generated streams: 'train' (many short streams plus some long ones) or 'valid' (own seed). A style
    model (`styles` > 0, its corpus a StyleCorpus) draws each style's share of the streams (style_shares) in that
    style, warmed up on that style's training sequences; `tag` names the model in the cache file."""
    if kind == "train":
        specs = [(args.streams, args.window + 30, 1), (args.long_streams, 1200, 2)]
    else:
        specs = [(256, args.window, 101)]
    arrays = []
    for streams, frames, seed in specs:
        rho = f"_rho{NOISE_CORRELATION}" if NOISE_CORRELATION else ""  # the streams before held normals had no suffix
        path = DEFAULT_CACHE / f"refiner_generated{tag}_t{TEMPERATURE}{rho}_{streams}x{frames}_w{args.warmup}_s{seed}.npz"
        if path.exists():
            arrays.append(np.load(path)["x"])
            continue
        if styles:
            x = np.concatenate([
                generate_streams(StyledGenerator(model, s), corpus, count, frames, args.warmup, TEMPERATURE, seed + 1000 * s,
                                 pool=[k for k, style in enumerate(corpus.train_styles) if style == s])
                for s, count in enumerate(style_shares(corpus, streams, styles)) if count])
        else:
            x = generate_streams(model, corpus, streams, frames, args.warmup, TEMPERATURE, seed)
        DEFAULT_CACHE.mkdir(parents=True, exist_ok=True)
        np.savez_compressed(path, x=x)
        arrays.append(x)
    return arrays


def style_shares(corpus, streams: int, styles: int) -> list[int]:
    """How many of `streams` each style draws: in proportion to the style's share of the real windows' sampling weight
    (corpus.weights), so that D sees the same mix of styles in real and generated windows (equal shares for the shipped
    style model; a checkpoint trained with --cmu-share gives CMU its share). Rounded by largest remainders."""
    weight = np.bincount(corpus.train_styles, weights=corpus.weights, minlength=styles)
    exact = streams * weight / weight.sum()
    counts = np.floor(exact).astype(int)
    counts[np.argsort(counts - exact)[:streams - counts.sum()]] += 1
    return counts.tolist()


class WindowSampler:
    """Windows of window + 1 frames (x_prev and the window) from a list of (streams, frames, D) arrays or
    from a list of sequences (frames, D) with weights."""

    def __init__(self, seqs: list[np.ndarray], window: int, weights: np.ndarray | None = None):
        self.seqs = [s for s in seqs if len(s) >= window + 1]
        w = np.array([len(s) - window for s in self.seqs], np.float64) if weights is None else \
            np.array([wt for s, wt in zip(seqs, weights) if len(s) >= window + 1], np.float64)
        self.p = w / w.sum()
        self.window = window

    def __call__(self, rng: np.random.Generator, size: int) -> tuple[torch.Tensor, torch.Tensor]:
        out = np.zeros((size, self.window + 1, self.seqs[0].shape[-1]), np.float32)
        for i, k in enumerate(rng.choice(len(self.seqs), size=size, p=self.p)):
            s = rng.integers(0, len(self.seqs[k]) - self.window)
            out[i] = self.seqs[k][s:s + self.window + 1]
        t = torch.from_numpy(out)
        return t[:, 1:], t[:, 0]


def streams_to_seqs(arrays: list[np.ndarray]) -> list[np.ndarray]:
    return [s for a in arrays for s in a]
