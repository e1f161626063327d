"""Lighter model files: large float32 weights stored as float16, int8 or int4 and turned back into float32 inside the
graph.

Each stored weight keeps its graph name; a small node chain right at the start of the graph makes it again:

- float16: `NAME.f16` --Cast(float)--> NAME
- int8: `NAME.i8` --Cast(float)--> * `NAME.scale` --> NAME, one scale per output channel (symmetric, max |w| / 127)
- int4 (2-D weights whose output channels are the last axis, e.g. a Gemm's (in, out) right-hand side): blocks of
  INT4_BLOCK input rows share one float16 scale per output channel (symmetric, max |w| / 7), levels -7..7 stored
  as 1..15. Two levels share a byte: row r in the low four bits and row r + P/2 in the high four (P: the rows padded
  to whole blocks), so the chain only needs arithmetic that every runtime has: `NAME.i4` --Cast, /16, Floor--> the
  high rows, the rest the low rows, Concat, -8, * `NAME.i4scale` per block, Slice back to the real rows --> NAME.

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
FORMATS = ("float32", "float16", "int8")  # what every model's export offers
# int4 stores only 2-D weights whose output channels are last, and was measured only on the dance models
# (docs/models/weights.md): the dance export offers it, the others do not.
ALL_FORMATS = FORMATS + ("int4",)
INT4_BLOCK = 32


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


def quantise_int4(w: np.ndarray, hessian: np.ndarray | None = None, damping: float = 0.01) -> tuple[np.ndarray, np.ndarray]:
    """(in, out) float32 -> packed uint8 (P/2, out) and float16 scales (P/INT4_BLOCK, 1, out); see the module docstring.

    With `hessian` (in, in), the mean of x x^T over inputs x that the weight multiplies (x @ w), the rounding is
    GPTQ's (Frantar et al. 2023): rows are rounded in order and each row's rounding error is pushed onto the rows
    not yet rounded, weighted by the inverse Hessian, so that x @ w changes as little as possible on such inputs
    rather than w itself. Without it, each weight is rounded to its nearest level."""
    rows, cols = w.shape
    padded = -(-rows // INT4_BLOCK) * INT4_BLOCK
    work = np.zeros((padded, cols), np.float64)
    work[:rows] = w
    inverse = None
    if hessian is not None:
        h = hessian.astype(np.float64) + damping * np.mean(np.diag(hessian)) * np.eye(rows)
        # Upper Cholesky factor of H^-1: row i holds how row i's error spreads onto the rows after it.
        inverse = np.linalg.cholesky(np.linalg.inv(h)).T
    levels = np.zeros((padded, cols), np.int64)
    scale = np.ones((padded // INT4_BLOCK, 1, cols), np.float16)
    for i in range(padded):
        block = i // INT4_BLOCK
        if i % INT4_BLOCK == 0:  # the block's scales from its rows as they stand now (updated by earlier errors)
            top = np.abs(work[i:i + INT4_BLOCK]).max(axis=0) / 7.0
            scale[block, 0] = np.where(top > 0, top, 1.0).astype(np.float16)
        s = scale[block, 0].astype(np.float64)
        levels[i] = np.clip(np.rint(work[i] / s), -7, 7)
        if inverse is not None and i < rows - 1:
            error = (work[i] - levels[i] * s) / inverse[i, i]
            work[i + 1:rows] -= np.outer(inverse[i, i + 1:rows], error)
    stored = (levels + 8).astype(np.uint8)
    return stored[:padded // 2] | (stored[padded // 2:] << 4), scale


def dequantise_int4(packed: np.ndarray, scale: np.ndarray, rows: int) -> np.ndarray:
    """The float32 (rows, out) weight that the int4 chain computes (numpy's twin of _int4_nodes)."""
    levels = np.concatenate([packed & 15, packed >> 4]).astype(np.float32) - 8.0
    blocks = levels.reshape(scale.shape[0], INT4_BLOCK, -1) * scale.astype(np.float32)
    return blocks.reshape(-1, blocks.shape[-1])[:rows]


def _int4_nodes(name: str, rows: int, padded: int, cols: int) -> tuple[list, list]:
    """The node chain (and its small constants) that makes NAME from NAME.i4 and NAME.i4scale."""
    c = lambda value, suffix, dtype=np.float32: numpy_helper.from_array(np.array(value, dtype), f"{name}.i4_{suffix}")
    consts = [c(16.0, "sixteen"), c(8.0, "eight"), c([padded // INT4_BLOCK, INT4_BLOCK, cols], "blocks", np.int64),
              c([padded, cols], "padded", np.int64), c([0], "start", np.int64), c([rows], "rows", np.int64),
              c([0], "axis", np.int64)]
    n = lambda op, inputs, output, **kw: helper.make_node(op, inputs, [f"{name}.i4_{output}"], **kw)
    nodes = [n("Cast", [f"{name}.i4"], "byte", to=TensorProto.FLOAT),
             n("Div", [f"{name}.i4_byte", f"{name}.i4_sixteen"], "div"),
             n("Floor", [f"{name}.i4_div"], "high"),
             n("Mul", [f"{name}.i4_high", f"{name}.i4_sixteen"], "high16"),
             n("Sub", [f"{name}.i4_byte", f"{name}.i4_high16"], "low"),
             n("Concat", [f"{name}.i4_low", f"{name}.i4_high"], "stored", axis=0),
             n("Sub", [f"{name}.i4_stored", f"{name}.i4_eight"], "levels"),
             n("Reshape", [f"{name}.i4_levels", f"{name}.i4_blocks"], "blocked"),
             n("Cast", [f"{name}.i4scale"], "scale", to=TensorProto.FLOAT),
             n("Mul", [f"{name}.i4_blocked", f"{name}.i4_scale"], "scaled"),
             n("Reshape", [f"{name}.i4_scaled", f"{name}.i4_padded"], "full"),
             helper.make_node("Slice", [f"{name}.i4_full", f"{name}.i4_start", f"{name}.i4_rows", f"{name}.i4_axis"], [name])]
    return nodes, consts


def compact_weights(model: onnx.ModelProto, fmt: str, overrides: dict[str, str] | None = None,
                    hessians: dict[str, np.ndarray] | None = None) -> onnx.ModelProto:
    """A copy of `model` with every float32 initialiser of MIN_ELEMENTS or more stored as `fmt`, or as
    `overrides[name]` for the weights it names (a layer the coarser format measurably hurts). `hessians`: for int4,
    the input second moments of the weights it names (quantise_int4's GPTQ rounding)."""
    overrides = overrides or {}
    for f in {fmt, *overrides.values()}:
        if f not in ALL_FORMATS:
            raise ValueError(f"unknown weight format {f!r} (one of {', '.join(ALL_FORMATS)})")
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
        elif stored == "int4":
            if w.ndim != 2 or _channel_axis(model, init.name, w.ndim) != 1:
                raise ValueError(f"int4 stores 2-D weights with output channels last; {init.name} is {w.shape}")
            packed, scale = quantise_int4(w, (hessians or {}).get(init.name))
            chain, consts = _int4_nodes(init.name, w.shape[0], 2 * packed.shape[0], w.shape[1])
            kept += [numpy_helper.from_array(packed, f"{init.name}.i4"), numpy_helper.from_array(scale, f"{init.name}.i4scale"), *consts]
            nodes += chain
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
        elif name.endswith(".i4"):
            out[name[:-3]] = dequantise_int4(value, inits[f"{name}scale"], int(inits[f"{name}_rows"][0]))
    return out


def float_initializers(model: onnx.ModelProto) -> dict[str, np.ndarray]:
    """Every initialiser by its graph name as float32, the stored ones (see module docstring) turned back into the
    values the graph computes with: what reading the weights of any export needs, whatever its format."""
    inits = {t.name: numpy_helper.to_array(t) for t in model.graph.initializer}
    int4_parts = {f"{n[:-3]}.i4_{part}" for n in inits if n.endswith(".i4")
                  for part in ("sixteen", "eight", "blocks", "padded", "start", "rows", "axis")}  # _int4_nodes' constants
    out = {n: v.astype(np.float32) for n, v in inits.items()
           if not n.endswith((".f16", ".i8", ".scale", ".i4", ".i4scale")) and n not in int4_parts}
    return out | stored_float_weights(model)


def weight_format(model: onnx.ModelProto) -> str:
    """How the file stores its large weights: 'int4', 'int8', 'float16', 'float32', or for a mix e.g. 'int8+float16'."""
    names = [t.name for t in model.graph.initializer]
    formats = [f for f, suffix in (("int4", ".i4"), ("int8", ".i8"), ("float16", ".f16")) if any(n.endswith(suffix) for n in names)]
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
