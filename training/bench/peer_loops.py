"""The peers the page's inference is compared with (npm run bench -- peers; the command is training/bench/peers.py): a PyTorch eager loop of the same
network, and native onnxruntime running the shipped ONNX step, each one stream (batch 1) on one thread, frame by
frame with the output and the state fed back, as the page generates.

- acLSTM: the reference code's synthesis loop (papagina/Auto_Conditioned_RNN_motion): three LSTMCells and a
  Linear, the output fed back as the next input; the shipped sizes (aclstm.json: 3 x LSTM(256) over 171 features
  and the 3-way style). Native onnxruntime runs the shipped Loop graph as the page does, 32 steps per call (and,
  for comparison, one step per call).
- generator: the shipped MixtureLSTM (FC, FC, 2 x LSTM(192), the mixture head) with one mixture draw per frame
  (component by its weight, then a Gaussian sample), fed back.

The torch networks have the shipped shapes but random weights: the time of dense products does not depend on
the values. Steps per second are frames per second here (one step is one frame).
"""
from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import torch
from torch import nn

from ..models.generator import MixtureLSTM
from ..onnx.sessions import cpu_session


STEPS_PER_CALL = 32  # the page's calls (web/runtime/aclstm/danceCore.ts STEPS_PER_CALL, as training/aclstm/shipped.py)


def _rate(step, frames: int, warmup: int) -> float:
    """Frames per second of `frames` calls of step() after `warmup` untimed ones."""
    for _ in range(warmup):
        step()
    t0 = time.perf_counter()
    for _ in range(frames):
        step()
    return frames / (time.perf_counter() - t0)


class ReferenceDanceLoop(nn.Module):
    """The acLSTM reference code's synthesis loop: LSTMCell x 3 and a Linear, one frame at a time."""

    def __init__(self, dim: int, styles: int, hidden: int):
        super().__init__()
        self.cells = nn.ModuleList([nn.LSTMCell(dim + styles, hidden), nn.LSTMCell(hidden, hidden), nn.LSTMCell(hidden, hidden)])
        self.decoder = nn.Linear(hidden, dim)

    def step(self, x: torch.Tensor, state: list[tuple[torch.Tensor, torch.Tensor]]) -> torch.Tensor:
        for k, cell in enumerate(self.cells):
            state[k] = cell(x, state[k])
            x = state[k][0]
        return self.decoder(x)


def aclstm_peers(models_dir: Path, frames: int, warmup: int) -> dict:
    info = json.loads((models_dir / "aclstm.json").read_text())
    o = info["onnx"]
    dim, styles, hidden, layers = o["dim"], o["styles"], o["hidden"], o["layers"]
    loop = ReferenceDanceLoop(dim, styles, hidden).eval()
    style = torch.zeros(1, styles)
    style[0, 0] = 1
    state = [(torch.zeros(1, hidden), torch.zeros(1, hidden)) for _ in range(layers)]
    y = torch.zeros(1, dim)

    def torch_step():
        nonlocal y
        with torch.no_grad():
            y = loop.step(torch.cat([y, style], dim=1), state)

    session = cpu_session(models_dir / info["file"], threads=1)
    feed = {"x": np.zeros((1, dim), np.float32), "style": style.numpy(), "h": np.zeros((layers, 1, hidden), np.float32),
            "c": np.zeros((layers, 1, hidden), np.float32)}

    def ort_calls(steps: int):
        """One call of `steps` steps of the shipped Loop graph, the last output fed to the next call."""
        def call():
            ys, feed["h"], feed["c"] = session.run(["ys", "h_out", "c_out"], {**feed, "steps": np.array([steps], np.int64)})
            feed["x"] = ys[-1]
        return call

    per_call = STEPS_PER_CALL
    return {"torch_frames_per_s": _rate(torch_step, frames, warmup),
            "ort_frames_per_s": per_call * _rate(ort_calls(per_call), frames // per_call, warmup // per_call + 1),
            "ort_single_step_frames_per_s": _rate(ort_calls(1), frames, warmup),
            "ort": f"the shipped Loop graph, {per_call} steps per call as the page calls it (and one step per call)",
            "torch": "3 x nn.LSTMCell(256) + Linear, the reference code's loop", "sizes": {"dim": dim, "hidden": hidden, "layers": layers}}


def _draw(weights: np.ndarray, mu: np.ndarray, sigma: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """One mixture draw per batch row: a component by its weight, then a Gaussian sample of it (normalised units)."""
    k = int(np.searchsorted(np.cumsum(weights[0]), rng.random() * weights[0].sum()))
    k = min(k, weights.shape[1] - 1)
    return (mu[0, k] + sigma[0, k] * rng.standard_normal(mu.shape[-1]))[None].astype(np.float32)


def generator_peers(models_dir: Path, frames: int, warmup: int) -> dict:
    info = json.loads((models_dir / "generator.json").read_text())
    o = info["onnx"]
    dim, hidden, mixtures = o["dim"], o["hidden"], o["mixtures"]
    model = MixtureLSTM(dim, hidden, mixtures).eval()
    rng = np.random.default_rng(0)
    state = model.zero_state(1)
    x = torch.zeros(1, 1, dim)

    def torch_step():
        nonlocal x, state
        with torch.no_grad():
            logits, mu, log_sigma, state = model(x, state)
            w = torch.softmax(logits[:, 0], dim=-1).numpy()
            x = torch.from_numpy(_draw(w, mu[:, 0].numpy(), torch.exp(log_sigma[:, 0]).numpy(), rng))[:, None]

    session = cpu_session(models_dir / info["file"], threads=1)
    feed = {"x": np.zeros((1, dim), np.float32), "h": np.zeros((2, 1, hidden), np.float32), "c": np.zeros((2, 1, hidden), np.float32)}

    def ort_step():
        w, mu, sigma, feed["h"], feed["c"] = session.run(["weights", "mu", "sigma", "h_out", "c_out"], feed)
        feed["x"] = _draw(w, mu, sigma, rng)

    return {"torch_frames_per_s": _rate(torch_step, frames, warmup), "ort_frames_per_s": _rate(ort_step, frames, warmup),
            "torch": "MixtureLSTM (FC, FC, 2 x LSTM(192), mixture head) + one mixture draw per frame",
            "sizes": {"dim": dim, "hidden": hidden, "mixtures": mixtures}}


def measure_peers(models_dir: Path, frames: int = 2000, warmup: int = 100) -> dict:
    torch.set_num_threads(1)
    torch.manual_seed(0)
    return {"aclstm": aclstm_peers(models_dir, frames, warmup), "generator": generator_peers(models_dir, frames, warmup),
            "threads": 1, "frames": frames, "torch_version": torch.__version__}
