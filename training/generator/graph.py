"""The generator's ONNX step graph, written directly with onnx.helper, and its parity check against torch."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import onnx
import torch

from ..models.generator import LOG_SIGMA_MIN, GeneratorStep, MixtureLSTM
from ..onnx.compact import compact_weights
from ..onnx.graph import GraphBuilder
from ..onnx.sessions import cpu_session

INPUTS, OUTPUTS = ["x", "h", "c"], ["weights", "mu", "sigma", "h_out", "c_out"]
PARITY_TOLERANCE = 1e-4
GATE_ORDER = [0, 1, 3, 2]  # the graph's gate blocks (i, f, o, g) from PyTorch's (i, f, g, o): one Sigmoid covers i, f, o


def step_graph(model: MixtureLSTM) -> onnx.ModelProto:
    """The generator step written directly as an ONNX graph: x (B, D), h, c (2, B, H) -> weights (B, M),
    mu, sigma (B, M, D), h_out, c_out (2, B, H); the batch dimension is dynamic.

    Each LSTM layer is written out at gate level: gates = Gemm(input, W_ih) + Gemm(h, W_hh, b_ih + b_hh) (the
    second Gemm is the first's C input, so no separate Add or Concat), then one Sigmoid over (i, f, o), one
    Tanh over g, and the cell update. The products run per column block, (i, f, o) and g, each block with its
    own Gemm pair, so onnxruntime fuses the block's last Gemm with its Sigmoid or Tanh (FusedGemm): the same
    frames bit for bit, a batch-64 step a few per cent faster in onnxruntime-web's Node build (docs/bench.md).
    The stored weights stay whole (4H columns); Split nodes on the initialisers, folded at load, cut them.
    fc1 and fc2 are Gemm + Relu (fused by onnxruntime); fc3 is three
    Gemms (mixture logits, means, log standard deviations), so no output is a slice of a larger tensor.
    Initializers are named after the torch layers; training/generator/recovery.py reads them back.
    A model with styles (MixtureLSTM(styles=N), issue 39) has a fourth input, style (B, N) float weights over the
    styles: x_styled = Concat(x, MatMul(style, style.weight)) feeds fc1 (training/style_generator/graph.py).
    """
    sd = {k: v.detach().cpu().numpy().astype(np.float32) for k, v in model.state_dict().items()}
    H, D, M = model.hidden, model.dim, model.mixtures
    builder = GraphBuilder()
    const, node = builder.const, builder.node

    def gemm(inp, name, weight, bias, out, c=None):  # inp @ weight.T + bias (torch layout), or + c
        w = const(f"{name}.weight_t", weight.T)
        return node("Gemm", [inp, w, const(f"{name}.bias", bias) if c is None else c], [out])

    def gates(w):  # rows in PyTorch's gate order -> GATE_ORDER
        return w.reshape(4, H, *w.shape[1:])[GATE_ORDER].reshape(4 * H, *w.shape[1:])

    inputs = [("x", ["batch", D]), ("h", [2, "batch", H]), ("c", [2, "batch", H])]
    fc1_input = "x"
    if model.styles > 0:  # the style generator (issue 39): x concatenated with style @ E; none of this without styles
        embedding = node("MatMul", ["style", const("style.weight", sd["style.weight"])], ["style_embedding"])
        fc1_input = node("Concat", ["x", embedding], ["x_styled"], axis=1)
        inputs.append(("style", ["batch", model.styles]))
    y = node("Relu", [gemm(fc1_input, "fc1", sd["fc1.weight"], sd["fc1.bias"], "fc1")], ["fc1_relu"])
    y = node("Relu", [gemm(y, "fc2", sd["fc2.weight"], sd["fc2.bias"], "fc2")], ["fc2_relu"])
    per_layer = const("per_layer", np.array([1, 1], np.int64))
    h_in = node("Split", ["h", per_layer], ["h0", "h1"], axis=0)  # (1, B, H) each
    c_in = node("Split", ["c", per_layer], ["c0", "c1"], axis=0)
    rows = const("rows", np.array([-1, H], np.int64))
    gate_split = const("gate_split", np.array([3 * H, H], np.int64))
    ifo_split = const("ifo_split", np.array([H, H, H], np.int64))
    h_new, c_new = [], []
    for layer in range(2):
        w_ih, w_hh = sd[f"lstm.weight_ih_l{layer}"], sd[f"lstm.weight_hh_l{layer}"]
        b = sd[f"lstm.bias_ih_l{layer}"] + sd[f"lstm.bias_hh_l{layer}"]
        h_rows = node("Reshape", [h_in[layer], rows], [f"h{layer}_rows"])
        c_rows = node("Reshape", [c_in[layer], rows], [f"c{layer}_rows"])
        # The column blocks (i, f, o) and g of the stored weights, split apart when the session is created.
        blocks = {}
        stored = ((f"lstm{layer}_ih.weight_t", gates(w_ih).T, 1), (f"lstm{layer}_hh.weight_t", gates(w_hh).T, 1),
                  (f"lstm{layer}_hh.bias", gates(b), 0))
        for name, value, axis in stored:
            blocks[name] = node("Split", [const(name, value), gate_split], [f"{name}.ifo", f"{name}.g"], axis=axis)
        pre = {}
        for k, part in enumerate(("ifo", "g")):
            rec = node("Gemm", [h_rows, blocks[f"lstm{layer}_hh.weight_t"][k], blocks[f"lstm{layer}_hh.bias"][k]], [f"rec_{part}{layer}"])
            pre[part] = node("Gemm", [y, blocks[f"lstm{layer}_ih.weight_t"][k], rec], [f"gates_{part}{layer}"])
        i, f, o = node("Split", [node("Sigmoid", [pre["ifo"]], [f"sig{layer}"]), ifo_split], [f"i{layer}", f"f{layer}", f"o{layer}"], axis=1)
        g = node("Tanh", [pre["g"]], [f"g{layer}"])
        c2 = node("Add", [node("Mul", [f, c_rows], [f"f_c{layer}"]), node("Mul", [i, g], [f"i_g{layer}"])], [f"c_new{layer}"])
        y = node("Mul", [o, node("Tanh", [c2], [f"tanh_c{layer}"])], [f"h_new{layer}"])
        h_new.append(y)
        c_new.append(c2)
    state = const("state_shape", np.array([2, -1, H], np.int64))
    node("Reshape", [node("Concat", h_new, ["h_rows"], axis=0), state], ["h_out"])
    node("Reshape", [node("Concat", c_new, ["c_rows"], axis=0), state], ["c_out"])
    w3, b3 = sd["fc3.weight"], sd["fc3.bias"]
    parts = {"logits": slice(0, M), "mu": slice(M, M + M * D), "log_sigma": slice(M + M * D, M + 2 * M * D)}
    out = {k: gemm(y, f"fc3_{k}", w3[s], b3[s], f"fc3_{k}") for k, s in parts.items()}
    node("Softmax", [out["logits"]], ["weights"], axis=-1)
    mixture_shape = const("mixture_shape", np.array([-1, M, D], np.int64))
    node("Reshape", [out["mu"], mixture_shape], ["mu"])
    log_sigma = node("Reshape", [out["log_sigma"], mixture_shape], ["log_sigma"])
    node("Exp", [node("Max", [log_sigma, const("log_sigma_min", np.array(LOG_SIGMA_MIN, np.float32))], ["log_sigma_clamped"])], ["sigma"])

    return builder.model("generator_step", inputs,
        [("weights", ["batch", M]), ("mu", ["batch", M, D]), ("sigma", ["batch", M, D]),
         ("h_out", [2, "batch", H]), ("c_out", [2, "batch", H])],
        "training.generator.export")


# The mixture head stays float16 when the rest is int8: int8 there (a scale per output row) moved the held-out
# NLL per frame from -28.9 to -14.5, as the means must be exact to a fraction of the small sigmas; int8 on every
# other layer moved it to -28.85 (docs/models/generator.md).
HEAD_WEIGHTS = ("fc3_logits.weight_t", "fc3_mu.weight_t", "fc3_log_sigma.weight_t")


def weight_overrides(weights: str) -> dict[str, str]:
    return {name: "float16" for name in HEAD_WEIGHTS} if weights == "int8" else {}


def export_onnx(model: MixtureLSTM, path: Path, weights: str = "float32") -> None:
    onnx.save(compact_weights(step_graph(model.eval()), weights, weight_overrides(weights)), str(path))


def parity_error(model: MixtureLSTM, path: Path, batches=(1, 7), steps: int = 20, seed: int = 1,
                 state_scale: float = 0.0) -> float:
    """Largest |torch - onnxruntime| / max(1, |torch|) over all outputs: torch (GeneratorStep: nn.LSTM, as
    trained) and onnxruntime side by side for `steps` steps at each batch size, random inputs, states fed
    forward from torch and starting from zero (state_scale 0) or random states of that scale."""
    session = cpu_session(path)
    step = GeneratorStep(model).eval()
    rng = np.random.default_rng(seed)
    worst = 0.0
    for batch in batches:
        h, c = (rng.normal(scale=state_scale, size=(2, batch, model.hidden)).astype(np.float32) for _ in range(2))
        for _ in range(steps):
            x = rng.normal(size=(batch, model.dim)).astype(np.float32)
            with torch.no_grad():
                ref = [t.numpy() for t in step(torch.from_numpy(x), torch.from_numpy(h), torch.from_numpy(c))]
            got = session.run(OUTPUTS, {"x": x, "h": h, "c": c})
            # Absolute below magnitude 1, relative above: unused mixture components can have sigmas in the
            # hundreds, where float32 rounding alone exceeds an absolute 1e-4.
            worst = max(worst, max(float((np.abs(a - b) / np.maximum(1.0, np.abs(a))).max()) for a, b in zip(ref, got)))
            h, c = ref[3], ref[4]
    return worst


def check_parity(model: MixtureLSTM, path: Path, steps: int = 20) -> dict:
    """The export's parity check at batch 1 and 7; exits when it fails."""
    worst = parity_error(model, path, steps=steps)
    if worst > PARITY_TOLERANCE:
        raise SystemExit(f"error: ONNX parity failed, max scaled |torch - onnxruntime| = {worst:.2e} > {PARITY_TOLERANCE:.0e}")
    return {"max_abs_diff": worst, "measure": "|a - b| / max(1, |a|)", "tolerance": PARITY_TOLERANCE, "batches": [1, 7], "steps": steps}
