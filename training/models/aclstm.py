"""Auto-conditioned LSTM (Zhou et al.): a stack of LSTMs with a linear decoder over joint positions.

One model serves every dance style: a one-hot style vector is appended to each frame's input.
The same network trained with teacher forcing only is the paper's "vanilla" baseline.
"""
from __future__ import annotations

import torch
from torch import nn


class DanceLSTM(nn.Module):
    def __init__(self, dim: int, styles: int, hidden: int = 256, layers: int = 3):
        super().__init__()
        self.dim, self.styles, self.hidden, self.layers = dim, styles, hidden, layers
        self.lstm = nn.LSTM(dim + styles, hidden, num_layers=layers, batch_first=True)
        self.decoder = nn.Linear(hidden, dim)

    def zero_state(self, batch: int) -> tuple[torch.Tensor, torch.Tensor]:
        z = torch.zeros(self.layers, batch, self.hidden)
        return z, z.clone()

    def forward(self, x: torch.Tensor, style: torch.Tensor, state=None):
        """x (batch, time, dim), style (batch, styles) -> next frames (batch, time, dim), (h, c)."""
        s = style.unsqueeze(1).expand(-1, x.shape[1], -1)
        y, state = self.lstm(torch.cat([x, s], dim=-1), state)
        return self.decoder(y), state

    def auto_conditioned(self, x: torch.Tensor, style: torch.Tensor, ground_truth: int, condition: int,
                         feedback_noise: float = 0.0):
        """The acRNN unroll: `ground_truth` real input frames, then `condition` frames of the network's own
        output fed back as input, alternating; returns the prediction for every input position.
        With condition=0 this is plain teacher forcing. Gradients flow through the fed-back frames.
        `feedback_noise`: Gaussian noise (normalised units) added to each fed-back frame, as at generation
        with the inference-time lever (the prediction itself is returned clean)."""
        if condition == 0:
            return self(x, style)[0]
        outs, state, t, total = [], None, 0, x.shape[1]
        while t < total:
            n = min(ground_truth, total - t)
            y, state = self(x[:, t:t + n], style, state)
            outs.append(y)
            t += n
            prev = y[:, -1:]
            for _ in range(min(condition, total - t)):
                fed = prev + feedback_noise * torch.randn_like(prev) if feedback_noise else prev
                prev, state = self(fed, style, state)
                outs.append(prev)
                t += 1
        return torch.cat(outs, dim=1)


class DanceStep(nn.Module):
    """One step with explicit state, for ONNX: (x (B, dim), style (B, styles), h, c (layers, B, H)) -> (y, h', c')."""

    def __init__(self, model: DanceLSTM):
        super().__init__()
        self.model = model

    def forward(self, x, style, h, c):
        y, (h2, c2) = self.model(x.unsqueeze(1), style, (h, c))
        return y[:, 0], h2, c2
