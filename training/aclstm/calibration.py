"""What the dance network's weights multiply, for int4 storage that keeps its outputs rather than its weights
(training/onnx/compact.py, quantise_int4 with a Hessian).

Each large weight of the step graph (training/aclstm/graph.py) multiplies one input: lstm0.w_x_t the normalised
frame, lstm<l>.w_ih_t the layer below's h, lstm<l>.w_hh_t the layer's own previous h, decoder.weight_t the top h.
Their second moments, mean x x^T, are taken over the network's training clips only (never the held-out ones the
report judges on), in two halves: teacher-forced on the real frames, and running on its own outputs from real
starts, which is what the page runs.
"""
from __future__ import annotations

import numpy as np
import torch

from ..data.dance import MODEL_FPS, STYLES, DanceClip, encode, resample_positions
from ..models.aclstm import DanceLSTM, DanceStep

WINDOW = 240  # frames per calibration window (8 s at 30 fps)
WINDOWS = 48  # per half (teacher-forced, free-running)
REAL_START = 10  # real frames before the free-running half runs on its own: exporting.SEED_FRAMES, the page's seed
# (not imported: exporting imports this module)


def _windows(clips: list[DanceClip], mean: np.ndarray, std: np.ndarray, styles: list[str], rng: np.random.Generator):
    """WINDOWS normalised feature windows of WINDOW frames from the training clips, styles in turn, and their
    one-hot styles."""
    training = {s: [c for c in clips if c.style == s and not c.held_out] for s in styles}
    frames, style = [], []
    for k in range(WINDOWS):
        s = styles[k % len(styles)]
        c = training[s][rng.integers(len(training[s]))]
        start = rng.uniform(0, max(c.seconds - (WINDOW + 2) / MODEL_FPS, 0))
        feats = encode(resample_positions(c.positions, c.fps, start, WINDOW + 1))
        frames.append((feats - mean) / std)
        style.append(np.eye(len(styles))[styles.index(s)])
    return np.array(frames, np.float32), np.array(style, np.float32)


@torch.no_grad()
def _layer_inputs(model: DanceLSTM, x: np.ndarray, style: np.ndarray, free_after: int | None) -> dict[str, list]:
    """Runs the network one frame at a time (DanceStep: teacher-forced, or from frame `free_after` on its own mean
    output) and collects what each large weight multiplies, by the graph's weight names: the frame, each layer's new
    h (the next layer's input; the top one the decoder's) and each layer's previous h."""
    step, L = DanceStep(model), model.layers
    style_t = torch.from_numpy(style)
    h, c = model.zero_state(len(x))
    seen = {name: [] for name in ["lstm0.w_x_t", *[f"lstm{l}.w_ih_t" for l in range(1, L)],
                                  *[f"lstm{l}.w_hh_t" for l in range(L)], "decoder.weight_t"]}
    frame = torch.from_numpy(x[:, 0])
    for t in range(x.shape[1]):
        if free_after is None or t < free_after:
            frame = torch.from_numpy(x[:, t])
        y, h_new, c = step(frame, style_t, h, c)
        seen["lstm0.w_x_t"].append(frame.numpy())
        for l in range(L):
            seen[f"lstm{l}.w_hh_t"].append(h[l].numpy())
            if l > 0:
                seen[f"lstm{l}.w_ih_t"].append(h_new[l - 1].numpy())
        seen["decoder.weight_t"].append(h_new[-1].numpy())
        frame, h = y, h_new
    return seen


def input_moments(model: DanceLSTM, clips: list[DanceClip], mean, std, styles: list[str] | None = None,
                  seed: int = 0) -> dict[str, np.ndarray]:
    """Mean x x^T of each large weight's input (see the module docstring), by the step graph's weight names. `styles`:
    the model's style order (its JSON's `styles`; default data.dance.STYLES)."""
    if model.head != "mean":
        raise ValueError("input_moments follows the mean head's output; sample the other heads before calibrating them")
    rng = np.random.default_rng(seed)
    x, style = _windows(clips, np.asarray(mean), np.asarray(std), list(styles or STYLES), rng)
    moments = {}
    for free_after in (None, REAL_START):  # teacher-forced, then free-running after a real start
        for name, rows in _layer_inputs(model, x, style, free_after).items():
            a = np.concatenate(rows).astype(np.float64)
            moments[name] = moments.get(name, 0) + a.T @ a / len(a) / 2
    return moments
