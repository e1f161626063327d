"""Losses shared by several models' training."""
from __future__ import annotations

import torch


def energy_loss(pred: torch.Tensor, real: torch.Tensor) -> torch.Tensor:
    """Motion energy: mean over windows and channels of (RMS frame-to-frame change of pred - of real)^2, for
    (batch, time, channels). Blind to phase, so a motion out of step costs nothing while a frozen one does."""
    rms = lambda x: torch.sqrt(((x[:, 1:] - x[:, :-1]) ** 2).mean(1) + 1e-6)
    return ((rms(pred) - rms(real)) ** 2).mean()
