"""Auto-conditioned LSTM (Zhou et al.): a stack of LSTMs with a linear decoder over joint positions.

One model serves every dance style: a one-hot style vector is appended to each frame's input.
The same network trained with teacher forcing only is the paper's "vanilla" baseline.

Three output heads: "mean" (the paper's: the next frame, trained by squared error), "gauss" (issue 18's
pilot lever: a diagonal Gaussian over the next frame, trained by likelihood, whose samples are fed back, since
regressing the mean pulls a long rollout toward a static pose) and "mdn" (issue 42's first lever: a mixture of K
diagonal Gaussians over the next frame, trained by likelihood; in the self-fed stretch of training the component is
drawn once and held for the stretch, as training/aclstm/phrase_sampling.py holds it over a phrase at inference).
"""
from __future__ import annotations

import torch
from torch import nn

LOG_SIGMA_RANGE = (-5.0, 1.0)  # the Gaussian head's log standard deviation, normalised units
HEADS = ("mean", "gauss", "mdn")


def draw(mu: torch.Tensor, log_sigma: torch.Tensor, temperature: float, normals: torch.Tensor) -> torch.Tensor:
    """The Gaussian head's draw from given standard normals: mu + temperature · sigma · normals (the exported
    graph computes the same, training/aclstm/graph.py)."""
    return mu + temperature * torch.exp(log_sigma) * normals


class DanceLSTM(nn.Module):
    def __init__(self, dim: int, styles: int, hidden: int = 256, layers: int = 3, head: str = "mean", components: int = 10):
        super().__init__()
        if head not in HEADS:
            raise ValueError(f"unknown head {head!r}: use 'mean', 'gauss' or 'mdn'")
        self.dim, self.styles, self.hidden, self.layers, self.head = dim, styles, hidden, layers, head
        self.components = components if head == "mdn" else 0
        self.lstm = nn.LSTM(dim + styles, hidden, num_layers=layers, batch_first=True)
        out = {"mean": dim, "gauss": 2 * dim, "mdn": components * (2 * dim + 1)}[head]
        self.decoder = nn.Linear(hidden, out)

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
        if self.head == "mdn":  # the mixture's mean (a point estimate; mixture() gives the components)
            logits, mu, _ = self._split_mixture(out)
            return (torch.softmax(logits, -1).unsqueeze(-1) * mu).sum(-2), None, state
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
        if self.head == "mdn":  # the mixture's mean at every position, its own held-component draws fed back
            logits, mu, _ = self.auto_conditioned_mixture(x, style, ground_truth, condition)
            return (torch.softmax(logits, -1).unsqueeze(-1) * mu).sum(-2)
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

    def _split_mixture(self, out: torch.Tensor):
        k, d = self.components, self.dim
        logits = out[..., :k]
        mu = out[..., k:k + k * d].unflatten(-1, (k, d))
        log_sigma = out[..., k + k * d:].unflatten(-1, (k, d)).clamp(*LOG_SIGMA_RANGE)
        return logits, mu, log_sigma

    def mixture(self, x: torch.Tensor, style: torch.Tensor, state=None):
        """The mdn head: x (batch, time, dim) -> mixture logits (batch, time, K), component means and log standard
        deviations (batch, time, K, dim), (h, c)."""
        if self.head != "mdn":
            raise ValueError("mixture() needs the 'mdn' head")
        s = style.unsqueeze(1).expand(-1, x.shape[1], -1)
        y, state = self.lstm(torch.cat([x, s], dim=-1), state)
        logits, mu, log_sigma = self._split_mixture(self.decoder(y))
        return logits, mu, log_sigma, state

    def auto_conditioned_mixture(self, x, style, ground_truth: int, condition: int, temperature: float = 1.0,
                                 generator: torch.Generator | None = None):
        """The acRNN unroll of the mdn head: (logits, mu, log_sigma) for every input position. In each self-fed
        stretch the component is drawn once from the mixture weights at the stretch's first frame and held for
        the stretch (the phrase sampler's rule at inference, training/aclstm/phrase_sampling.py); each fed-back
        frame is that component's mean + temperature · σ · normal, reparameterised so gradients flow through it
        (not through the choice of component)."""
        if condition == 0:
            logits, mu, log_sigma, _ = self.mixture(x, style)
            return logits, mu, log_sigma
        outs, state, t, total = [], None, 0, x.shape[1]
        rows = torch.arange(x.shape[0], device=x.device)
        while t < total:
            n = min(ground_truth, total - t)
            logits, mu, log_sigma, state = self.mixture(x[:, t:t + n], style, state)
            outs.append((logits, mu, log_sigma))
            t += n
            held = None
            for _ in range(min(condition, total - t)):
                if held is None:
                    held = torch.multinomial(torch.softmax(logits[:, -1].detach(), -1), 1, generator=generator)[:, 0]
                normals = torch.randn(mu[:, -1, 0].shape, generator=generator, device=mu.device)
                fed = mu[rows, -1, held] + temperature * torch.exp(log_sigma[rows, -1, held]) * normals
                logits, mu, log_sigma, state = self.mixture(fed.unsqueeze(1), style, state)
                outs.append((logits, mu, log_sigma))
                t += 1
        return tuple(torch.cat([o[i] for o in outs], dim=1) for i in range(3))


def mixture_nll(logits: torch.Tensor, mu: torch.Tensor, log_sigma: torch.Tensor, target: torch.Tensor) -> torch.Tensor:
    """Mean negative log-likelihood of `target` (..., dim) under the mixture (logits (..., K), mu and log_sigma
    (..., K, dim)), per frame and divided by dim (so it reads per channel, like the Gaussian head's loss; the
    constant ½ log 2π dropped)."""
    z = (target.unsqueeze(-2) - mu) * torch.exp(-log_sigma)
    per_component = (-0.5 * z ** 2 - log_sigma).sum(-1)
    return -(torch.logsumexp(torch.log_softmax(logits, -1) + per_component, dim=-1)).mean() / target.shape[-1]


class DanceStep(nn.Module):
    """One step with explicit state, for ONNX: (x (B, dim), style (B, styles), h, c (layers, B, H)) -> (y, h', c')."""

    def __init__(self, model: DanceLSTM):
        super().__init__()
        self.model = model

    def forward(self, x, style, h, c):
        y, (h2, c2) = self.model(x.unsqueeze(1), style, (h, c))
        return y[:, 0], h2, c2
