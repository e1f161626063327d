"""Start the style generator from the shipped CMU generator's weights (issue 39's third recipe).

Two full runs from random weights turned on CMU's held-out clips after about 10,000 iterations while the Bandai styles
kept improving (docs/models/style-generator.md). Starting from the shipped generator puts CMU at its shipped quality
from the first step, and the styles only have to learn what differs.

The two models normalise their features differently (the style corpus's mean and std include Bandai), so the copied
weights are rewritten to mean the same in the new units:
- fc1 reads z = (x - m2) / s2 where the shipped one read (x - m1) / s1 = (z s2 + m2 - m1) / s1: its columns are scaled
  by s2 / s1 and its bias gains W (m2 - m1) / s1. The style columns start at zero, so every style starts as CMU.
- fc3's means are in the old units: mu2 = (mu1 s1 + m1 - m2) / s2 (rows scaled by s1 / s2, bias moved), and each
  log sigma gains log(s1 / s2). The mixture logits are unchanged.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import torch

from ..generator.recovery import model_from_onnx
from ..models.generator import MixtureLSTM
from ..paths import MODELS_DIR


def shipped_generator(models_dir: Path = MODELS_DIR) -> tuple[MixtureLSTM, np.ndarray, np.ndarray]:
    """The shipped generator (weights as exported) and its normalisation mean and std."""
    info = json.loads((models_dir / "generator.json").read_text())
    o = info["onnx"]
    model = model_from_onnx(models_dir / info["file"], o["dim"], o["hidden"], o["mixtures"])
    return model, np.array(info["normalisation"]["mean"]), np.array(info["normalisation"]["std"])


@torch.no_grad()
def warm_start(model: MixtureLSTM, mean: np.ndarray, std: np.ndarray, models_dir: Path = MODELS_DIR) -> None:
    """Copy the shipped generator into `model` (a MixtureLSTM with styles, normalised by `mean` and `std`)."""
    shipped, m1, s1 = shipped_generator(models_dir)
    d, m = model.dim, model.mixtures
    if (shipped.dim, shipped.hidden, shipped.mixtures) != (d, model.hidden, m):
        raise ValueError(f"the shipped generator is {shipped.dim} features x {shipped.hidden} x {shipped.mixtures}, "
                         f"the style model {d} x {model.hidden} x {m}: --init-from-shipped needs the same sizes")
    m2, s2 = np.asarray(mean, np.float64), np.asarray(std, np.float64)
    scale_in = torch.from_numpy(s2 / s1).float()  # per input feature
    shift_in = torch.from_numpy((m2 - m1) / s1).float()
    w1 = shipped.fc1.weight  # (hidden, d)
    model.fc1.weight.zero_()
    model.fc1.weight[:, :d] = w1 * scale_in
    model.fc1.bias.copy_(shipped.fc1.bias + w1 @ shift_in)
    model.fc2.load_state_dict(shipped.fc2.state_dict())
    model.lstm.load_state_dict(shipped.lstm.state_dict())
    w3, b3 = shipped.fc3.weight.clone(), shipped.fc3.bias.clone()
    ratio = torch.from_numpy(s1 / s2).float()  # old units -> new units, per output feature
    offset = torch.from_numpy((m1 - m2) / s2).float()
    mu_rows = slice(m, m + m * d)
    sigma_rows = slice(m + m * d, m + 2 * m * d)
    w3[mu_rows] = (w3[mu_rows].reshape(m, d, -1) * ratio[None, :, None]).reshape(m * d, -1)
    b3[mu_rows] = (b3[mu_rows].reshape(m, d) * ratio[None, :] + offset[None, :]).reshape(-1)
    b3[sigma_rows] = (b3[sigma_rows].reshape(m, d) + torch.log(ratio)[None, :]).reshape(-1)
    model.fc3.weight.copy_(w3)
    model.fc3.bias.copy_(b3)
