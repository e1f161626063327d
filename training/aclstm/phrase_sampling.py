"""Phrase-scale sampling of the mdn head (issue 42's first lever): randomness at the scale of a dance phrase,
not of a frame.

Each rollout row holds one mixture component for a phrase and draws its frames from that component alone:
  * the component is drawn from the mixture weights, among the components whose weight is at least `threshold`
    (the largest one when none is), and held;
  * it is redrawn when its weight at the current frame falls below `threshold` (the network has moved on: the
    held component no longer explains what comes next), or when it has been held `max_hold` frames (at most a
    phrase, 0.5–2 s at 30 fps), never before `min_hold` frames;
  * within the held component a frame is mean + temperature · σ · w, where w is AR(1) over frames
    (w ← ρ·w + √(1-ρ²)·n, each w still N(0, 1)), so the draws wander smoothly instead of shaking; w runs on
    across a redraw.
Temperature and max_hold may differ per row (per style, `PhraseParams`). Everything is seeded by one
torch.Generator, so a rollout is reproducible: each step takes one uniform per row (torch.rand), used when the row
redraws, then one standard normal per row and channel (torch.randn), the AR(1) innovations; `step` also takes them
as arguments, which is how the ONNX graph is checked against it.

The draw is by inverse CDF: with `allowed` the weights at or above the threshold (the largest weight's one-hot when
none is), the component is the first k whose cumulative allowed weight exceeds the uniform times the total, i.e.
the number of k whose cumulative sum is at most u · total (u in [0, 1), so some k always exceeds it). The same
uniforms give the same draws in torch, in the ONNX graph (training/aclstm/graph.py, mdn_graph: CumSum, LessOrEqual,
ReduceSum) and in the page.

ONNX, for the page: the mdn graph runs this rule inside its Loop with the uniforms and normals as inputs, the
sampler's state (held, age, wander) in and out, and the output filter of training/aclstm/jitter_filter.py after it
(the filtered frames are shown, the raw draws fed back); the interface is the graph module's docstring.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import torch


@dataclass(frozen=True)
class PhraseParams:
    temperature: float = 0.35  # σ of the held component times this
    max_hold: int = 30         # frames: redraw at least this often (30 = 1 s at 30 fps)
    rho: float = 0.9           # AR(1) coefficient of the within-component normals (0: white)
    threshold: float = 0.05    # redraw when the held component's weight falls below this
    min_hold: int = 5          # frames: no redraw before this (a phrase is never shorter)

    def to_json(self) -> dict:
        return asdict(self)


class PhraseSampler:
    """The phrase rule over a batch of rollouts; `step` turns one frame's mixture into one frame per row."""

    def __init__(self, params: list[PhraseParams], dim: int, generator: torch.Generator | None = None,
                 wander: torch.Tensor | None = None):
        """`wander`: the AR(1) state to start from (B, dim); default one standard normal draw per row and channel."""
        self.params = params
        self.generator = generator
        batch = len(params)
        self.temperature = torch.tensor([p.temperature for p in params]).unsqueeze(-1)
        self.rho = torch.tensor([p.rho for p in params]).unsqueeze(-1)
        self.threshold = torch.tensor([p.threshold for p in params])
        self.max_hold = torch.tensor([p.max_hold for p in params])
        self.min_hold = torch.tensor([p.min_hold for p in params])
        self.held = torch.full((batch,), -1, dtype=torch.long)
        self.age = torch.zeros(batch, dtype=torch.long)
        self.wander = torch.randn((batch, dim), generator=generator) if wander is None else torch.as_tensor(wander).clone()
        self.redraws = torch.zeros(batch, dtype=torch.long)  # how many times each row drew a component

    def draw_components(self, weights: torch.Tensor, uniforms: torch.Tensor) -> torch.Tensor:
        """One component per row from `weights` (B, K), among those at or above the row's threshold, by inverse CDF
        of `uniforms` (B,) in [0, 1)."""
        return inverse_cdf_draw(weights, self.threshold, uniforms)

    def step(self, logits: torch.Tensor, mu: torch.Tensor, log_sigma: torch.Tensor,
             uniforms: torch.Tensor | None = None, normals: torch.Tensor | None = None) -> torch.Tensor:
        """logits (B, K), mu and log_sigma (B, K, D) -> one frame per row (B, D). `uniforms` (B,) and `normals`
        (B, D): this step's randoms (default drawn from the generator, the uniforms first)."""
        if uniforms is None:
            uniforms = torch.rand(len(logits), generator=self.generator)
        if normals is None:
            normals = torch.randn(self.wander.shape, generator=self.generator)
        weights = torch.softmax(logits, -1)
        rows = torch.arange(len(weights))
        fresh = self.held < 0
        held_weight = weights[rows, self.held.clamp(min=0)]
        redraw = fresh | (self.age >= self.max_hold) | ((self.age >= self.min_hold) & (held_weight < self.threshold))
        if redraw.any():
            self.held = torch.where(redraw, self.draw_components(weights, uniforms), self.held)
            self.age = torch.where(redraw, torch.zeros_like(self.age), self.age)
            self.redraws += redraw.long()
        self.wander = self.rho * self.wander + torch.sqrt(1 - self.rho ** 2) * normals
        self.age += 1
        return mu[rows, self.held] + self.temperature * torch.exp(log_sigma[rows, self.held]) * self.wander


def inverse_cdf_draw(weights: torch.Tensor, threshold: torch.Tensor, uniforms: torch.Tensor) -> torch.Tensor:
    """weights (B, K), threshold (B,), uniforms (B,) -> component (B,): the number of k whose cumulative allowed
    weight is at most u · total (the first k whose cumulative share exceeds u), allowed = the weights at or above
    the threshold, or the largest weight's one-hot where none is."""
    allowed = weights * (weights >= threshold.unsqueeze(-1))
    none = allowed.sum(-1, keepdim=True) <= 0
    top = torch.nn.functional.one_hot(weights.argmax(-1), weights.shape[-1]).to(weights.dtype)
    allowed = torch.where(none, top, allowed)
    cumulative = torch.cumsum(allowed, -1)
    return (cumulative <= uniforms.unsqueeze(-1) * cumulative[:, -1:]).sum(-1)


def phrase_rollout(model, meta: dict, seed_frames: np.ndarray, styles: list[str], frames: int,
                   params: list[PhraseParams], seed: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """An mdn-head model warmed up on the seeds (batch, seed, dim; physical units), then fed its own phrase-scale
    draws for `frames` frames: (features (batch, frames, dim) in physical units, component draws per row)."""
    mean, std = np.array(meta["mean"], np.float32), np.array(meta["std"], np.float32)
    style = torch.eye(len(meta["styles"]))[[meta["styles"].index(s) for s in styles]]
    x = torch.from_numpy(((seed_frames - mean) / std).astype(np.float32))
    out = np.zeros((len(x), frames, x.shape[-1]), np.float32)
    sampler = PhraseSampler(params, x.shape[-1], torch.Generator().manual_seed(seed))
    with torch.no_grad():
        logits, mu, log_sigma, state = model.mixture(x, style)
        for t in range(frames):
            y = sampler.step(logits[:, -1], mu[:, -1], log_sigma[:, -1])
            out[:, t] = y.numpy()
            logits, mu, log_sigma, state = model.mixture(y.unsqueeze(1), style, state)
    return out * std + mean, sampler.redraws.numpy()
