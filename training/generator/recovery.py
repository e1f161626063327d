"""Rebuilding the generator's torch checkpoint from the shipped ONNX model and its JSON (python -m training.generator.recover).

For when runs/generator/best.pt is gone (runs/ is not in git) but the model still has to be re-exported.
The weights come from the ONNX initializers, the checkpoint's `meta` (dim, hidden, mixtures, fps,
normalisation, rotation references, training numbers) from generator.json, in the format
training/generator/training.py saves, so python -m training.generator.export works on the result. The rebuilt
model is checked against the ONNX file with onnxruntime before anything is written.

Reads both export forms: the original one (torch's exporter: two ONNX LSTM nodes, weights in ONNX gate
order i, o, f, c, fc layers as MatMul + Add) and the gate-level one training/generator/graph.py writes now
(initializers named after the torch layers, gates in the order GATE_ORDER). The gate-level form keeps only
b_ih + b_hh, so a checkpoint recovered from it holds that sum in bias_ih and zeros in bias_hh: the same model.

What cannot be recovered: the optimiser state (so no --resume from it) and the unrounded normalisation
and references (the JSON keeps 7 decimals; those rounded values are what the page uses anyway).
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import onnx
import torch

from ..mocap.rotations import quat_to_matrix
from ..models.generator import MixtureLSTM
from ..onnx.compact import float_initializers
from ..onnx.lstm import lstm_node_weights
from .graph import GATE_ORDER, parity_error

def _consumers(graph: onnx.GraphProto) -> dict[str, list[onnx.NodeProto]]:
    out: dict[str, list[onnx.NodeProto]] = {}
    for node in graph.node:
        for name in node.input:
            out.setdefault(name, []).append(node)
    return out


def _lstm_node_weights(graph: onnx.GraphProto, inits: dict[str, np.ndarray], hidden: int) -> dict[str, np.ndarray]:
    """State dict entries from the original export: LSTM nodes for the layers, MatMul (+ Add) for fc1-3."""
    state: dict[str, np.ndarray] = {}
    lstms = [n for n in graph.node if n.op_type == "LSTM"]
    if len(lstms) != 2:
        raise ValueError(f"expected 2 LSTM nodes, found {len(lstms)}")
    for layer, node in enumerate(lstms):
        state.update({f"lstm.{k}_l{layer}": v for k, v in lstm_node_weights(node, inits, hidden).items()})
    # fc1, fc2, fc3 are the MatMul nodes with a weight initializer, in graph order, each followed by an Add
    # of its bias (the legacy exporter's Linear); Gemm is accepted too.
    consumers = _consumers(graph)
    linears = []
    for node in graph.node:
        if node.op_type == "MatMul" and node.input[1] in inits:
            adds = [a for a in consumers.get(node.output[0], []) if a.op_type == "Add"]
            bias = next(name for a in adds for name in a.input if name in inits)
            linears.append((inits[node.input[1]].T, inits[bias]))
        elif node.op_type == "Gemm" and node.input[1] in inits:
            attrs = {a.name: onnx.helper.get_attribute_value(a) for a in node.attribute}
            w = inits[node.input[1]]
            linears.append((w if attrs.get("transB", 0) else w.T, inits[node.input[2]]))
    if len(linears) != 3:
        raise ValueError(f"expected 3 linear layers (fc1, fc2, fc3), found {len(linears)}")
    for k, (w, b) in enumerate(linears, start=1):
        state[f"fc{k}.weight"], state[f"fc{k}.bias"] = w, b
    return state


def _named_weights(inits: dict[str, np.ndarray], hidden: int) -> dict[str, np.ndarray]:
    """State dict entries from training/generator/graph.py's own graph, whose initializers are named after
    the torch layers: fcK.weight_t / fcK.bias (fc3 in three parts: logits, mu, log_sigma), and per LSTM
    layer lstmL_ih.weight_t, lstmL_hh.weight_t and lstmL_hh.bias (gates in the order GATE_ORDER, biases summed)."""
    state = {}
    for k in (1, 2):
        state[f"fc{k}.weight"], state[f"fc{k}.bias"] = inits[f"fc{k}.weight_t"].T, inits[f"fc{k}.bias"]
    parts = [f"fc3_{p}" for p in ("logits", "mu", "log_sigma")]
    state["fc3.weight"] = np.concatenate([inits[f"{p}.weight_t"].T for p in parts])
    state["fc3.bias"] = np.concatenate([inits[f"{p}.bias"] for p in parts])
    back = lambda w: w.reshape(4, hidden, *w.shape[1:])[np.argsort(GATE_ORDER)].reshape(4 * hidden, *w.shape[1:])
    for layer in (0, 1):
        state[f"lstm.weight_ih_l{layer}"] = back(inits[f"lstm{layer}_ih.weight_t"].T)
        state[f"lstm.weight_hh_l{layer}"] = back(inits[f"lstm{layer}_hh.weight_t"].T)
        state[f"lstm.bias_ih_l{layer}"] = back(inits[f"lstm{layer}_hh.bias"])
        state[f"lstm.bias_hh_l{layer}"] = np.zeros(4 * hidden, np.float32)
    return state


def model_from_onnx(path: Path, dim: int, hidden: int, mixtures: int) -> MixtureLSTM:
    """A MixtureLSTM (eval mode) holding the weights of the exported generator step at `path`."""
    graph = onnx.load(str(path)).graph
    inits = float_initializers(onnx.load(str(path)))
    if "fc1.weight_t" in inits:
        state = _named_weights(inits, hidden)
    elif any(n.op_type == "LSTM" for n in graph.node):
        state = _lstm_node_weights(graph, inits, hidden)
    else:
        raise ValueError(f"{path}: neither named initializers (fc1.weight_t ...) nor LSTM nodes; not a generator export")
    model = MixtureLSTM(dim, hidden, mixtures)
    expected = model.state_dict()
    for name, value in state.items():
        if tuple(value.shape) != tuple(expected[name].shape):
            raise ValueError(f"{path}: {name} has shape {value.shape}, the model needs {tuple(expected[name].shape)}")
    model.load_state_dict({name: torch.from_numpy(np.ascontiguousarray(v)) for name, v in state.items()})
    return model.eval()


def compare_with_onnx(model: MixtureLSTM, path: Path, batches=(1, 7), steps: int = 5, seed: int = 0) -> float:
    """Largest |torch - onnxruntime| / max(1, |torch|) from random states (see graph.parity_error)."""
    return parity_error(model, path, batches, steps, seed, state_scale=0.5)


def checkpoint_from_shipped(onnx_path: Path, info: dict) -> dict:
    """The best.pt dictionary (model, epoch, valid_nll, meta) training.py would have saved."""
    o, training = info["onnx"], info["training"]
    model = model_from_onnx(onnx_path, o["dim"], o["hidden"], o["mixtures"])
    references = quat_to_matrix(np.array(info["features"]["references"], np.float64))
    meta = {"dim": o["dim"], "hidden": o["hidden"], "mixtures": o["mixtures"], "fps": info["fps"],
            "mean": info["normalisation"]["mean"], "std": info["normalisation"]["std"],
            "references": references.tolist(), "valid_files": training["valid_files"],
            "train_frames": training["train_frames"], "args": training["args"]}
    digest = hashlib.sha256(onnx_path.read_bytes()).hexdigest()
    return {"model": model.state_dict(), "epoch": training["epochs"], "valid_nll": training["valid_nll_per_frame"],
            "meta": meta, "recovered_from": {"onnx": onnx_path.name, "sha256": digest}}


def recover_checkpoint(onnx_path: Path, info_path: Path, out: Path) -> tuple[dict, float]:
    """Rebuild the checkpoint from the export at `onnx_path` and its JSON, check it against the ONNX file with
    onnxruntime and write it to `out`; returns the checkpoint and the largest scaled difference."""
    info = json.loads(info_path.read_text())
    state = checkpoint_from_shipped(onnx_path, info)
    o = info["onnx"]
    model = MixtureLSTM(o["dim"], o["hidden"], o["mixtures"])
    model.load_state_dict(state["model"])
    worst = compare_with_onnx(model.eval(), onnx_path)
    if worst > 1e-5:
        raise SystemExit(f"error: the rebuilt model does not reproduce {onnx_path}: max scaled difference {worst:.2e} > 1e-5")
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(".tmp")
    torch.save(state, tmp)
    tmp.replace(out)
    return state, worst
