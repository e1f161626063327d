"""The style generator's ONNX step (training/generator/graph.py's step_graph with its style input) and its parity.

The step: x (B, D), h, c (2, B, H), style (B, S) -> weights, mu, sigma, h_out, c_out, the batch dynamic. `style` holds
float weights over the styles, in the order of the JSON's `styles`: a one-hot picks a style, and since the graph
computes the embedding as style @ E (MatMul with the learned table E, S x style_dim) before concatenating it to x, a
convex combination of one-hots blends the styles' embeddings (how the page will move from one style to another over a
second). The torch side of the parity is MixtureLSTM with the same float weights (models/generator.py).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import onnx
import torch
from torch import nn

from ..generator.graph import OUTPUTS, PARITY_TOLERANCE, export_onnx
from ..generator.recovery import _named_weights
from ..models.generator import MixtureLSTM
from ..onnx.compact import float_initializers
from ..onnx.sessions import cpu_session

INPUTS = ["x", "h", "c", "style"]
__all__ = ["INPUTS", "OUTPUTS", "StyleGeneratorStep", "export_style_onnx", "model_from_style_onnx", "style_vectors",
           "style_parity_error", "check_style_parity"]


class StyleGeneratorStep(nn.Module):
    """One step with explicit state and style weights: (x (B, D), h, c (2, B, H), style (B, S)) -> weights, mu, sigma,
    h', c' (models/generator.py GeneratorStep with the style)."""

    def __init__(self, model: MixtureLSTM):
        super().__init__()
        self.model = model

    def forward(self, x, h, c, style):
        logits, mu, log_sigma, (h2, c2) = self.model(x.unsqueeze(1), (h, c), style)
        return torch.softmax(logits[:, 0], dim=-1), mu[:, 0], torch.exp(log_sigma[:, 0]), h2, c2


def export_style_onnx(model: MixtureLSTM, path: Path, weights: str = "float32") -> None:
    """The gate-level step graph with the style input, its weights stored as `weights` (int8: mixture head float16)."""
    if model.styles <= 0:
        raise ValueError("this generator has no style input; export it with python -m training.generator.export")
    export_onnx(model, path, weights)


def model_from_style_onnx(path: Path, dim: int, hidden: int, mixtures: int, styles: int, style_dim: int) -> MixtureLSTM:
    """A MixtureLSTM(styles=...) (eval mode) holding the weights as the file at `path` stores them."""
    inits = float_initializers(onnx.load(str(path)))
    state = _named_weights(inits, hidden)
    state["style.weight"] = inits["style.weight"]
    model = MixtureLSTM(dim, hidden, mixtures, styles=styles, style_dim=style_dim)
    expected = model.state_dict()
    for name, value in state.items():
        if tuple(value.shape) != tuple(expected[name].shape):
            raise ValueError(f"{path}: {name} has shape {value.shape}, the model needs {tuple(expected[name].shape)}")
    model.load_state_dict({name: torch.from_numpy(np.ascontiguousarray(v)) for name, v in state.items()})
    return model.eval()


def style_vectors(rng: np.random.Generator, batch: int, styles: int, blend: bool) -> np.ndarray:
    """(batch, styles) float32: one-hots (row b: style b mod styles), or with `blend` random convex combinations of two
    styles (a switch half-way through its blend)."""
    out = np.zeros((batch, styles), np.float32)
    for b in range(batch):
        if blend:
            i, j = rng.choice(styles, size=2, replace=False)
            w = rng.uniform()
            out[b, i], out[b, j] = w, 1.0 - w
        else:
            out[b, b % styles] = 1.0
    return out


def style_parity_error(model: MixtureLSTM, path: Path, blend: bool, batches=(1, 7), steps: int = 20, seed: int = 1) -> float:
    """Largest |torch - onnxruntime| / max(1, |torch|) over all outputs (graph.parity_error's measure) with one-hot or
    blended style vectors, states fed forward from torch."""
    session = cpu_session(path)
    step = StyleGeneratorStep(model).eval()
    rng = np.random.default_rng(seed)
    worst = 0.0
    for batch in batches:
        h = np.zeros((2, batch, model.hidden), np.float32)
        c = h.copy()
        style = style_vectors(rng, batch, model.styles, blend)
        for _ in range(steps):
            x = rng.normal(size=(batch, model.dim)).astype(np.float32)
            with torch.no_grad():
                ref = [t.numpy() for t in step(*(torch.from_numpy(a) for a in (x, h, c, style)))]
            got = session.run(OUTPUTS, {"x": x, "h": h, "c": c, "style": style})
            worst = max(worst, max(float((np.abs(a - b) / np.maximum(1.0, np.abs(a))).max()) for a, b in zip(ref, got)))
            h, c = ref[3], ref[4]
    return worst


def check_style_parity(model: MixtureLSTM, path: Path, steps: int = 20) -> dict:
    """The export's parity check, one-hot and blended styles at batch 1 and 7; exits when either fails."""
    one_hot = style_parity_error(model, path, blend=False, steps=steps)
    blended = style_parity_error(model, path, blend=True, steps=steps, seed=2)
    worst = max(one_hot, blended)
    if worst > PARITY_TOLERANCE:
        raise SystemExit(f"error: ONNX parity failed, max scaled |torch - onnxruntime| = {worst:.2e} > {PARITY_TOLERANCE:.0e} "
                         f"(one-hot {one_hot:.2e}, blended {blended:.2e})")
    return {"max_abs_diff": worst, "one_hot": one_hot, "blended": blended, "measure": "|a - b| / max(1, |a|)",
            "tolerance": PARITY_TOLERANCE, "batches": [1, 7], "steps": steps}
