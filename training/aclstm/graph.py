"""The dance models' ONNX graph, written directly with onnx.helper: K autoregressive steps in one session call.

    x (B, D), style (B, S), h, c (layers, B, H), steps (1,) int64  ->  ys (steps, B, D), h_out, c_out

An ONNX Loop runs `steps` steps; each step's output frame is the next step's input, as the page's dance loop
feeds it back, so one call replaces `steps` calls (steps = 1 is the plain one-step call, used for the seed frames).
A model with the Gaussian head (DanceLSTM head="gauss") takes two more inputs, noise (≥ steps, B, D) standard
normals and temperature (1,), and each step's frame is its draw mu + temperature · sigma · noise[step]: the caller
supplies the random numbers, so a seeded caller gets the same frames in any runtime.
Each LSTM layer is written at gate level (two Gemms, one Sigmoid over i, o, f, one Tanh over g); the style's share
of the first layer's input product and both biases are one Gemm before the loop, as the style is fixed for a call.
The batch dimension is dynamic. `dance_model_from_onnx` reads the network back from this graph or from the
earlier torch export (one step, ONNX LSTM nodes), so a shipped file can be rewritten without its checkpoint.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import onnx
import torch
from onnx import TensorProto, helper

from ..models.aclstm import LOG_SIGMA_RANGE, DanceLSTM, draw
from ..onnx.compact import float_initializers
from ..onnx.graph import OPSET, GraphBuilder
from ..onnx.lstm import lstm_node_weights, onnx_gates_to_torch, torch_gates_to_onnx
from ..onnx.sessions import cpu_session

INPUTS, OUTPUTS = ["x", "style", "h", "c", "steps"], ["ys", "h_out", "c_out"]
GAUSS_INPUTS = INPUTS + ["noise", "temperature"]
PARITY_TOLERANCE = 1e-4


def graph_inputs(model: DanceLSTM) -> list[str]:
    return GAUSS_INPUTS if model.head == "gauss" else INPUTS



def dance_graph(model: DanceLSTM) -> onnx.ModelProto:
    """The Loop graph of the module docstring for a trained DanceLSTM. Initialisers are named
    `lstm{l}.w_ih_t` (the first layer's: `lstm0.w_x_t` and `lstm0.w_style_t`), `lstm{l}.w_hh_t`, `lstm{l}.bias`
    (b_ih + b_hh) and `decoder.weight_t`, `decoder.bias`: dance_model_from_onnx reads them back."""
    if model.head == "mdn":  # issue 42: the phrase sampler's graph is a later step (training/aclstm/phrase_sampling.py)
        raise ValueError("the mdn head has no ONNX graph yet: its mixture and the phrase sampler are not exported")
    sd = {k: v.detach().cpu().numpy().astype(np.float32) for k, v in model.state_dict().items()}
    H, D, S, L = model.hidden, model.dim, model.styles, model.layers
    outer = GraphBuilder()
    const, node = outer.const, outer.node
    gates = lambda w: torch_gates_to_onnx(w, H)  # this graph keeps ONNX LSTM's gate order (i, o, f, g)
    w_ih = [gates(sd[f"lstm.weight_ih_l{l}"]) for l in range(L)]
    bias = [gates(sd[f"lstm.bias_ih_l{l}"] + sd[f"lstm.bias_hh_l{l}"]) for l in range(L)]
    w_in = [const("lstm0.w_x_t", w_ih[0][:, :D].T)] + [const(f"lstm{l}.w_ih_t", w_ih[l].T) for l in range(1, L)]
    w_hh = [const(f"lstm{l}.w_hh_t", gates(sd[f"lstm.weight_hh_l{l}"]).T) for l in range(L)]
    b = ["bias0"] + [const(f"lstm{l}.bias", bias[l]) for l in range(1, L)]
    node("Gemm", ["style", const("lstm0.w_style_t", w_ih[0][:, D:].T), const("lstm0.bias", bias[0])], ["bias0"])
    w_out, b_out = const("decoder.weight_t", sd["decoder.weight"].T), const("decoder.bias", sd["decoder.bias"])
    sig_tanh = const("sig_tanh_split", np.array([3 * H, H], np.int64))
    iof = const("iof_split", np.array([H, H, H], np.int64))

    # The loop body: one step. Loop-carried: the input frame, then h and c of each layer (B, H).
    body = GraphBuilder()
    h_in, c_in = [f"h{l}_in" for l in range(L)], [f"c{l}_in" for l in range(L)]
    inp = "x_in"
    for l in range(L):
        rec = body.node("Gemm", [h_in[l], w_hh[l], b[l]], [f"rec{l}"])
        pre = body.node("Gemm", [inp, w_in[l], rec], [f"pre{l}"])
        s_in, t_in = body.node("Split", [pre, sig_tanh], [f"sig_in{l}", f"tanh_in{l}"], axis=1)
        i, o, f = body.node("Split", [body.node("Sigmoid", [s_in], [f"sig{l}"]), iof], [f"i{l}", f"o{l}", f"f{l}"], axis=1)
        g = body.node("Tanh", [t_in], [f"g{l}"])
        c2 = body.node("Add", [body.node("Mul", [f, c_in[l]], [f"f_c{l}"]), body.node("Mul", [i, g], [f"i_g{l}"])], [f"c{l}_out"])
        inp = body.node("Mul", [o, body.node("Tanh", [c2], [f"tanh_c{l}"])], [f"h{l}_out"])
    if model.head == "gauss":
        out = body.node("Gemm", [inp, w_out, b_out], ["mu_log_sigma"])
        mu, log_sigma = body.node("Split", [out, const("mu_sigma_split", np.array([D, D], np.int64))], ["mu", "log_sigma_raw"], axis=1)
        lo, hi = (const(n, np.array(v, np.float32)) for n, v in (("log_sigma_min", LOG_SIGMA_RANGE[0]), ("log_sigma_max", LOG_SIGMA_RANGE[1])))
        sigma = body.node("Exp", [body.node("Clip", [log_sigma, lo, hi], ["log_sigma"])], ["sigma"])
        step_noise = body.node("Gather", ["noise", body.node("Squeeze", ["iteration"], ["step_index"])], ["step_noise"], axis=0)
        spread = body.node("Mul", [body.node("Mul", [sigma, "temperature"], ["scaled_sigma"]), step_noise], ["spread"])
        body.node("Add", [mu, spread], ["x_out"])
    else:
        body.node("Gemm", [inp, w_out, b_out], ["x_out"])
    body.node("Identity", ["x_out"], ["frame"])
    body.node("Identity", ["cond_in"], ["cond_out"])
    f32 = lambda n, shape: helper.make_tensor_value_info(n, TensorProto.FLOAT, shape)
    flag = lambda n, t: helper.make_tensor_value_info(n, t, [1])
    carried = lambda suffix: [f"x_{suffix}"] + [f"h{l}_{suffix}" for l in range(L)] + [f"c{l}_{suffix}" for l in range(L)]
    shape = lambda n: ["batch", D] if n.startswith("x") else ["batch", H]
    body_graph = helper.make_graph(
        body.nodes, "dance_step",
        [flag("iteration", TensorProto.INT64), flag("cond_in", TensorProto.BOOL)] + [f32(n, shape(n)) for n in carried("in")],
        [flag("cond_out", TensorProto.BOOL)] + [f32(n, shape(n)) for n in carried("out")] + [f32("frame", ["batch", D])], [])

    per_layer = const("per_layer", np.ones(L, np.int64))
    rows = const("rows", np.array([-1, H], np.int64))
    h_split = node("Split", ["h", per_layer], [f"h{l}" for l in range(L)], axis=0)
    c_split = node("Split", ["c", per_layer], [f"c{l}" for l in range(L)], axis=0)
    h0 = [node("Reshape", [h_split[l], rows], [f"h{l}_rows"]) for l in range(L)]
    c0 = [node("Reshape", [c_split[l], rows], [f"c{l}_rows"]) for l in range(L)]
    last = carried("last")
    node("Loop", ["steps", const("always", np.array([True])), "x"] + h0 + c0, last + ["ys"], body=body_graph)
    state = const("state_shape", np.array([L, -1, H], np.int64))
    node("Reshape", [node("Concat", last[1:1 + L], ["h_rows"], axis=0), state], ["h_out"])
    node("Reshape", [node("Concat", last[1 + L:], ["c_rows"], axis=0), state], ["c_out"])

    inputs = [f32("x", ["batch", D]), f32("style", ["batch", S]), f32("h", [L, "batch", H]), f32("c", [L, "batch", H]),
              helper.make_tensor_value_info("steps", TensorProto.INT64, [1])]
    if model.head == "gauss":
        inputs += [f32("noise", ["noise_steps", "batch", D]), f32("temperature", [1])]
    outputs = [f32("ys", ["steps", "batch", D]), f32("h_out", [L, "batch", H]), f32("c_out", [L, "batch", H])]
    graph = helper.make_graph(outer.nodes, "dance_steps", inputs, outputs, outer.inits)
    onnx_model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", OPSET)], producer_name="training.aclstm.export")
    onnx_model.ir_version = 8
    onnx.checker.check_model(onnx_model)  # (full_check's shape inference rejects Loop's rank-1 iteration count)
    return onnx_model


def dance_model_from_onnx(path: Path, dim: int, styles: int, hidden: int, layers: int) -> DanceLSTM:
    """The DanceLSTM an exported file holds: this module's Loop graph, or the earlier torch export (LSTM nodes).
    Weights stored in lower precision come back as the float32 values the graph computes with."""
    graph_model = onnx.load(str(path))
    w = float_initializers(graph_model)
    gauss = any(i.name == "noise" for i in graph_model.graph.input)
    model = DanceLSTM(dim, styles, hidden, layers, "gauss" if gauss else "mean")
    to_torch = lambda a: onnx_gates_to_torch(a, hidden)
    sd: dict[str, np.ndarray] = {}
    lstm_nodes = [n for n in graph_model.graph.node if n.op_type == "LSTM"]
    if lstm_nodes:  # the earlier torch export: one ONNX LSTM node per layer
        for l, n in enumerate(lstm_nodes):
            sd.update({f"lstm.{k}_l{l}": v for k, v in lstm_node_weights(n, w, hidden).items()})
        matmul = next(n for n in graph_model.graph.node if n.op_type == "MatMul")
        sd["decoder.weight"] = w[matmul.input[1]].T
        sd["decoder.bias"] = w["model.decoder.bias"]
    else:
        for l in range(layers):
            w_ih = np.concatenate([w["lstm0.w_x_t"], w["lstm0.w_style_t"]]) if l == 0 else w[f"lstm{l}.w_ih_t"]
            sd[f"lstm.weight_ih_l{l}"] = to_torch(w_ih.T)
            sd[f"lstm.weight_hh_l{l}"] = to_torch(w[f"lstm{l}.w_hh_t"].T)
            sd[f"lstm.bias_ih_l{l}"], sd[f"lstm.bias_hh_l{l}"] = to_torch(w[f"lstm{l}.bias"]), np.zeros(4 * hidden, np.float32)
        sd["decoder.weight"], sd["decoder.bias"] = w["decoder.weight_t"].T, w["decoder.bias"]
    model.load_state_dict({k: torch.from_numpy(np.ascontiguousarray(v)) for k, v in sd.items()})
    return model.eval()


def check_parity(model: DanceLSTM, path: Path, steps: int = 20, temperature: float = 0.5) -> dict:
    """torch (the one-step module, outputs fed back) against onnxruntime's Loop, at batch 1 and 5, in one call of
    `steps` steps and in calls of 1 step; a Gaussian head with the same normals and `temperature` in both."""
    session = cpu_session(path)
    rng = np.random.default_rng(1)
    worst = 0.0
    gauss = model.head == "gauss"
    for batch in (1, 5):
        x = rng.normal(size=(batch, model.dim)).astype(np.float32)
        style = np.eye(model.styles, dtype=np.float32)[rng.integers(0, model.styles, batch)]
        h, c = (rng.normal(scale=0.3, size=(model.layers, batch, model.hidden)).astype(np.float32) for _ in range(2))
        noise = rng.normal(size=(steps, batch, model.dim)).astype(np.float32)
        extra = lambda n: {"noise": noise[:n], "temperature": np.array([temperature], np.float32)} if gauss else {}
        ref, state = [], (h, c)
        xt = x
        for t in range(steps):
            with torch.no_grad():
                mu, log_sigma, (h2, c2) = model.distribution(torch.from_numpy(xt)[:, None], torch.from_numpy(style),
                                                             tuple(torch.from_numpy(a) for a in state))
                y = mu[:, 0] if log_sigma is None else draw(mu[:, 0], log_sigma[:, 0], temperature, torch.from_numpy(noise[t]))
            ref.append(y.numpy())
            xt, state = y.numpy(), (h2.numpy(), c2.numpy())
        ys, h_out, c_out = session.run(OUTPUTS, {"x": x, "style": style, "h": h, "c": c, "steps": np.array([steps], np.int64), **extra(steps)})
        worst = max(worst, float(np.abs(np.stack(ref) - ys).max()), float(np.abs(state[0] - h_out).max()),
                    float(np.abs(state[1] - c_out).max()))
        y1, _, _ = session.run(OUTPUTS, {"x": x, "style": style, "h": h, "c": c, "steps": np.array([1], np.int64), **extra(1)})
        worst = max(worst, float(np.abs(ref[0] - y1[0]).max()))
    if worst > PARITY_TOLERANCE:
        raise SystemExit(f"error: ONNX parity failed, max |torch - onnxruntime| = {worst:.2e} > {PARITY_TOLERANCE:.0e}")
    return {"max_abs_diff": worst, "tolerance": PARITY_TOLERANCE, "batches": [1, 5], "steps": [1, steps]}
