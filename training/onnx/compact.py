"""Lighter model files: large float32 weights stored as float16 or int8 and turned back into float32 inside the graph.

Each stored weight keeps its graph name; a small node chain right at the start of the graph makes it again:

- float16: `NAME.f16` --Cast(float)--> NAME
- int8: `NAME.i8` --Cast(float)--> * `NAME.scale` --> NAME, one scale per output channel (symmetric, max |w| / 127)

Both chains depend on initialisers only, so onnxruntime (and onnxruntime-web) folds them into float32 constants
when the session is created: the arithmetic stays float32 and a call costs what it did; only the download shrinks.
Weights smaller than MIN_ELEMENTS (biases, small tables) stay float32.
"""
from __future__ import annotations

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper

MIN_ELEMENTS = 4096
FORMATS = ("float32", "float16", "int8")


def _channel_axis(model: onnx.ModelProto, name: str, rank: int) -> int:
    """The weight's output-channel axis, from the node that reads it: Conv (out, in, k) 0, LSTM (1, 4H, in) 1, a
    Gemm/MatMul right-hand side (in, out) the last (Gemm with transB: 0)."""
    for graph in _graphs(model.graph):
        for n in graph.node:
            if name not in n.input:
                continue
            if n.op_type in ("Conv", "ConvTranspose"):
                return 0
            if n.op_type in ("LSTM", "GRU"):
                return 1
            if n.op_type == "Gemm" and any(a.name == "transB" and a.i for a in n.attribute):
                return 0
            return rank - 1
    return rank - 1


def _graphs(graph: onnx.GraphProto):
    yield graph
    for n in graph.node:
        for a in n.attribute:
            if a.type == onnx.AttributeProto.GRAPH:
                yield from _graphs(a.g)


def quantise_int8(w: np.ndarray, axis: int) -> tuple[np.ndarray, np.ndarray]:
    """Symmetric int8 with one float32 scale per slice along `axis` (broadcastable against w)."""
    others = tuple(a for a in range(w.ndim) if a != axis)
    scale = np.abs(w).max(axis=others, keepdims=True) / 127.0
    scale = np.where(scale > 0, scale, 1.0).astype(np.float32)
    return np.clip(np.rint(w / scale), -127, 127).astype(np.int8), scale


def compact_weights(model: onnx.ModelProto, fmt: str) -> onnx.ModelProto:
    """A copy of `model` with every float32 initialiser of MIN_ELEMENTS or more stored as `fmt`."""
    if fmt not in FORMATS:
        raise ValueError(f"unknown weight format {fmt!r} (one of {', '.join(FORMATS)})")
    out = onnx.ModelProto()
    out.CopyFrom(model)
    if fmt == "float32":
        return out
    graph = out.graph
    kept, nodes = [], []
    for init in graph.initializer:
        w = numpy_helper.to_array(init)
        if init.data_type != TensorProto.FLOAT or w.size < MIN_ELEMENTS:
            kept.append(init)
            continue
        if fmt == "float16":
            kept.append(numpy_helper.from_array(w.astype(np.float16), f"{init.name}.f16"))
            nodes.append(helper.make_node("Cast", [f"{init.name}.f16"], [init.name], to=TensorProto.FLOAT))
        else:
            q, scale = quantise_int8(w, _channel_axis(model, init.name, w.ndim))
            kept += [numpy_helper.from_array(q, f"{init.name}.i8"), numpy_helper.from_array(scale, f"{init.name}.scale")]
            nodes += [helper.make_node("Cast", [f"{init.name}.i8"], [f"{init.name}.i8_float"], to=TensorProto.FLOAT),
                      helper.make_node("Mul", [f"{init.name}.i8_float", f"{init.name}.scale"], [init.name])]
    del graph.initializer[:]
    graph.initializer.extend(kept)
    rest = list(graph.node)
    del graph.node[:]
    graph.node.extend(nodes + rest)
    onnx.checker.check_model(out)
    return out


def stored_float_weights(model: onnx.ModelProto) -> dict[str, np.ndarray]:
    """The float32 values of the weights compact_weights stored in lower precision, by their graph name."""
    inits = {t.name: numpy_helper.to_array(t) for t in model.graph.initializer}
    out = {}
    for name, value in inits.items():
        if name.endswith(".f16"):
            out[name[:-4]] = value.astype(np.float32)
        elif name.endswith(".i8"):
            out[name[:-3]] = value.astype(np.float32) * inits[f"{name[:-3]}.scale"]
    return out


def float_initializers(model: onnx.ModelProto) -> dict[str, np.ndarray]:
    """Every initialiser by its graph name as float32, the stored ones (see module docstring) turned back into the
    values the graph computes with: what reading the weights of any export needs, whatever its format."""
    inits = {t.name: numpy_helper.to_array(t) for t in model.graph.initializer}
    out = {n: v.astype(np.float32) for n, v in inits.items() if not n.endswith((".f16", ".i8", ".scale"))}
    return out | stored_float_weights(model)


def weight_format(model: onnx.ModelProto) -> str:
    """How the file stores its large weights: 'int8', 'float16' or 'float32'."""
    names = [t.name for t in model.graph.initializer]
    if any(n.endswith(".i8") for n in names):
        return "int8"
    return "float16" if any(n.endswith(".f16") for n in names) else "float32"
