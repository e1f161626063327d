"""The recurrent VAE conditioned on a control signal (Habibie et al. 2017, §3–4.2).

- Control-signal encoder and inference network: two blocks each of 1-D convolution along time (25-frame
  kernels), ELU and max-pooling by 2, so one step covers 4 frames (133 ms at 30 fps). The inference network
  ends in a 1×1 convolution to the posterior's mean and log-variance per step.
- The modified LSTM cell of eqs. 7–9: no output gate, the cell state itself is the output, and
      i = s(W_ic c' + W_ih h),  f = s(W_fc c' + W_fh h),  c = ELU(f ⊙ W_c[x] + i ⊙ W_h[h])
  where h is the control encoding of the step, c' the previous cell state, and x the latent code z_t in
  training (teacher mode) or the previous cell state at test time (free mode). The first step's previous
  state is z_1, so the whole motion hangs on one latent sample (Algorithm 1).
- The cell states form the motion canvas; a decoder of nearest-neighbour upsampling (deterministic, exports
  as ONNX Resize) and 25-frame convolutions turns it back into frames.

Everything is fully convolutional along time except the cell, so a control signal of any length (a multiple
of 4 frames) encodes and decodes in one pass, and the cell carries its state across any number of steps.
Shapes: frames (batch, frames, channels); steps (batch, frames / 4, channels).
"""
from __future__ import annotations

import torch
from torch import nn

KERNEL = 25
POOLING = 4  # two max-poolings of 2


def conv_block(cin: int, cout: int, kernel: int = KERNEL) -> list[nn.Module]:
    return [nn.Conv1d(cin, cout, kernel, padding=kernel // 2), nn.ELU(), nn.MaxPool1d(2)]


class StepEncoder(nn.Module):
    """Frames (batch, frames, cin) to steps (batch, frames / 4, cout) through two conv–ELU–pool blocks."""

    def __init__(self, cin: int, hidden: int, cout: int, dropout: float = 0.0):
        super().__init__()
        self.dropout = nn.Dropout(dropout)
        self.net = nn.Sequential(*conv_block(cin, hidden), *conv_block(hidden, cout))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.net(self.dropout(x).transpose(1, 2)).transpose(1, 2)


class InferenceNetwork(nn.Module):
    """q(z_t | x): frames (batch, frames, dim) to the posterior's mean and log-variance per step."""

    def __init__(self, dim: int, latent: int, hidden: int = 64, features: int = 256, dropout: float = 0.0):
        super().__init__()
        self.encoder = StepEncoder(dim, hidden, features, dropout)
        self.head = nn.Linear(features, 2 * latent)

    def forward(self, x: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        mean, log_var = self.head(self.encoder(x)).chunk(2, dim=-1)
        return mean, log_var.clamp(-10.0, 6.0)


class CanvasCell(nn.Module):
    """The modified LSTM cell of eqs. 7–9; its state (batch, latent) is also its output."""

    def __init__(self, latent: int, control: int):
        super().__init__()
        self.gates_state = nn.Linear(latent, 2 * latent)
        self.gates_control = nn.Linear(control, 2 * latent)
        self.content_state = nn.Linear(latent, latent, bias=False)
        self.content_control = nn.Linear(control, latent, bias=False)

    def forward(self, previous: torch.Tensor, content: torch.Tensor, control: torch.Tensor) -> torch.Tensor:
        i, f = torch.sigmoid(self.gates_state(previous) + self.gates_control(control)).chunk(2, dim=-1)
        return nn.functional.elu(f * self.content_state(content) + i * self.content_control(control))

    def run(self, state: torch.Tensor, controls: torch.Tensor, latents: torch.Tensor | None = None, mix: float = 1.0) -> tuple[torch.Tensor, torch.Tensor]:
        """The canvas (batch, steps, latent) over controls (batch, steps, control) from `state`, and the last
        state. With `latents` (batch, steps, latent) the content of step t is mix · z_t + (1 − mix) · the previous
        state (mix 1: teacher mode), else the previous state (free mode)."""
        canvas = []
        for t in range(controls.shape[1]):
            content = state if latents is None else (latents[:, t] if mix == 1.0 else mix * latents[:, t] + (1 - mix) * state)
            state = self(state, content, controls[:, t])
            canvas.append(state)
        return torch.stack(canvas, dim=1), state


class CanvasDecoder(nn.Module):
    """The motion canvas (batch, steps, latent) to frames (batch, 4 × steps, dim)."""

    def __init__(self, latent: int, dim: int, hidden: int = 128, kernel: int = KERNEL):
        super().__init__()
        pad = kernel // 2
        self.net = nn.Sequential(
            nn.Upsample(scale_factor=2, mode="nearest"), nn.Conv1d(latent, hidden, kernel, padding=pad), nn.ELU(),
            nn.Upsample(scale_factor=2, mode="nearest"), nn.Conv1d(hidden, dim, kernel, padding=pad))

    def forward(self, canvas: torch.Tensor) -> torch.Tensor:
        return self.net(canvas.transpose(1, 2)).transpose(1, 2)


class VaeLstm(nn.Module):
    def __init__(self, dim: int, control: int = 3, latent: int = 128, control_features: int = 128,
                 inference_features: int = 256, decoder_hidden: int = 128, dropout: float = 0.1):
        super().__init__()
        self.dim, self.control, self.latent = dim, control, latent
        self.control_encoder = StepEncoder(control, 64, control_features, dropout)
        self.inference = InferenceNetwork(dim, latent, 64, inference_features, dropout)
        self.cell = CanvasCell(latent, control_features)
        self.decoder = CanvasDecoder(latent, dim, decoder_hidden)

    def generate(self, control: torch.Tensor, z1: torch.Tensor, mix: float = 0.0) -> torch.Tensor:
        """Algorithm 1: frames (batch, frames, dim) for a control signal (batch, frames, control) from one
        latent sample z1 (batch, latent), the cell running on its own state (with `mix` > 0 z1 is also that share
        of every step's content)."""
        return self.decoder(self.free_canvas(z1, self.control_encoder(control), mix))

    def free_canvas(self, z1: torch.Tensor, hc: torch.Tensor, mix: float = 0.0) -> torch.Tensor:
        """The free mode's canvas (batch, steps, latent) from z1 over control encodings `hc`: the cell on its own
        state, z1 its first state and, with `mix` > 0, that share of every step's content."""
        latents = z1[:, None].expand(-1, hc.shape[1], -1) if mix > 0 else None
        return self.cell.run(z1, hc, latents, mix)[0]

    def posterior_first(self, seed: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """q(z_1 | the first 4 frames): mean and log-variance (batch, latent) of the first step of `seed` (batch,
        frames, dim), whatever it holds after them (generation.py pads 4 frames by repeating the last)."""
        mean, log_var = self.inference(seed)
        return mean[:, 0], log_var[:, 0]
