"""Contact-aware LSTM with a Gaussian-mixture output (Wang, Chai, Xia §4.1, Fig. 3).

FC1 -> FC2 -> LSTM1 -> LSTM2 -> FC3, where FC3 gives M mixture weights (softmax of logits),
means and log standard deviations of a diagonal Gaussian over the next frame's features (eq. 6-7).
All features, contacts included, live in normalised units (zero mean, unit variance per feature).

Optional style input (issue 39): with `styles` > 0 the model holds one learned embedding of `style_dim` values per
style, concatenated to the frame at every step before FC1 (so FC1 takes dim + style_dim inputs). With the default
styles = 0 the network is exactly the one without it (same parameter names and shapes), which the shipped generator,
its export and training.own use.
"""
from __future__ import annotations

import math

import torch
from torch import nn

LOG_SIGMA_MIN = -7.0  # keeps exp(log sigma) away from zero so the NLL cannot run off to -inf


class MixtureLSTM(nn.Module):
    def __init__(self, dim: int, hidden: int = 256, mixtures: int = 5, dropout: float = 0.0, styles: int = 0,
                 style_dim: int = 8):
        super().__init__()
        self.dim, self.hidden, self.mixtures = dim, hidden, mixtures
        self.styles, self.style_dim = styles, (style_dim if styles > 0 else 0)
        self.fc1 = nn.Linear(dim + self.style_dim, hidden)
        self.fc2 = nn.Linear(hidden, hidden)
        self.lstm = nn.LSTM(hidden, hidden, num_layers=2, batch_first=True, dropout=dropout)
        self.drop = nn.Dropout(dropout)  # active in training only; the exported step runs in eval mode
        self.fc3 = nn.Linear(hidden, mixtures * (1 + 2 * dim))
        if styles > 0:  # registered last, so the networks without styles keep their parameter order too
            self.style = nn.Embedding(styles, style_dim)

    def zero_state(self, batch: int) -> tuple[torch.Tensor, torch.Tensor]:
        z = torch.zeros(2, batch, self.hidden)
        return z, z.clone()

    def forward(self, x: torch.Tensor, state=None, style: torch.Tensor | None = None):
        """x (batch, time, dim) -> logits (b, t, M), mu (b, t, M, dim), log_sigma (b, t, M, dim), (h, c).
        style: (batch,) style ids, or (batch, styles) float weights over the styles (a one-hot, or a convex combination
        of one-hots blending the embeddings: embedding = style @ E, as the exported step computes it); required when the
        model has styles and refused when it has none."""
        b, t, _ = x.shape
        if self.styles > 0:
            if style is None:
                raise ValueError("this generator has a style input: pass style ids (batch,) or weights (batch, styles)")
            if style.is_floating_point():
                embedding = style.reshape(b, self.styles) @ self.style.weight
            else:
                embedding = self.style(style.reshape(b))
            x = torch.cat([x, embedding.unsqueeze(1).expand(b, t, self.style_dim)], dim=-1)
        elif style is not None:
            raise ValueError("this generator has no style input")
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


class StyledGenerator(nn.Module):
    """A style model with its style fixed: called as a MixtureLSTM without styles is (x, state), so code written for
    the plain generator (validation NLL, initial-state estimation, sampling) runs it unchanged."""

    def __init__(self, model: MixtureLSTM, style: int):
        super().__init__()
        self.model, self.style_id = model, style
        self.dim, self.hidden, self.mixtures = model.dim, model.hidden, model.mixtures

    def zero_state(self, batch: int):
        return self.model.zero_state(batch)

    def forward(self, x: torch.Tensor, state=None):
        return self.model(x, state, torch.full((x.shape[0],), self.style_id, dtype=torch.long))


class GeneratorStep(nn.Module):
    """One step with explicit state, for ONNX: (x (B, D), h (2, B, H), c (2, B, H)) ->
    (weights (B, M), mu (B, M, D), sigma (B, M, D), h', c')."""

    def __init__(self, model: MixtureLSTM):
        super().__init__()
        self.model = model

    def forward(self, x, h, c):
        logits, mu, log_sigma, (h2, c2) = self.model(x.unsqueeze(1), (h, c))
        return torch.softmax(logits[:, 0], dim=-1), mu[:, 0], torch.exp(log_sigma[:, 0]), h2, c2
