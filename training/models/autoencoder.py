"""The convolutional motion autoencoder (Holden et al.; Yearsley §3.1.1, Fig. 3.2): 1-D convolutions along
time with 25-frame kernels, ReLU and max-pooling in the encoder; in the decoder, nearest-neighbour
upsampling (deterministic, so it exports as an ONNX Resize) and convolutions that invert them. Frames in,
frames out: (batch, frames, channels), frames a multiple of 4; the latent is (batch, frames / 4, latent).

Trained as a denoising autoencoder: masked noise zeroes a share of the (normalised) input values and the
loss asks for the clean motion.
"""
from __future__ import annotations

import torch
from torch import nn

KERNEL = 25
POOLING = 4  # two max-poolings of 2


class MotionAutoencoder(nn.Module):
    def __init__(self, dim: int, hidden: int = 128, latent: int = 128, kernel: int = KERNEL, dropout: float = 0.1):
        super().__init__()
        self.dim, self.hidden, self.latent = dim, hidden, latent
        pad = kernel // 2
        self.encoder = nn.Sequential(
            nn.Conv1d(dim, hidden, kernel, padding=pad), nn.ReLU(), nn.MaxPool1d(2),
            nn.Conv1d(hidden, latent, kernel, padding=pad), nn.ReLU(), nn.MaxPool1d(2))
        self.decoder = nn.Sequential(
            nn.Upsample(scale_factor=2, mode="nearest"), nn.Dropout(dropout), nn.Conv1d(latent, hidden, kernel, padding=pad), nn.ReLU(),
            nn.Upsample(scale_factor=2, mode="nearest"), nn.Dropout(dropout), nn.Conv1d(hidden, dim, kernel, padding=pad))

    def encode(self, x: torch.Tensor) -> torch.Tensor:
        return self.encoder(x.transpose(1, 2)).transpose(1, 2)

    def decode(self, z: torch.Tensor) -> torch.Tensor:
        return self.decoder(z.transpose(1, 2)).transpose(1, 2)

    def forward(self, x: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        z = self.encode(x)
        return self.decode(z), z


def masked_noise(x: torch.Tensor, p: float) -> torch.Tensor:
    """x with each value set to 0 (the mean, in normalised units) with probability p, and the others scaled
    by 1 / (1 - p) as in dropout, so that clean input has the scale the network trained on (without it,
    the pilots reconstructed clean windows worse than masked ones)."""
    return x * (torch.rand_like(x) >= p) / (1 - p)
