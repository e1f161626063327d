"""The refiner R as a causal streaming ONNX graph, its parity checks against torch, and the way back
(refiner_from_onnx).

public/models/refiner.onnx: T frames per call (T dynamic; T = 1 is a single streaming step), inputs
    x          (B, T, D)  the generator's newest frames, normalised (generator.json normalisation), contacts
                          as the generator feeds them back (clean 0/1 bits, normalised);
    ends       (B, T, 3E) root-frame positions (metres) of the E end effectors of those raw frames;
    ends_prev  (B, 3E)    the same for the raw frame before the first (after a seed: the seed frame);
    h, c       (1, B, H)  R's LSTM state (zeros at the start of a stream);
outputs x_refined (B, T, D) normalised (same layout, contacts included), h_out, c_out after the last frame.
R is causal, so refining a chunk in one call gives what T single steps give. The batch is dynamic.
"Root frame": q = R_y(-yaw) (p - (root_x, 0, root_z)) for world positions p of the decoded frame, with
yaw the frame's heading (after its own dry), i.e. positions relative to the root's ground point with the
heading removed and y the height above the floor (models/refiner.py FeatureGeometry.end_positions).

The graph is written directly with onnx.helper (sequence_graph): the velocities v = fps (step + R_y(dry) q -
q_prev) and the input normalisation are folded into FC1's weights (FC1 acts on [x, q, q_prev, cos(dry) q,
sin(dry) q]), the LSTM is one ONNX LSTM node, and the residual is FC2 plus x.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import onnx
import torch

from ..models.refiner import Refiner, RefinerStep
from ..onnx.compact import float_initializers
from ..onnx.graph import GraphBuilder
from ..onnx.sessions import cpu_session

INPUTS, OUTPUTS = ["x", "ends", "ends_prev", "h", "c"], ["x_refined", "h_out", "c_out"]
PARITY_TOLERANCE = 1e-4
GATE_ORDER = [0, 3, 1, 2]  # the ONNX LSTM node's gate blocks (i, o, f, c) from PyTorch's (i, f, g, o)


def folded_fc1(model: Refiner) -> tuple[np.ndarray, np.ndarray]:
    """FC1 over z = [x, q, q_prev, cos(dry) q, sin(dry) q] (D + 12E inputs): weights (H, D + 12E), bias (H,).

    FC1(x, e) with e = ([q, v] - end_mean) / end_std and v = fps (P step + cos * Mc q + sin * Ms q + My q - q_prev),
    step = (dtx, dtz) = x[0:2] * std[0:2] + mean[0:2], is linear in each block of z."""
    g = model.geometry
    E3 = 3 * model.ends
    w = model.fc1.weight.detach().double().numpy()
    b = model.fc1.bias.detach().double().numpy()
    std, mean = model.std.double().numpy(), model.mean.double().numpy()
    em, es = model.end_mean.double().numpy(), model.end_std.double().numpy()
    D, fps = model.dim, g.fps
    wx, wq, wv = w[:, :D], w[:, D:D + E3] / es[:E3], w[:, D + E3:] / es[E3:]
    P = np.zeros((E3, 2))
    P[0::3, 0], P[2::3, 1] = 1.0, 1.0                       # (dtx, 0, dtz) per end effector
    Mc, Ms, My = np.zeros((E3, E3)), np.zeros((E3, E3)), np.zeros((E3, E3))
    for k in range(model.ends):
        x_, y_, z_ = 3 * k, 3 * k + 1, 3 * k + 2
        Mc[x_, x_], Mc[z_, z_] = 1.0, 1.0                   # cos part of R_y(dry) q
        Ms[x_, z_], Ms[z_, x_] = 1.0, -1.0                  # sin part: (qz, ., -qx)
        My[y_, y_] = 1.0
    wx = wx.copy()
    wx[:, 0:2] += fps * wv @ P * std[0:2]
    bias = b - wq @ em[:E3] - wv @ em[E3:] + fps * wv @ P @ mean[0:2]
    weights = np.concatenate([wx, wq + fps * wv @ My, -fps * wv, fps * wv @ Mc, fps * wv @ Ms], axis=1)
    return weights.astype(np.float32), bias.astype(np.float32)


def sequence_graph(model: Refiner) -> onnx.ModelProto:
    """R over T frames in one call (T dynamic; T = 1 is the streaming step): FC1 and FC2 as MatMuls over
    (B, T, .), the LSTM as one ONNX LSTM node. One call per generated chunk instead of one per frame: in
    onnxruntime-web a call's fixed cost is about that of R's arithmetic for a whole chunk."""
    H, D, E3 = model.hidden, model.dim, 3 * model.ends
    sd = {k: v.detach().cpu().numpy().astype(np.float32) for k, v in model.state_dict().items()}
    builder = GraphBuilder()
    const, node = builder.const, builder.node

    def gates(w):
        return w.reshape(4, H, *w.shape[1:])[GATE_ORDER].reshape(4 * H, *w.shape[1:])

    # q_prev per frame: ends_prev (the frame before the first), then ends without its last frame
    first = node("Unsqueeze", ["ends_prev", const("axis1", np.array([1], np.int64))], ["ends_first"])
    earlier = node("Slice", ["ends", const("slice_start", np.array([0], np.int64)), const("slice_end", np.array([-1], np.int64)),
                             "axis1"], ["ends_earlier"])
    q_prev = node("Concat", [first, earlier], ["q_prev"], axis=1)
    # dry (physical) per frame as a one-column MatMul of x, then its cosine and sine
    pick = np.zeros((D, 1), np.float32)
    pick[2, 0] = model.std[2].item()
    dry = node("Add", [node("MatMul", ["x", const("dry_pick", pick)], ["dry_scaled"]),
                       const("dry_mean", np.array([model.mean[2].item()], np.float32))], ["dry"])
    cq = node("Mul", ["ends", node("Cos", [dry], ["cos_dry"])], ["cos_q"])
    sq = node("Mul", ["ends", node("Sin", [dry], ["sin_dry"])], ["sin_q"])
    z = node("Concat", ["x", "ends", q_prev, cq, sq], ["fc1_in"], axis=2)
    w1, b1 = folded_fc1(model)
    y = node("Relu", [node("Add", [node("MatMul", [z, const("fc1.weight_t", w1.T)], ["fc1_mm"]), const("fc1.bias", b1)],
                           ["fc1"])], ["fc1_relu"])
    y_tb = node("Transpose", [y], ["fc1_tb"], perm=[1, 0, 2])  # (T, B, F): the LSTM node's layout
    w_ih, w_hh = gates(sd["lstm.weight_ih_l0"])[None], gates(sd["lstm.weight_hh_l0"])[None]
    bias = np.concatenate([gates(sd["lstm.bias_ih_l0"]), gates(sd["lstm.bias_hh_l0"])])[None]
    seq = node("LSTM", [y_tb, const("lstm.W", w_ih), const("lstm.R", w_hh), const("lstm.B", bias), "", "h", "c"],
               ["lstm_y", "h_out", "c_out"], hidden_size=H)
    hs = node("Transpose", [node("Squeeze", [seq[0], "axis1"], ["lstm_y_tbh"])], ["lstm_h_bt"], perm=[1, 0, 2])
    delta = node("Add", [node("MatMul", [hs, const("fc2.weight_t", sd["fc2.weight"].T)], ["fc2_mm"]), const("fc2.bias", sd["fc2.bias"])],
                 ["fc2"])
    node("Add", [delta, "x"], ["x_refined"])

    return builder.model("refiner_sequence",
        [("x", ["batch", "frames", D]), ("ends", ["batch", "frames", E3]), ("ends_prev", ["batch", E3]),
         ("h", [1, "batch", H]), ("c", [1, "batch", H])],
        [("x_refined", ["batch", "frames", D]), ("h_out", [1, "batch", H]), ("c_out", [1, "batch", H])],
        "training.refiner.export")


def export_onnx(model: Refiner, path: Path) -> None:
    onnx.save(sequence_graph(model.eval()), str(path))


def stream_inputs(model: Refiner, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Root-frame end positions (B, T, 3E) of normalised frames x (B, T, D): what the caller computes."""
    with torch.no_grad():
        q = model.geometry.end_positions(model.physical(torch.from_numpy(x.astype(np.float32))))
    return q.flatten(-2).numpy()


def parity_error(model: Refiner, path: Path, frames: np.ndarray, batches=(1, 7), chunks=(None, 1, 7)) -> float:
    """Largest |torch - onnxruntime| / max(1, |torch|) over all outputs, streaming `frames` (N, T + 1, D)
    (normalised, frame 0 = the frame before) from a zero state in calls of `chunk` frames (None: all at once,
    the rest of the sequence after the last whole chunk in a shorter call): torch's full-sequence forward
    (nn.LSTM, FK in torch) against the ONNX graph fed the same ends."""
    session = cpu_session(path)
    worst = 0.0
    for batch in batches:
        x = frames[:batch]
        q = stream_inputs(model, x)
        with torch.no_grad():
            ref, (ref_h, ref_c) = model(torch.from_numpy(x[:, 1:]), torch.from_numpy(x[:, 0]))
        ref = ref.numpy()
        scaled = lambda a, b: float((np.abs(a - b) / np.maximum(1.0, np.abs(b))).max())
        for chunk in chunks:
            h = np.zeros((1, batch, model.hidden), np.float32)
            c = h.copy()
            t, total = 1, x.shape[1]
            while t < total:
                n = total - t if chunk is None else min(chunk, total - t)
                out, h, c = session.run(OUTPUTS, {"x": x[:, t:t + n], "ends": q[:, t:t + n], "ends_prev": q[:, t - 1], "h": h, "c": c})
                worst = max(worst, scaled(out, ref[:, t - 1:t - 1 + n]))
                t += n
            worst = max(worst, scaled(h, ref_h.numpy()), scaled(c, ref_c.numpy()))
    return worst


def step_parity(model: Refiner, path: Path, frames: np.ndarray) -> float:
    """The graph at one frame per call against torch's RefinerStep (the step form) with states fed forward from torch."""
    session = cpu_session(path)
    step = RefinerStep(model).eval()
    x = frames[:5]
    q = stream_inputs(model, x)
    h = np.zeros((1, len(x), model.hidden), np.float32)
    c = h.copy()
    worst = 0.0
    for t in range(1, x.shape[1]):
        feed = {"x": x[:, t], "ends": q[:, t], "ends_prev": q[:, t - 1], "h": h, "c": c}
        with torch.no_grad():
            ref = [a.numpy() for a in step(*(torch.from_numpy(feed[k]) for k in INPUTS))]
        got = session.run(OUTPUTS, dict(feed, x=x[:, t:t + 1], ends=q[:, t:t + 1]))
        got[0] = got[0][:, 0]
        worst = max(worst, max(float(np.abs(a - b).max()) for a, b in zip(ref, got)))
        h, c = ref[1], ref[2]
    return worst


def refiner_from_onnx(path: Path, meta: dict) -> Refiner:
    """The torch Refiner computing what an export of sequence_graph computes: FC1 unfolded from the folded weights
    (the end-effector normalisation comes from `meta`, any run's; the function does not depend on it), the
    LSTM gates back in PyTorch's order, the summed LSTM bias as bias_ih."""
    inits = {n: v.astype(np.float64) for n, v in float_initializers(onnx.load(str(path))).items()}
    model = Refiner(np.array(meta["mean"]), np.array(meta["std"]), np.array(meta["references"]),
                    inits["lstm.R"].shape[-1], np.array(meta["end_mean"]), np.array(meta["end_std"]), fps=meta["fps"])
    g, D, E3, H = model.geometry, model.dim, 3 * model.ends, model.hidden
    std, mean = np.array(meta["std"]), np.array(meta["mean"])
    em, es = np.array(meta["end_mean"]), np.array(meta["end_std"])
    w = inits["fc1.weight_t"].T
    wx, wq_f, wqp = w[:, :D].copy(), w[:, D:D + E3], w[:, D + E3:D + 2 * E3]
    wv = -wqp / g.fps
    P = np.zeros((E3, 2))
    P[0::3, 0], P[2::3, 1] = 1.0, 1.0
    My = np.zeros((E3, E3))
    My[1::3, 1::3] = np.eye(model.ends)
    wq = wq_f - g.fps * wv @ My
    wx[:, 0:2] -= g.fps * wv @ P * std[0:2]
    bias = inits["fc1.bias"] + wq @ em[:E3] + wv @ em[E3:] - g.fps * wv @ P @ mean[0:2]
    inverse = np.argsort(GATE_ORDER)
    ungate = lambda a: a.reshape(4, H, *a.shape[1:])[inverse].reshape(4 * H, *a.shape[1:])
    lstm_b = inits["lstm.B"][0]
    sd = {"fc1.weight": np.concatenate([wx, wq * es[:E3], wv * es[E3:]], axis=1), "fc1.bias": bias,
          "lstm.weight_ih_l0": ungate(inits["lstm.W"][0]), "lstm.weight_hh_l0": ungate(inits["lstm.R"][0]),
          "lstm.bias_ih_l0": ungate(lstm_b[:4 * H]), "lstm.bias_hh_l0": ungate(lstm_b[4 * H:]),
          "fc2.weight": inits["fc2.weight_t"].T, "fc2.bias": inits["fc2.bias"]}
    state = model.state_dict()
    for k, v in sd.items():
        state[k] = torch.tensor(v, dtype=torch.float32)
    model.load_state_dict(state)
    return model.eval()
