"""The encoder-recurrent-decoder with a control signal (Yearsley Ch. 6, Fig. 6.1, network ON2): an ELU
encoder, three LSTM layers with skip connections (each layer sees the encoder's output as well as the
layer below; the decoder sees every layer), dropout and a linear decoder. Each step takes the current
frame (a latent step of the motion manifold, or a pose row for the pose-space baseline) with the control
for the next step, and predicts the next frame as a change from the current one.

The state is explicit: h and c of shape (layers, batch, hidden), in and out, so one step exports to ONNX.
Each prediction is clamped per channel to the range seen in training (`set_range`): a free-running ERD
that drifts cannot leave the box its decoder was trained on (a dead ReLU channel of the manifold stays
exactly at its constant).
"""
from __future__ import annotations

import torch
from torch import nn


class ControlERD(nn.Module):
    def __init__(self, dim: int, control: int, hidden: int = 256, layers: int = 3, dropout: float = 0.2):
        super().__init__()
        self.dim, self.control, self.hidden, self.layers = dim, control, hidden, layers
        self.encoder = nn.Sequential(nn.Linear(dim + control, hidden), nn.ELU())
        self.lstms = nn.ModuleList(nn.LSTM(hidden if i == 0 else 2 * hidden, hidden, batch_first=True) for i in range(layers))
        self.dropout = nn.Dropout(dropout)
        self.decoder = nn.Linear(layers * hidden, dim)
        self.register_buffer("low", torch.full((dim,), -1e6))
        self.register_buffer("high", torch.full((dim,), 1e6))

    def set_range(self, low, high) -> None:
        self.low.copy_(torch.as_tensor(low, dtype=torch.float32))
        self.high.copy_(torch.as_tensor(high, dtype=torch.float32))

    def zero_state(self, batch: int) -> tuple[torch.Tensor, torch.Tensor]:
        z = torch.zeros(self.layers, batch, self.hidden)
        return z, z.clone()

    def forward(self, x: torch.Tensor, control: torch.Tensor, state=None):
        """x (batch, time, dim), control (batch, time, control) -> next frames (batch, time, dim), (h, c)."""
        h0, c0 = state if state is not None else self.zero_state(x.shape[0])
        e = self.encoder(torch.cat([x, control], dim=-1))
        outs, hs, cs = [], [], []
        below = None
        for i, lstm in enumerate(self.lstms):
            inp = e if below is None else torch.cat([e, below], dim=-1)
            below, (h, c) = lstm(inp, (h0[i:i + 1], c0[i:i + 1]))
            outs.append(below)
            hs.append(h)
            cs.append(c)
        delta = self.decoder(self.dropout(torch.cat(outs, dim=-1)))
        return torch.minimum(torch.maximum(x + delta, self.low), self.high), (torch.cat(hs), torch.cat(cs))
