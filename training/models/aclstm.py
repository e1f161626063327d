"""Auto-conditioned LSTM (Zhou et al.): a stack of LSTMs with a linear decoder over joint positions.

One model serves every dance style: a one-hot style vector is appended to each frame's input.
The same network trained with teacher forcing only is the paper's "vanilla" baseline.

Two output heads: "mean" (the paper's: the next frame, trained by squared error) and "gauss" (issue 18's
pilot lever: a diagonal Gaussian over the next frame, trained by likelihood, whose samples are fed back, since
regressing the mean pulls a long rollout toward a static pose).
"""
from __future__ import annotations

import torch
from torch import nn

LOG_SIGMA_RANGE = (-5.0, 1.0)  # the Gaussian head's log standard deviation, normalised units


def draw(mu: torch.Tensor, log_sigma: torch.Tensor, temperature: float, normals: torch.Tensor) -> torch.Tensor:
    """The Gaussian head's draw from given standard normals: mu + temperature · sigma · normals (the exported
    graph computes the same, training/aclstm/graph.py)."""
    return mu + temperature * torch.exp(log_sigma) * normals


class DanceLSTM(nn.Module):
    def __init__(self, dim: int, styles: int, hidden: int = 256, layers: int = 3, head: str = "mean"):
        super().__init__()
        if head not in ("mean", "gauss"):
            raise ValueError(f"unknown head {head!r}: use 'mean' or 'gauss'")
        self.dim, self.styles, self.hidden, self.layers, self.head = dim, styles, hidden, layers, head
        self.lstm = nn.LSTM(dim + styles, hidden, num_layers=layers, batch_first=True)
        self.decoder = nn.Linear(hidden, dim if head == "mean" else 2 * dim)

    def zero_state(self, batch: int) -> tuple[torch.Tensor, torch.Tensor]:
        z = torch.zeros(self.layers, batch, self.hidden)
        return z, z.clone()

    def distribution(self, x: torch.Tensor, style: torch.Tensor, state=None):
        """x (batch, time, dim), style (batch, styles) -> mean of the next frames (batch, time, dim), their log
        standard deviation (same shape; None for the mean head), (h, c)."""
        s = style.unsqueeze(1).expand(-1, x.shape[1], -1)
        y, state = self.lstm(torch.cat([x, s], dim=-1), state)
        out = self.decoder(y)
        if self.head == "mean":
            return out, None, state
        mu, log_sigma = out.split(self.dim, dim=-1)
        return mu, log_sigma.clamp(*LOG_SIGMA_RANGE), state

    def forward(self, x: torch.Tensor, style: torch.Tensor, state=None, sample: bool = False,
                generator: torch.Generator | None = None, temperature: float = 1.0):
        """x (batch, time, dim), style (batch, styles) -> next frames (batch, time, dim), (h, c): the mean, or
        with `sample` a draw from the Gaussian head with its σ scaled by `temperature` (the mean head has
        nothing to draw)."""
        mu, log_sigma, state = self.distribution(x, style, state)
        if sample and log_sigma is not None:
            mu = draw(mu, log_sigma, temperature, torch.randn(mu.shape, generator=generator))
        return mu, state

    def auto_conditioned(self, x: torch.Tensor, style: torch.Tensor, ground_truth: int, condition: int,
                         feedback_noise: float = 0.0) -> torch.Tensor:
        """The acRNN unroll: `ground_truth` real input frames, then `condition` frames of the network's own
        output fed back as input, alternating; returns the prediction (the mean) for every input position.
        With condition=0 this is plain teacher forcing. Gradients flow through the fed-back frames.
        `feedback_noise`: Gaussian noise (normalised units) added to each fed-back frame, as at generation
        with the inference-time lever (the prediction itself is returned clean)."""
        return self.auto_conditioned_distribution(x, style, ground_truth, condition, feedback_noise)[0]

    def auto_conditioned_distribution(self, x, style, ground_truth: int, condition: int, feedback_noise: float = 0.0):
        """auto_conditioned, returning (mean, log sigma or None) for every input position. The Gaussian head
        feeds back a reparameterised draw, so gradients flow through the sample."""
        if condition == 0:
            mu, log_sigma, _ = self.distribution(x, style)
            return mu, log_sigma
        mus, sigmas, state, t, total = [], [], None, 0, x.shape[1]

        def step(inp, state):
            mu, log_sigma, state = self.distribution(inp, style, state)
            mus.append(mu)
            sigmas.append(log_sigma)
            fed = mu[:, -1:] if log_sigma is None else draw(mu[:, -1:], log_sigma[:, -1:], 1.0, torch.randn_like(mu[:, -1:]))
            return fed, state

        while t < total:
            n = min(ground_truth, total - t)
            prev, state = step(x[:, t:t + n], state)
            t += n
            for _ in range(min(condition, total - t)):
                fed = prev + feedback_noise * torch.randn_like(prev) if feedback_noise else prev
                prev, state = step(fed, state)
                t += 1
        return torch.cat(mus, dim=1), None if self.head == "mean" else torch.cat(sigmas, dim=1)


class DanceStep(nn.Module):
    """One step with explicit state, for ONNX: (x (B, dim), style (B, styles), h, c (layers, B, H)) -> (y, h', c')."""

    def __init__(self, model: DanceLSTM):
        super().__init__()
        self.model = model

    def forward(self, x, style, h, c):
        y, (h2, c2) = self.model(x.unsqueeze(1), style, (h, c))
        return y[:, 0], h2, c2
