"""The generator step's matrix-product ceiling for npm run bench -- peers (the command is training/bench/peers.py).

A graph with only the generator step's dense products, the same inputs and outputs, names and shapes as the
shipped public/models/generator.onnx (x (B, D), h, c (2, B, H) -> weights (B, M), mu, sigma (B, M, D), h_out,
c_out (2, B, H)), so the page runs it exactly as it runs the generator (GeneratorClient.benchmark: the same
worker, thread count and feeding of h_out, c_out back as h, c). What the generator does beyond it (Relu, the
gate nonlinearities and the cell update, Softmax, the clamp and Exp of sigma) is the overhead the ratio
page / ceiling measures.

The products are those of training/generator/graph.py step_graph (Gemm on weights stored (in, out)): fc1, fc2,
per LSTM layer W_hh (with the summed bias) and W_ih (the first Gemm as its C input), and fc3's three Gemms. Each
layer's products stay whole here (4H columns, 9 Gemms in all) where the generator runs them per column block
((i, f, o) and g, 13 Gemms) so that onnxruntime fuses each block with its nonlinearity: the ceiling keeps the
fewer, larger calls, the faster form for the products alone. Only shape glue joins them: h and c are split per
layer (Split, Reshape), c feeds fc1's and fc2's Gemms as their C input (fc widths equal H in MixtureLSTM), each
layer's gates are split into blocks whose first (H wide) is the layer's c_out and last its h_out and the next
layer's input, the states are concatenated back, and mu and sigma are reshaped. The weights come from the network's shapes only
(MixtureLSTM with generator.json's sizes): random, small enough that the state fed back stays near a fixed
point of ordinary float magnitude (no denormals, no overflow); the time of dense products does not depend on
the values otherwise.
"""
from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import onnx

from ..models.generator import MixtureLSTM
from ..onnx.graph import GraphBuilder
from ..onnx.sessions import cpu_session

OUTPUTS = ["weights", "mu", "sigma", "h_out", "c_out"]
WEIGHT_SCALE = 0.1  # weights ~ N(0, (WEIGHT_SCALE / sqrt(fan_in))^2): the fed-back state contracts


def generator_sizes(models_dir: Path) -> dict:
    """dim, hidden, mixtures and layers of the shipped generator (generator.json's onnx block)."""
    o = json.loads((models_dir / "generator.json").read_text())["onnx"]
    return {k: int(o[k]) for k in ("dim", "hidden", "mixtures", "layers")}


def product_shapes(dim: int, hidden: int, mixtures: int) -> dict[str, tuple[int, ...]]:
    """The generator network's parameter shapes (MixtureLSTM's state dict, torch layout (out, in))."""
    return {k: tuple(v.shape) for k, v in MixtureLSTM(dim, hidden, mixtures).state_dict().items()}


def multiply_adds(shapes: dict[str, tuple[int, ...]]) -> int:
    """Multiply-adds per particle-step of the step's products (every 2-D weight once)."""
    return int(sum(s[0] * s[1] for k, s in shapes.items() if len(s) == 2))


def ceiling_graph(dim: int, hidden: int, mixtures: int, layers: int = 2, seed: int = 0) -> onnx.ModelProto:
    """The products-only graph (module docstring); the batch dimension is dynamic."""
    shapes = product_shapes(dim, hidden, mixtures)
    H, D, M = hidden, dim, mixtures
    if shapes["fc1.weight"][0] != H or shapes["fc2.weight"][0] != H:
        raise ValueError(f"fc1 and fc2 must be {H} wide to take c as their C input, got {shapes['fc1.weight']}, {shapes['fc2.weight']}")
    if layers != 2 or f"lstm.weight_ih_l{layers}" in shapes:
        raise ValueError(f"expected a 2-layer LSTM, generator.json says {layers}")
    rng = np.random.default_rng(seed)
    builder = GraphBuilder()
    const, node = builder.const, builder.node

    def gemm(inp, name, rows_out, c=None, cols=None):  # inp @ W (in, out) + bias or c
        fan_in = shapes[f"{name}.weight"][1] if cols is None else cols
        w = const(f"{name}.weight_t", (rng.standard_normal((fan_in, rows_out)) * WEIGHT_SCALE / np.sqrt(fan_in)).astype(np.float32))
        bias = c if c is not None else const(f"{name}.bias", rng.standard_normal(rows_out).astype(np.float32))
        return node("Gemm", [inp, w, bias], [name])

    per_layer = const("per_layer", np.array([1] * layers, np.int64))
    rows = const("rows", np.array([-1, H], np.int64))
    h_in = node("Split", ["h", per_layer], [f"h{k}" for k in range(layers)], axis=0)
    c_in = node("Split", ["c", per_layer], [f"c{k}" for k in range(layers)], axis=0)
    h_rows = [node("Reshape", [h_in[k], rows], [f"h{k}_rows"]) for k in range(layers)]
    c_rows = [node("Reshape", [c_in[k], rows], [f"c{k}_rows"]) for k in range(layers)]

    y = gemm("x", "fc1", H, c=c_rows[0])
    y = gemm(y, "fc2", H, c=c_rows[1])
    blocks = const("gate_blocks", np.array([H, 2 * H, H], np.int64))
    h_new, c_new = [], []
    for k in range(layers):
        four_h, _ = shapes[f"lstm.weight_hh_l{k}"]
        rec = gemm(h_rows[k], f"lstm{k}_hh", four_h, cols=H)
        pre = gemm(y, f"lstm{k}_ih", four_h, c=rec, cols=shapes[f"lstm.weight_ih_l{k}"][1])
        c2, _, y = node("Split", [pre, blocks], [f"c_new{k}", f"rest{k}", f"h_new{k}"], axis=1)
        h_new.append(y)
        c_new.append(c2)
    state = const("state_shape", np.array([layers, -1, H], np.int64))
    node("Reshape", [node("Concat", h_new, ["h_rows"], axis=0), state], ["h_out"])
    node("Reshape", [node("Concat", c_new, ["c_rows"], axis=0), state], ["c_out"])
    out3 = shapes["fc3.weight"][0]
    if out3 != M * (1 + 2 * D):
        raise ValueError(f"fc3 has {out3} outputs, expected {M * (1 + 2 * D)}")
    gemm(y, "weights", M, cols=H)  # the logits Gemm, named as the output the page reads
    mixture_shape = const("mixture_shape", np.array([-1, M, D], np.int64))
    node("Reshape", [gemm(y, "fc3_mu", M * D, cols=H), mixture_shape], ["mu"])
    node("Reshape", [gemm(y, "fc3_log_sigma", M * D, cols=H), mixture_shape], ["sigma"])

    return builder.model("generator_step_products",
        [("x", ["batch", D]), ("h", [layers, "batch", H]), ("c", [layers, "batch", H])],
        [("weights", ["batch", M]), ("mu", ["batch", M, D]), ("sigma", ["batch", M, D]),
         ("h_out", [layers, "batch", H]), ("c_out", [layers, "batch", H])],
        "training.bench.ceiling")


def write_ceiling(models_dir: Path, path: Path) -> dict:
    """Writes the ceiling graph of the shipped generator's sizes to `path`; returns what it is."""
    sizes = generator_sizes(models_dir)
    model = ceiling_graph(**sizes)
    path.parent.mkdir(parents=True, exist_ok=True)
    onnx.save(model, str(path))
    ops = sorted({n.op_type for n in model.graph.node})
    return {"path": str(path), "sizes": sizes, "ops": ops, "gemms": sum(n.op_type == "Gemm" for n in model.graph.node),
            "multiply_adds_per_particle_step": multiply_adds(product_shapes(sizes["dim"], sizes["hidden"], sizes["mixtures"]))}


def native_batch_rate(path: Path, batch: int, calls: int, warmup: int, threads: int = 1, seed: int = 0) -> dict:
    """Native onnxruntime on a generator-shaped step graph at `batch` rows: `calls` timed calls after `warmup`,
    x fixed, h_out and c_out fed back as h and c (as the page's benchmark does)."""
    session = cpu_session(path, threads=threads)
    shapes = {i.name: i.shape for i in session.get_inputs()}
    dim, (layers, _, hidden) = shapes["x"][1], shapes["h"]
    rng = np.random.default_rng(seed)
    feed = {"x": rng.standard_normal((batch, dim)).astype(np.float32),
            "h": np.zeros((layers, batch, hidden), np.float32), "c": np.zeros((layers, batch, hidden), np.float32)}

    def call():
        *_, feed["h"], feed["c"] = session.run(OUTPUTS, feed)

    for _ in range(warmup):
        call()
    t0 = time.perf_counter()
    for _ in range(calls):
        call()
    seconds = time.perf_counter() - t0
    return {"particle_steps_per_s": batch * calls / seconds, "ms_per_call": 1000 * seconds / calls}
