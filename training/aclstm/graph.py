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

The mdn head (issue 42; the page's side of it: /tmp/brief/mdn-interface.md at the time of writing, the JSON's `onnx`
fields) runs the phrase sampler inside the Loop (mdn_graph):
    x, style, h, c, steps, held (B,) int64, age (B,) int64, wander (B, D), temperature, rho, threshold (B,),
    max_hold, min_hold (B,) int64, uniforms (>= steps, B), normals (>= steps, B, D), filt (B, 4, D), filter_b (B, 3),
    filter_a (B, 2)
    ->  ys (steps, B, D), display (steps, B, D), h_out, c_out, held_out, age_out, wander_out, filt_out, weights (steps, B, K)
Each step: the mixture (weights = softmax(logits), means, clipped log σ), the redraw rule and the inverse-CDF draw on
the step's uniform, the AR(1) wander on the step's normals, the frame mu[held] + temperature · σ[held] · wander (fed
back as the next input, `ys`) and that frame through the causal biquad (`display`, never fed back), all as
training/aclstm/phrase_sampling.py and jitter_filter.py compute them in torch (mdn_torch_steps; check_mdn_parity).
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
MDN_INPUTS = INPUTS + ["held", "age", "wander", "temperature", "rho", "threshold", "max_hold", "min_hold", "uniforms",
                       "normals", "filt", "filter_b", "filter_a"]
MDN_OUTPUTS = ["ys", "display", "h_out", "c_out", "held_out", "age_out", "wander_out", "filt_out", "weights"]
PARITY_TOLERANCE = 1e-4


def graph_inputs(model: DanceLSTM) -> list[str]:
    return {"gauss": GAUSS_INPUTS, "mdn": MDN_INPUTS}.get(model.head, INPUTS)


def graph_outputs(model: DanceLSTM) -> list[str]:
    return MDN_OUTPUTS if model.head == "mdn" else OUTPUTS


def _outer_weights(outer: GraphBuilder, model: DanceLSTM):
    """The network's initialisers (see dance_graph) and the style's Gemm into `bias0`: (w_in, w_hh, b, w_out, b_out)."""
    sd = {k: v.detach().cpu().numpy().astype(np.float32) for k, v in model.state_dict().items()}
    H, D, L = model.hidden, model.dim, model.layers
    const, node = outer.const, outer.node
    gates = lambda w: torch_gates_to_onnx(w, H)  # this graph keeps ONNX LSTM's gate order (i, o, f, g)
    w_ih = [gates(sd[f"lstm.weight_ih_l{l}"]) for l in range(L)]
    bias = [gates(sd[f"lstm.bias_ih_l{l}"] + sd[f"lstm.bias_hh_l{l}"]) for l in range(L)]
    w_in = [const("lstm0.w_x_t", w_ih[0][:, :D].T)] + [const(f"lstm{l}.w_ih_t", w_ih[l].T) for l in range(1, L)]
    w_hh = [const(f"lstm{l}.w_hh_t", gates(sd[f"lstm.weight_hh_l{l}"]).T) for l in range(L)]
    b = ["bias0"] + [const(f"lstm{l}.bias", bias[l]) for l in range(1, L)]
    node("Gemm", ["style", const("lstm0.w_style_t", w_ih[0][:, D:].T), const("lstm0.bias", bias[0])], ["bias0"])
    w_out, b_out = const("decoder.weight_t", sd["decoder.weight"].T), const("decoder.bias", sd["decoder.bias"])
    return w_in, w_hh, b, w_out, b_out


def _lstm_layers(body: GraphBuilder, outer: GraphBuilder, inp: str, h_in, c_in, w_in, w_hh, b, H: int) -> str:
    """The gate-level LSTM layers of one step inside the loop body; returns the top layer's output (B, H). Writes
    h{l}_out and c{l}_out."""
    sig_tanh = outer.const("sig_tanh_split", np.array([3 * H, H], np.int64))
    iof = outer.const("iof_split", np.array([H, H, H], np.int64))
    for l in range(len(h_in)):
        rec = body.node("Gemm", [h_in[l], w_hh[l], b[l]], [f"rec{l}"])
        pre = body.node("Gemm", [inp, w_in[l], rec], [f"pre{l}"])
        s_in, t_in = body.node("Split", [pre, sig_tanh], [f"sig_in{l}", f"tanh_in{l}"], axis=1)
        i, o, f = body.node("Split", [body.node("Sigmoid", [s_in], [f"sig{l}"]), iof], [f"i{l}", f"o{l}", f"f{l}"], axis=1)
        g = body.node("Tanh", [t_in], [f"g{l}"])
        c2 = body.node("Add", [body.node("Mul", [f, c_in[l]], [f"f_c{l}"]), body.node("Mul", [i, g], [f"i_g{l}"])], [f"c{l}_out"])
        inp = body.node("Mul", [o, body.node("Tanh", [c2], [f"tanh_c{l}"])], [f"h{l}_out"])
    return inp


def dance_graph(model: DanceLSTM) -> onnx.ModelProto:
    """The Loop graph of the module docstring for a trained DanceLSTM. Initialisers are named
    `lstm{l}.w_ih_t` (the first layer's: `lstm0.w_x_t` and `lstm0.w_style_t`), `lstm{l}.w_hh_t`, `lstm{l}.bias`
    (b_ih + b_hh) and `decoder.weight_t`, `decoder.bias`: dance_model_from_onnx reads them back."""
    if model.head == "mdn":
        return mdn_graph(model)
    H, D, S, L = model.hidden, model.dim, model.styles, model.layers
    outer = GraphBuilder()
    const, node = outer.const, outer.node
    w_in, w_hh, b, w_out, b_out = _outer_weights(outer, model)
    # The loop body: one step. Loop-carried: the input frame, then h and c of each layer (B, H).
    body = GraphBuilder()
    h_in, c_in = [f"h{l}_in" for l in range(L)], [f"c{l}_in" for l in range(L)]
    inp = _lstm_layers(body, outer, "x_in", h_in, c_in, w_in, w_hh, b, H)
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


def mdn_graph(model: DanceLSTM) -> onnx.ModelProto:
    """The mdn head's Loop graph (issue 42; the interface in the module docstring): each step the
    network's mixture, the phrase sampler's rule (training/aclstm/phrase_sampling.py) on the step's uniform and
    normals, the drawn frame fed back, and the causal biquad of training/aclstm/jitter_filter.py on it as `display`.
    The same initialiser names as dance_graph; the decoder's output is [logits (K), means (K·D), log σ (K·D)]."""
    H, D, S, L, K = model.hidden, model.dim, model.styles, model.layers, model.components
    I64, F32 = TensorProto.INT64, TensorProto.FLOAT
    outer = GraphBuilder()
    const, node = outer.const, outer.node
    w_in, w_hh, b, w_out, b_out = _outer_weights(outer, model)
    # Per-row parameters as columns (B, 1), computed once before the loop.
    axis1 = const("axis1", np.array([1], np.int64))
    col = lambda n: node("Unsqueeze", [n, axis1], [f"{n}_col"])
    temperature, rho, threshold = col("temperature"), col("rho"), col("threshold")
    one = const("one", np.array(1.0, np.float32))
    innovation = node("Sqrt", [node("Sub", [one, node("Mul", [rho, rho], ["rho2"])], ["one_minus_rho2"])], ["innovation"])
    b0, b1, b2 = node("Split", ["filter_b", const("split3", np.ones(3, np.int64))], ["b0", "b1", "b2"], axis=1)
    a1, a2 = node("Split", ["filter_a", const("split2", np.ones(2, np.int64))], ["a1", "a2"], axis=1)

    body = GraphBuilder()
    bn = body.node
    h_in, c_in = [f"h{l}_in" for l in range(L)], [f"c{l}_in" for l in range(L)]
    top = _lstm_layers(body, outer, "x_in", h_in, c_in, w_in, w_hh, b, H)
    out = bn("Gemm", [top, w_out, b_out], ["mixture"])
    logits, mu_flat, ls_flat = bn("Split", [out, const("mixture_split", np.array([K, K * D, K * D], np.int64))],
                                  ["logits", "mu_flat", "log_sigma_flat"], axis=1)
    bkd = const("bkd_shape", np.array([0, K, D], np.int64))
    mu = bn("Reshape", [mu_flat, bkd], ["mu"])
    lo, hi = (const(n, np.array(v, np.float32)) for n, v in (("log_sigma_min", LOG_SIGMA_RANGE[0]), ("log_sigma_max", LOG_SIGMA_RANGE[1])))
    log_sigma = bn("Clip", [bn("Reshape", [ls_flat, bkd], ["log_sigma_raw"]), lo, hi], ["log_sigma"])
    weights = bn("Softmax", [logits], ["step_weights"], axis=1)
    # The redraw rule: no component yet, held max_hold frames, or (after min_hold) its weight under the threshold.
    zero_i = const("zero_i", np.array(0, np.int64))
    one_i = const("one_i", np.array(1, np.int64))
    held_index = bn("Unsqueeze", [bn("Max", ["held_in", zero_i], ["held_clamped"]), axis1], ["held_index"])
    held_weight = bn("GatherElements", [weights, held_index], ["held_weight"], axis=1)  # (B, 1)
    weak = bn("And", [bn("GreaterOrEqual", ["age_in", "min_hold"], ["past_min"]),
                      bn("Squeeze", [bn("Less", [held_weight, threshold], ["below_col"]), axis1], ["below"])], ["weak"])
    redraw = bn("Or", [bn("Less", ["held_in", zero_i], ["fresh"]),
                       bn("Or", [bn("GreaterOrEqual", ["age_in", "max_hold"], ["old"]), weak], ["old_or_weak"])], ["redraw"])
    # The draw by inverse CDF over the allowed weights (the largest one's one-hot where none is allowed).
    allowed = bn("Mul", [weights, bn("Cast", [bn("GreaterOrEqual", [weights, threshold], ["allowed_mask"])], ["allowed_f"], to=F32)], ["allowed_raw"])
    none = bn("LessOrEqual", [bn("ReduceSum", [allowed, axis1], ["allowed_sum"], keepdims=1), const("zero_f", np.array(0.0, np.float32))], ["none_allowed"])
    top_k = bn("ArgMax", [weights], ["top_k"], axis=1, keepdims=1)
    one_hot = bn("Cast", [bn("Equal", [const("components_range", np.arange(K, dtype=np.int64)[None]), top_k], ["top_mask"])], ["top_one_hot"], to=F32)
    allowed = bn("Where", [none, one_hot, allowed], ["allowed"])
    cumulative = bn("CumSum", [allowed, one_i], ["cumulative"])
    total = bn("Slice", [cumulative, const("last_start", np.array([-1], np.int64)), const("last_end", np.array([K], np.int64)), axis1], ["total"])
    step = bn("Squeeze", ["iteration"], ["step_index"])
    u = bn("Unsqueeze", [bn("Gather", ["uniforms", step], ["step_uniform"], axis=0), axis1], ["u_col"])
    below_u = bn("Cast", [bn("LessOrEqual", [cumulative, bn("Mul", [u, total], ["u_total"])], ["below_u_mask"])], ["below_u"], to=I64)
    drawn = bn("ReduceSum", [below_u, axis1], ["drawn"], keepdims=0)
    held = bn("Where", [redraw, drawn, "held_in"], ["held_out_step"])
    age = bn("Add", [bn("Where", [redraw, zero_i, "age_in"], ["age_kept"]), one_i], ["age_out_step"])
    # The held component's frame from the AR(1) normals.
    normal = bn("Gather", ["normals", step], ["step_normal"], axis=0)
    wander = bn("Add", [bn("Mul", [rho, "wander_in"], ["wander_kept"]), bn("Mul", [innovation, normal], ["wander_new"])], ["wander_out_step"])
    pick = bn("Expand", [bn("Unsqueeze", [held, const("axes12", np.array([1, 2], np.int64))], ["held_b11"]),
                         const("pick_shape", np.array([1, 1, D], np.int64))], ["pick"])
    mu_held = bn("Squeeze", [bn("GatherElements", [mu, pick], ["mu_held_1"], axis=1), axis1], ["mu_held"])
    ls_held = bn("Squeeze", [bn("GatherElements", [log_sigma, pick], ["log_sigma_held_1"], axis=1), axis1], ["log_sigma_held"])
    spread = bn("Mul", [bn("Mul", [temperature, bn("Exp", [ls_held], ["sigma_held"])], ["scaled_sigma"]), wander], ["spread"])
    y = bn("Add", [mu_held, spread], ["x_out"])
    # The output filter: y_f = b0·y + b1·x1 + b2·x2 - a1·y1 - a2·y2 on the state (x1, x2, y1, y2) (B, 4, D).
    x1, x2, y1, y2 = (bn("Squeeze", [s, axis1], [f"filt_{n}"]) for s, n in
                      zip(bn("Split", ["filt_in", const("split4", np.ones(4, np.int64))], ["filt_x1_1", "filt_x2_1", "filt_y1_1", "filt_y2_1"], axis=1),
                          ("x1", "x2", "y1", "y2")))
    terms = [bn("Mul", [c, v], [f"term_{n}"]) for c, v, n in ((b0, y, "b0"), (b1, x1, "b1"), (b2, x2, "b2"), (a1, y1, "a1"), (a2, y2, "a2"))]
    fed = bn("Add", [bn("Add", [terms[0], terms[1]], ["sum01"]), terms[2]], ["sum012"])
    shown = bn("Sub", [bn("Sub", [fed, terms[3]], ["minus_a1"]), terms[4]], ["shown"])
    bn("Concat", [bn("Unsqueeze", [v, axis1], [f"{n}_1"]) for v, n in ((y, "new_x1"), (x1, "new_x2"), (shown, "new_y1"), (y1, "new_y2"))],
       ["filt_out_step"], axis=1)
    bn("Identity", [y], ["frame"])
    bn("Identity", [shown], ["display_frame"])
    bn("Identity", [weights], ["weights_frame"])
    bn("Identity", ["cond_in"], ["cond_out"])

    f32 = lambda n, shape: helper.make_tensor_value_info(n, F32, shape)
    i64 = lambda n, shape: helper.make_tensor_value_info(n, I64, shape)
    flag = lambda n, t: helper.make_tensor_value_info(n, t, [1])
    lstm = lambda suffix: [f"h{l}_{suffix}" for l in range(L)] + [f"c{l}_{suffix}" for l in range(L)]
    carried_in = [f32("x_in", ["batch", D])] + [f32(n, ["batch", H]) for n in lstm("in")] + [
        i64("held_in", ["batch"]), i64("age_in", ["batch"]), f32("wander_in", ["batch", D]), f32("filt_in", ["batch", 4, D])]
    carried_out = [f32("x_out", ["batch", D])] + [f32(n, ["batch", H]) for n in lstm("out")] + [
        i64("held_out_step", ["batch"]), i64("age_out_step", ["batch"]), f32("wander_out_step", ["batch", D]), f32("filt_out_step", ["batch", 4, D])]
    scans = [f32("frame", ["batch", D]), f32("display_frame", ["batch", D]), f32("weights_frame", ["batch", K])]
    body_graph = helper.make_graph(body.nodes, "dance_mdn_step", [flag("iteration", I64), flag("cond_in", TensorProto.BOOL)] + carried_in,
                                   [flag("cond_out", TensorProto.BOOL)] + carried_out + scans, [])

    per_layer = const("per_layer", np.ones(L, np.int64))
    rows = const("rows", np.array([-1, H], np.int64))
    h_split = node("Split", ["h", per_layer], [f"h{l}" for l in range(L)], axis=0)
    c_split = node("Split", ["c", per_layer], [f"c{l}" for l in range(L)], axis=0)
    h0 = [node("Reshape", [h_split[l], rows], [f"h{l}_rows"]) for l in range(L)]
    c0 = [node("Reshape", [c_split[l], rows], [f"c{l}_rows"]) for l in range(L)]
    last = ["x_last"] + lstm("last") + ["held_out", "age_out", "wander_out", "filt_out"]
    node("Loop", ["steps", const("always", np.array([True])), "x"] + h0 + c0 + ["held", "age", "wander", "filt"],
         last + ["ys", "display", "weights"], body=body_graph)
    state = const("state_shape", np.array([L, -1, H], np.int64))
    node("Reshape", [node("Concat", last[1:1 + L], ["h_rows"], axis=0), state], ["h_out"])
    node("Reshape", [node("Concat", last[1 + L:1 + 2 * L], ["c_rows"], axis=0), state], ["c_out"])

    inputs = [f32("x", ["batch", D]), f32("style", ["batch", S]), f32("h", [L, "batch", H]), f32("c", [L, "batch", H]),
              i64("steps", [1]), i64("held", ["batch"]), i64("age", ["batch"]), f32("wander", ["batch", D]),
              f32("temperature", ["batch"]), f32("rho", ["batch"]), f32("threshold", ["batch"]),
              i64("max_hold", ["batch"]), i64("min_hold", ["batch"]),
              f32("uniforms", ["random_steps", "batch"]), f32("normals", ["random_steps", "batch", D]),
              f32("filt", ["batch", 4, D]), f32("filter_b", ["batch", 3]), f32("filter_a", ["batch", 2])]
    outputs = [f32("ys", ["steps", "batch", D]), f32("display", ["steps", "batch", D]), f32("h_out", [L, "batch", H]),
               f32("c_out", [L, "batch", H]), i64("held_out", ["batch"]), i64("age_out", ["batch"]),
               f32("wander_out", ["batch", D]), f32("filt_out", ["batch", 4, D]), f32("weights", ["steps", "batch", K])]
    graph = helper.make_graph(outer.nodes, "dance_mdn_steps", inputs, outputs, outer.inits)
    onnx_model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", OPSET)], producer_name="training.aclstm.export")
    onnx_model.ir_version = 8
    onnx.checker.check_model(onnx_model)
    return onnx_model


def dance_model_from_onnx(path: Path, dim: int, styles: int, hidden: int, layers: int) -> DanceLSTM:
    """The DanceLSTM an exported file holds: this module's Loop graph, or the earlier torch export (LSTM nodes).
    Weights stored in lower precision come back as the float32 values the graph computes with."""
    graph_model = onnx.load(str(path))
    w = float_initializers(graph_model)
    names = {i.name for i in graph_model.graph.input}
    if "uniforms" in names:  # the mdn graph: K from the decoder's width, K · (2D + 1)
        model = DanceLSTM(dim, styles, hidden, layers, "mdn", len(w["decoder.bias"]) // (2 * dim + 1))
    else:
        model = DanceLSTM(dim, styles, hidden, layers, "gauss" if "noise" in names else "mean")
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
    """An mdn head: check_mdn_parity. Otherwise: torch (the one-step module, outputs fed back) against onnxruntime's Loop, at batch 1 and 5, in one call of
    `steps` steps and in calls of 1 step; a Gaussian head with the same normals and `temperature` in both."""
    if model.head == "mdn":
        return check_mdn_parity(model, path)
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


def mdn_torch_steps(model: DanceLSTM, feeds: dict) -> dict:
    """The mdn graph's outputs computed in torch from the same feeds (numpy, the graph's inputs): DanceLSTM.mixture,
    the PhraseSampler (training/aclstm/phrase_sampling.py) on the given uniforms and normals, and the CausalLowPass
    (training/aclstm/jitter_filter.py). Returns the graph's outputs by name, plus `redraws` per row."""
    from .jitter_filter import CausalLowPass
    from .phrase_sampling import PhraseParams, PhraseSampler

    t = lambda a: torch.from_numpy(np.asarray(a))
    batch = len(feeds["x"])
    params = [PhraseParams(float(feeds["temperature"][r]), int(feeds["max_hold"][r]), float(feeds["rho"][r]),
                           float(feeds["threshold"][r]), int(feeds["min_hold"][r])) for r in range(batch)]
    sampler = PhraseSampler(params, model.dim, wander=t(feeds["wander"]))
    sampler.held, sampler.age = t(feeds["held"]).clone(), t(feeds["age"]).clone()
    sampler.temperature = t(feeds["temperature"]).unsqueeze(-1)
    sampler.rho, sampler.threshold = t(feeds["rho"]).unsqueeze(-1), t(feeds["threshold"])
    lowpass = CausalLowPass(feeds["filter_b"], feeds["filter_a"], feeds["filt"])
    x, style, state = t(feeds["x"]), t(feeds["style"]), (t(feeds["h"]), t(feeds["c"]))
    ys, shown, weights = [], [], []
    with torch.no_grad():
        for k in range(int(feeds["steps"][0])):
            logits, mu, log_sigma, state = model.mixture(x[:, None], style, state)
            weights.append(torch.softmax(logits[:, 0], -1))
            x = sampler.step(logits[:, 0], mu[:, 0], log_sigma[:, 0], t(feeds["uniforms"][k]), t(feeds["normals"][k]))
            ys.append(x)
            shown.append(lowpass.step(x))
    out = {"ys": torch.stack(ys), "display": torch.stack(shown), "h_out": state[0], "c_out": state[1],
           "held_out": sampler.held, "age_out": sampler.age, "wander_out": sampler.wander, "filt_out": lowpass.state,
           "weights": torch.stack(weights)}
    return {**{k: v.numpy() for k, v in out.items()}, "redraws": sampler.redraws.numpy()}


def mdn_parity_feeds(model: DanceLSTM, batch: int, steps: int, rng: np.random.Generator) -> dict:
    """Random feeds for the mdn graph: a state mid-dance (some rows holding a component, some fresh), per-row phrase
    parameters with short holds (so a component is redrawn inside the call) and filters at 4-12 Hz (30 fps)."""
    from .jitter_filter import butterworth_lowpass

    D, L, H, K = model.dim, model.layers, model.hidden, model.components
    filters = [butterworth_lowpass(float(f), 30.0) for f in rng.uniform(4, 12, batch)]
    return {
        "x": rng.normal(size=(batch, D)).astype(np.float32),
        "style": np.eye(model.styles, dtype=np.float32)[rng.integers(0, model.styles, batch)],
        "h": rng.normal(scale=0.3, size=(L, batch, H)).astype(np.float32),
        "c": rng.normal(scale=0.3, size=(L, batch, H)).astype(np.float32),
        "steps": np.array([steps], np.int64),
        "held": np.array([-1 if r % 2 == 0 else int(rng.integers(0, K)) for r in range(batch)], np.int64),
        "age": rng.integers(0, 4, batch).astype(np.int64),
        "wander": rng.normal(size=(batch, D)).astype(np.float32),
        "temperature": rng.uniform(0.2, 0.7, batch).astype(np.float32),
        "rho": rng.uniform(0.0, 0.95, batch).astype(np.float32),
        "threshold": rng.uniform(0.02, 0.1, batch).astype(np.float32),
        "max_hold": rng.integers(3, 9, batch).astype(np.int64),
        "min_hold": rng.integers(0, 3, batch).astype(np.int64),
        "uniforms": rng.random((steps, batch)).astype(np.float32),
        "normals": rng.normal(size=(steps, batch, D)).astype(np.float32),
        "filt": np.repeat(rng.normal(size=(batch, 1, D)), 4, axis=1).astype(np.float32),
        "filter_b": np.array([f[0] for f in filters], np.float32),
        "filter_a": np.array([f[1][1:] for f in filters], np.float32),
    }


def check_mdn_parity(model: DanceLSTM, path: Path, steps: int = 40) -> dict:
    """torch (mdn_torch_steps) against onnxruntime on the same feeds, at batch 1 and 3, in one call of 1 step and of
    `steps` steps; checks that a component was redrawn inside a call (a row already holding one)."""
    session = cpu_session(path)
    rng = np.random.default_rng(1)
    worst, redrawn = 0.0, 0
    for batch in (1, 3):
        for n in (1, steps):
            feeds = mdn_parity_feeds(model, batch, n, rng)
            ref = mdn_torch_steps(model, feeds)
            got = dict(zip(MDN_OUTPUTS, session.run(MDN_OUTPUTS, feeds)))
            for name in MDN_OUTPUTS:
                worst = max(worst, float(np.abs(ref[name].astype(np.float64) - got[name]).max()))
            if n > 1:  # redraws inside the call beyond the first draw of a fresh row
                redrawn += int((ref["redraws"] - (feeds["held"] < 0)).sum())
    if worst > PARITY_TOLERANCE:
        raise SystemExit(f"error: ONNX parity failed, max |torch - onnxruntime| = {worst:.2e} > {PARITY_TOLERANCE:.0e}")
    if redrawn == 0:
        raise SystemExit("error: ONNX parity: no component was redrawn inside a call, the draw is untested")
    return {"max_abs_diff": worst, "tolerance": PARITY_TOLERANCE, "batches": [1, 3], "steps": [1, steps],
            "redraws_in_calls": redrawn}
