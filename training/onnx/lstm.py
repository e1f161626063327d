"""ONNX LSTM nodes read back into PyTorch's layout: the one place that knows both gate orders.

An ONNX LSTM node keeps its gate blocks in the order (i, o, f, c), W (1, 4H, in), R (1, 4H, H) and B (1, 8H) = input
and recurrent biases; nn.LSTM keeps (i, f, g, o). The generator, latent ERD and dance model read-backs use this.
"""
from __future__ import annotations

import numpy as np
import onnx

# PyTorch gate block k is ONNX gate block ONNX_TO_TORCH_GATES[k].
ONNX_TO_TORCH_GATES = [0, 2, 3, 1]


def onnx_gates_to_torch(w: np.ndarray, hidden: int) -> np.ndarray:
    """Rows (4H, ...) in ONNX gate order -> PyTorch gate order."""
    return w.reshape(4, hidden, *w.shape[1:])[ONNX_TO_TORCH_GATES].reshape(4 * hidden, *w.shape[1:])


def torch_gates_to_onnx(w: np.ndarray, hidden: int) -> np.ndarray:
    """Rows (4H, ...) in PyTorch gate order -> ONNX gate order (the inverse of onnx_gates_to_torch)."""
    return w.reshape(4, hidden, *w.shape[1:])[np.argsort(ONNX_TO_TORCH_GATES)].reshape(4 * hidden, *w.shape[1:])


def lstm_node_weights(node: onnx.NodeProto, inits: dict[str, np.ndarray], hidden: int) -> dict[str, np.ndarray]:
    """One forward LSTM node's weights as nn.LSTM names them for one layer: weight_ih, weight_hh, bias_ih, bias_hh."""
    attrs = {a.name: onnx.helper.get_attribute_value(a) for a in node.attribute}
    if attrs.get("hidden_size") != hidden or attrs.get("direction", b"forward") not in (b"forward", "forward"):
        raise ValueError(f"LSTM node {node.name or node.output[0]}: unexpected attributes {attrs} (hidden {hidden}, forward)")
    w, r, b = (inits[name] for name in node.input[1:4])
    return {"weight_ih": onnx_gates_to_torch(w[0], hidden), "weight_hh": onnx_gates_to_torch(r[0], hidden),
            "bias_ih": onnx_gates_to_torch(b[0, :4 * hidden], hidden), "bias_hh": onnx_gates_to_torch(b[0, 4 * hidden:], hidden)}
