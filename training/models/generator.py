"""Contact-aware LSTM with a Gaussian-mixture output (Wang, Chai, Xia §4.1, Fig. 3).

FC1 -> FC2 -> LSTM1 -> LSTM2 -> FC3, where FC3 gives M mixture weights (softmax of logits),
means and log standard deviations of a diagonal Gaussian over the next frame's features (eq. 6-7).
All features, contacts included, live in normalised units (zero mean, unit variance per feature).
"""
from __future__ import annotations

import math

import torch
from torch import nn

LOG_SIGMA_MIN = -7.0  # keeps exp(log sigma) away from zero so the NLL cannot run off to -inf


class MixtureLSTM(nn.Module):
    def __init__(self, dim: int, hidden: int = 256, mixtures: int = 5, dropout: float = 0.0):
        super().__init__()
        self.dim, self.hidden, self.mixtures = dim, hidden, mixtures
        self.fc1 = nn.Linear(dim, hidden)
        self.fc2 = nn.Linear(hidden, hidden)
        self.lstm = nn.LSTM(hidden, hidden, num_layers=2, batch_first=True, dropout=dropout)
        self.drop = nn.Dropout(dropout)  # active in training only; the exported step runs in eval mode
        self.fc3 = nn.Linear(hidden, mixtures * (1 + 2 * dim))

    def zero_state(self, batch: int) -> tuple[torch.Tensor, torch.Tensor]:
        z = torch.zeros(2, batch, self.hidden)
        return z, z.clone()

    def forward(self, x: torch.Tensor, state=None):
        """x (batch, time, dim) -> logits (b, t, M), mu (b, t, M, dim), log_sigma (b, t, M, dim), (h, c)."""
        b, t, _ = x.shape
        y = self.drop(torch.relu(self.fc2(self.drop(torch.relu(self.fc1(x))))))
        y, state = self.lstm(y, state)
        out = self.fc3(self.drop(y))
        m, d = self.mixtures, self.dim
        logits = out[..., :m]
        mu = out[..., m:m + m * d].reshape(b, t, m, d)
        log_sigma = out[..., m + m * d:].reshape(b, t, m, d).clamp(min=LOG_SIGMA_MIN)
        return logits, mu, log_sigma, state


def mixture_nll(logits, mu, log_sigma, target) -> torch.Tensor:
    """Negative log-likelihood (eq. 8) per frame, shape (b, t); target (b, t, dim)."""
    z = (target.unsqueeze(-2) - mu) * torch.exp(-log_sigma)
    log_comp = -0.5 * (z * z).sum(-1) - log_sigma.sum(-1) - 0.5 * mu.shape[-1] * math.log(2 * math.pi)
    return -torch.logsumexp(torch.log_softmax(logits, dim=-1) + log_comp, dim=-1)


class GeneratorStep(nn.Module):
    """One step with explicit state, for ONNX: (x (B, D), h (2, B, H), c (2, B, H)) ->
    (weights (B, M), mu (B, M, D), sigma (B, M, D), h', c')."""

    def __init__(self, model: MixtureLSTM):
        super().__init__()
        self.model = model

    def forward(self, x, h, c):
        logits, mu, log_sigma, (h2, c2) = self.model(x.unsqueeze(1), (h, c))
        return torch.softmax(logits[:, 0], dim=-1), mu[:, 0], torch.exp(log_sigma[:, 0]), h2, c2
