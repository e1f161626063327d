"""The VAE-LSTM read back from its four exported ONNX graphs (public/models/vae-lstm*.onnx), for when its checkpoint
is gone (runs/ is not in git) and the shipped files still have to be written again (export --from-shipped), and as
the parity reference of an export: the network exactly as the files store it.

The weights are read with training.onnx.compact.float_initializers, so a file whose large weights are stored as
float16 or int8 gives the float32 values its graph computes with. The three convolutional graphs name their
weights after the torch module (`fn.<parameter>`). The cell graph and the inference network's head also hold
anonymous initialisers (`onnx::MatMul_1033`: the torch exporter's pre-transposed right-hand sides of MatMul);
each is placed by the graph's structure, not its name:

- cell: each Gemm or MatMul weight by the graph inputs its data operand depends on at its first use (step 0):
  only `state` -> gates_state (a Gemm), only `hc` -> gates_control (a Gemm) or content_control (a MatMul), `z`
  (mix . z_t + (1 - mix) . state) -> content_state (a MatMul); every role is checked to have one weight, the named
  ones the role of their name, and every shape the one the module has (load_state_dict, strict).
- inference: the one MatMul after the convolutions is the head (Linear(features, 2 x latent)).

The read-back module is then compared with onnxruntime on every graph (exporting.check_parity; the pytest in
tests/python/test_vae_lstm.py does this on the shipped files).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import onnx
import torch

from ..models.vae_lstm import VaeLstm
from ..onnx.compact import float_initializers


def _producers(graph: onnx.GraphProto) -> dict[str, onnx.NodeProto]:
    return {out: n for n in graph.node for out in n.output}


def _source(name: str, producers: dict[str, onnx.NodeProto]) -> str:
    """The tensor `name` comes from, through Identity nodes (the exporter aliases a weight once per step)."""
    while name in producers and producers[name].op_type == "Identity":
        name = producers[name].input[0]
    return name


def _input_dependence(graph: onnx.GraphProto) -> dict[str, frozenset[str]]:
    """For every tensor, the graph inputs it depends on (nodes are in topological order in an export)."""
    deps: dict[str, frozenset[str]] = {i.name: frozenset([i.name]) for i in graph.input}
    for n in graph.node:
        d = frozenset().union(*(deps.get(i, frozenset()) for i in n.input if i))
        for out in n.output:
            deps[out] = d
    return deps


def _weight(inits: dict[str, np.ndarray], name: str, path: Path) -> np.ndarray:
    if name not in inits:
        raise ValueError(f"{path.name}: {name!r} is not an initialiser; not an export of training/vae_lstm/exporting.py")
    return inits[name]


def cell_state_dict(path: Path) -> dict[str, np.ndarray]:
    """CanvasCell's state dict from the cell graph (see the module docstring for how each weight is placed)."""
    model = onnx.load(str(path))
    graph, inits = model.graph, float_initializers(model)
    producers, deps = _producers(graph), _input_dependence(graph)
    roles: dict[str, str] = {}
    found: dict[str, tuple[np.ndarray, np.ndarray | None]] = {}
    for n in graph.node:
        if n.op_type not in ("Gemm", "MatMul"):
            continue
        name = _source(n.input[1], producers)
        if name in roles:
            continue  # placed at its first use
        fed_by = deps.get(n.input[0], frozenset())
        if n.op_type == "Gemm":
            attrs = {a.name: a.i for a in n.attribute}
            if not attrs.get("transB") or attrs.get("transA") or len(n.input) < 3:
                raise ValueError(f"{path.name}: Gemm {n.name} is not x . W^T + b")
            weight, bias = _weight(inits, name, path), _weight(inits, _source(n.input[2], producers), path)
        else:
            weight, bias = _weight(inits, name, path).T, None
        gemm = n.op_type == "Gemm"
        if fed_by == {"state"} and gemm:
            role = "gates_state"
        elif fed_by == {"hc"}:
            role = "gates_control" if gemm else "content_control"
        elif "z" in fed_by and not gemm:
            role = "content_state"
        else:
            raise ValueError(f"{path.name}: cannot place {name!r} ({n.op_type} on {sorted(fed_by)})")
        roles[name] = role
        if role in found:
            raise ValueError(f"{path.name}: two weights for the cell's {role}")
        found[role] = (weight, bias)
    missing = {"gates_state", "gates_control", "content_state", "content_control"} - set(found)
    if missing:
        raise ValueError(f"{path.name}: no weight found for the cell's {', '.join(sorted(missing))}")
    for name, role in roles.items():
        if name.startswith("cell.") and not name.startswith(f"cell.{role}."):
            raise ValueError(f"{path.name}: {name!r} sits where the cell's {role} does")
    sd = {}
    for role, (weight, bias) in found.items():
        sd[f"{role}.weight"] = weight
        if bias is not None:
            sd[f"{role}.bias"] = bias
    return sd


def conv_state_dict(path: Path) -> dict[str, np.ndarray]:
    """The state dict of a convolutional graph's module (control encoder, decoder, inference network): its named
    `fn.*` initialisers, and for the inference network the head's anonymous MatMul weight (transposed back)."""
    model = onnx.load(str(path))
    inits = float_initializers(model)
    producers = _producers(model.graph)
    sd = {name[len("fn."):]: value for name, value in inits.items() if name.startswith("fn.")}
    matmuls = [n for n in model.graph.node if n.op_type == "MatMul"]
    if len(matmuls) > 1:
        raise ValueError(f"{path.name}: {len(matmuls)} MatMul nodes; the inference network has one (its head)")
    for n in matmuls:
        name = _source(n.input[1], producers)
        if name.startswith("fn."):
            continue
        sd["head.weight"] = _weight(inits, name, path).T
    return sd


def vae_lstm_from_onnx(models_dir: Path, files: dict[str, str]) -> VaeLstm:
    """The VaeLstm (eval mode) the four graphs `files` (graph key -> file name, vae-lstm.json's `files`) in
    `models_dir` compute, its sizes read from the weights' shapes."""
    parts = {"cell": cell_state_dict(models_dir / files["cell"]),
             "control_encoder.net": _net(conv_state_dict(models_dir / files["control"])),
             "decoder.net": _net(conv_state_dict(models_dir / files["decoder"])),
             "inference": conv_state_dict(models_dir / files["inference"])}
    cell, control, decoder = parts["cell"], parts["control_encoder.net"], parts["decoder.net"]
    inference = parts["inference"]
    model = VaeLstm(dim=decoder["4.weight"].shape[0], control=control["0.weight"].shape[1],
                    latent=cell["gates_state.weight"].shape[1], control_features=cell["gates_control.weight"].shape[1],
                    inference_features=inference["encoder.net.3.weight"].shape[0], decoder_hidden=decoder["1.weight"].shape[0])
    sd = {f"{prefix}.{key}": torch.from_numpy(np.ascontiguousarray(value, np.float32))
          for prefix, part in parts.items() for key, value in part.items()}
    model.load_state_dict(sd)  # strict: every parameter found, shapes as the module has them
    return model.eval()


def _net(sd: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """`net.<i>.<p>` keys (a StepEncoder or CanvasDecoder wrapped whole) as `<i>.<p>` under the module's `net`."""
    out = {}
    for key, value in sd.items():
        if not key.startswith("net."):
            raise ValueError(f"unexpected initialiser fn.{key}")
        out[key[len("net."):]] = value
    return out
