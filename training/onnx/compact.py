"""Lighter model files: large float32 weights stored as float16 or int8 and turned back into float32 inside the graph.

Each stored weight keeps its graph name; a small node chain right at the start of the graph makes it again:

- float16: `NAME.f16` --Cast(float)--> NAME
- int8: `NAME.i8` --Cast(float)--> * `NAME.scale` --> NAME, one scale per output channel (symmetric, max |w| / 127)

Both chains depend on initialisers only, so onnxruntime (and onnxruntime-web) folds them into float32 constants
when the session is created: the arithmetic stays float32 and a call costs what it did; only the download shrinks.
Weights smaller than MIN_ELEMENTS (biases, small tables) stay float32.
"""
from __future__ import annotations

import json
from pathlib import Path

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


def compact_weights(model: onnx.ModelProto, fmt: str, overrides: dict[str, str] | None = None) -> onnx.ModelProto:
    """A copy of `model` with every float32 initialiser of MIN_ELEMENTS or more stored as `fmt`, or as
    `overrides[name]` for the weights it names (a layer the coarser format measurably hurts)."""
    overrides = overrides or {}
    for f in {fmt, *overrides.values()}:
        if f not in FORMATS:
            raise ValueError(f"unknown weight format {f!r} (one of {', '.join(FORMATS)})")
    out = onnx.ModelProto()
    out.CopyFrom(model)
    graph = out.graph
    kept, nodes = [], []
    for init in graph.initializer:
        w = numpy_helper.to_array(init)
        stored = overrides.get(init.name, fmt)
        if init.data_type != TensorProto.FLOAT or w.size < MIN_ELEMENTS or stored == "float32":
            kept.append(init)
            continue
        if stored == "float16":
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
    """How the file stores its large weights: 'int8', 'float16', 'float32', or for a mix e.g. 'int8+float16'."""
    names = [t.name for t in model.graph.initializer]
    formats = [f for f, suffix in (("int8", ".i8"), ("float16", ".f16")) if any(n.endswith(suffix) for n in names)]
    return "+".join(formats) or "float32"


def compact_file(path: Path, fmt: str) -> tuple[int, int]:
    """Rewrites the float32 export at `path` with its large weights stored as `fmt`; returns (bytes before, after).
    A file already stored in lower precision is refused: compacting twice would round twice."""
    model = onnx.load(str(path))
    if weight_format(model) != "float32":
        raise ValueError(f"{path.name} already stores its weights as {weight_format(model)}; compact its float32 export")
    before = path.stat().st_size
    onnx.save(compact_weights(model, fmt), str(path))
    return before, path.stat().st_size


def files_weight_format(paths: list[Path]) -> str:
    """How a model's files store their weights together: one weight_format, or e.g. 'float32/int8' when they differ."""
    return "/".join(sorted({weight_format(onnx.load(str(p), load_external_data=False)) for p in paths}))


def model_files(info: dict) -> list[str]:
    """The ONNX files of a model JSON or manifest entry: `files` (several graphs) or `file`."""
    return sorted(set(info["files"].values())) if "files" in info else [info["file"]]


def refresh_bytes(models_dir: Path) -> None:
    """Sets `bytes` (the model's ONNX files together) and `weights` (their storage format) in each model JSON, and
    `bytes` in the manifest, from the files as they are now."""
    manifest_path = models_dir / "index.json"
    manifest = json.loads(manifest_path.read_text())
    for entry in manifest["models"]:
        info_path = models_dir / f"{entry['id']}.json"
        info = json.loads(info_path.read_text())
        files = [models_dir / f for f in model_files(info)]
        entry["bytes"] = info["bytes"] = sum(f.stat().st_size for f in files)
        info["weights"] = files_weight_format(files)
        info_path.write_text(json.dumps(info) + "\n")
    manifest_path.write_text(json.dumps(manifest, indent=1) + "\n")
