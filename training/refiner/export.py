"""Export the trained refiner R as a causal streaming model (ONNX) plus its JSON, parity-checked.

    python -m training.export_refiner [--checkpoint runs/refiner/shipped.pt]
    python -m training.export_refiner --checkpoint runs/refiner/checkpoint.pt --recover runs/refiner/shipped.pt
        (rebuild the torch checkpoint of the shipped export; see refiner_from_onnx)

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
sin(dry) q]), the LSTM is one ONNX LSTM node, and the residual is FC2 plus x. Also writes
public/models/refiner.json, the manifest entry and tests/fixtures/refiner_reference.json (two calls at
batch 2, for the browser's parity test and its end-effector computation).
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import onnx
import onnxruntime as ort
import torch
from onnx import numpy_helper

from ..footlock import BLEND_IN, BLEND_OUT, REACH, TOE_GROUND_HEIGHT
from ..onnx.manifest import register_model
from ..onnx.graph import OPSET, GraphBuilder
from ..models.refiner import Refiner, RefinerStep
from ..paths import MODELS_DIR, REPO_ROOT
from ..runs import RUNS_DIR

INPUTS, OUTPUTS = ["x", "ends", "ends_prev", "h", "c"], ["x_refined", "h_out", "c_out"]
PARITY_TOLERANCE = 1e-4
GATE_ORDER = [0, 3, 1, 2]  # the ONNX LSTM node's gate blocks (i, o, f, c) from PyTorch's (i, f, g, o)
FIXTURE = REPO_ROOT / "tests" / "fixtures" / "refiner_reference.json"


def load_refiner(checkpoint: Path) -> tuple[Refiner, dict, dict]:
    state = torch.load(checkpoint, weights_only=False)
    meta = state["meta"]
    model = Refiner(np.array(meta["mean"]), np.array(meta["std"]), np.array(meta["references"]), meta["hidden"],
                    np.array(meta["end_mean"]), np.array(meta["end_std"]), fps=meta["fps"])
    model.load_state_dict(state["refiner"])
    return model.eval(), meta, state


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
        "training.export_refiner")


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
    session = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
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
    session = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
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


def time_steps(path: Path, batch: int, inputs_fn, repeats: int = 3000) -> float:
    """Median over 5 runs of the mean ms per session.run at one thread."""
    options = ort.SessionOptions()
    options.intra_op_num_threads = 1
    session = ort.InferenceSession(str(path), options, providers=["CPUExecutionProvider"])
    feed = inputs_fn(batch)
    for _ in range(200):
        session.run(None, feed)
    runs = []
    for _ in range(5):
        t0 = time.perf_counter()
        for _ in range(repeats // 5):
            session.run(None, feed)
        runs.append((time.perf_counter() - t0) / (repeats // 5) * 1e3)
    return float(np.median(runs))


def measure_cost(refiner_path: Path, generator_path: Path, model: Refiner, gen_hidden: int, chunk: int = 15) -> dict:
    """Refiner against generator cost per frame: the generator one call per frame, the refiner one call per
    `chunk` frames (as the browser calls it, a generated chunk at a time)."""
    rng = np.random.default_rng(0)
    D, E3, H = model.dim, 3 * model.ends, model.hidden
    r_in = lambda b: {"x": rng.normal(size=(b, chunk, D)).astype(np.float32), "ends": rng.normal(size=(b, chunk, E3)).astype(np.float32),
                      "ends_prev": rng.normal(size=(b, E3)).astype(np.float32),
                      "h": np.zeros((1, b, H), np.float32), "c": np.zeros((1, b, H), np.float32)}
    g_in = lambda b: {"x": rng.normal(size=(b, D)).astype(np.float32), "h": np.zeros((2, b, gen_hidden), np.float32),
                      "c": np.zeros((2, b, gen_hidden), np.float32)}
    out = {"measure": f"onnxruntime Python, 1 thread, mean ms per frame (median of 5 runs, interleaved); the refiner "
                      f"in calls of {chunk} frames, the generator one call per frame"}
    for b in (1, 64):
        r, g = [], []
        for _ in range(2):  # interleaved, so both see the same machine load
            r.append(time_steps(refiner_path, b, r_in, repeats=600) / chunk)
            g.append(time_steps(generator_path, b, g_in))
        out[f"batch{b}"] = {"refiner_ms": min(r), "generator_ms": min(g), "ratio": min(r) / min(g)}
    return out


def write_fixture(model: Refiner, path: Path, frames: np.ndarray, info: dict) -> None:
    """Two streams of 4 frames in two calls (frames 1-3, then frame 4 from the first call's state): inputs
    (x, ends, ends_prev, h, c) and outputs per call, plus the physical frames the ends come from (for testing
    the browser's end-effector computation)."""
    session = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    x = frames[:2, :5]
    q = stream_inputs(model, x)
    mean, std = model.mean.numpy(), model.std.numpy()
    h = np.zeros((1, 2, model.hidden), np.float32)
    c = h.copy()
    calls = []
    for t, n in ((1, 3), (4, 1)):
        feed = {"x": x[:, t:t + n], "ends": q[:, t:t + n], "ends_prev": q[:, t - 1], "h": h, "c": c}
        out, h2, c2 = session.run(OUTPUTS, feed)
        calls.append({"frames": n, "inputs": {k: np.asarray(v).ravel().tolist() for k, v in feed.items()},
                      "outputs": {"x_refined": out.ravel().tolist(), "h_out": h2.ravel().tolist(), "c_out": c2.ravel().tolist()}})
        h, c = h2, c2
    FIXTURE.write_text(json.dumps({
        "model": info["file"], "batch": 2, "hidden": model.hidden, "dim": model.dim, "end_effectors": info["end_effectors"]["names"],
        "frames_normalised": x.ravel().tolist(), "frames_physical": (x * std + mean).ravel().tolist(), "frames": x.shape[1],
        "ends": q.ravel().tolist(), "calls": calls,
        "note": "frames_* are (batch 2, 5 frames, dim); ends (2, 5, 3E) are their root-frame end-effector positions; "
                "call 1 feeds frames 1-3 (x (2, 3, dim)) with ends_prev from frame 0 and zero states, call 2 feeds "
                "frame 4 with ends_prev from frame 3 and call 1's states."}) + "\n")
    print(f"wrote {FIXTURE}")


def refiner_from_onnx(path: Path, meta: dict) -> Refiner:
    """The torch Refiner computing what an export of sequence_graph computes: FC1 unfolded from the folded weights
    (the end-effector normalisation comes from `meta`, any run's; the function does not depend on it), the
    LSTM gates back in PyTorch's order, the summed LSTM bias as bias_ih."""
    inits = {t.name: numpy_helper.to_array(t).astype(np.float64) for t in onnx.load(str(path)).graph.initializer}
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


def recover_checkpoint(onnx_path: Path, meta_checkpoint: Path, info_json: Path, out: Path) -> float:
    """Rebuild a torch checkpoint for a shipped export (meta from a checkpoint of the same run, counters from
    the export's JSON); returns the largest output difference between the export and a re-export."""
    meta = torch.load(meta_checkpoint, weights_only=False)["meta"]
    info = json.loads(info_json.read_text())
    model = refiner_from_onnx(onnx_path, meta)
    t = info["training"]
    state = {"r_updates": t["r_updates"], "d_updates": t["d_updates"], "elapsed": t["minutes"] * 60}
    torch.save({"refiner": model.state_dict(), "meta": dict(meta, args=t["args"]), "state": state, "valid": t["valid"],
                "recovered_from": str(onnx_path)}, out)
    tmp = out.with_suffix(".onnx")
    export_onnx(model, tmp)
    rng = np.random.default_rng(0)
    a, b = (ort.InferenceSession(str(p), providers=["CPUExecutionProvider"]) for p in (onnx_path, tmp))
    feed = {"x": rng.normal(size=(5, 4, model.dim)).astype(np.float32), "ends": rng.normal(size=(5, 4, 3 * model.ends)).astype(np.float32),
            "ends_prev": rng.normal(size=(5, 3 * model.ends)).astype(np.float32),
            "h": rng.normal(size=(1, 5, model.hidden)).astype(np.float32), "c": rng.normal(size=(1, 5, model.hidden)).astype(np.float32)}
    diff = max(float(np.abs(u - v).max()) for u, v in zip(a.run(OUTPUTS, feed), b.run(OUTPUTS, feed)))
    tmp.unlink()
    return diff


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--checkpoint", type=Path, default=RUNS_DIR / "refiner" / "shipped.pt",
                        help="the shipped model's checkpoint (a run's best.pt or last.pt to try another)")
    parser.add_argument("--out", type=Path, default=MODELS_DIR)
    parser.add_argument("--recover", type=Path, default=None, metavar="OUT.pt",
                        help="instead of exporting: rebuild a torch checkpoint for the shipped refiner.onnx into OUT.pt "
                             "(meta from --checkpoint, a checkpoint of the same run)")
    args = parser.parse_args(argv)
    if args.recover is not None:
        diff = recover_checkpoint(MODELS_DIR / "refiner.onnx", args.checkpoint, MODELS_DIR / "refiner.json", args.recover)
        print(f"wrote {args.recover}; its re-export differs from the shipped export by {diff:.2e}")
        return
    if not args.checkpoint.exists():
        raise SystemExit(f"error: no checkpoint at {args.checkpoint}; train first with python -m training.train_refiner")
    model, meta, state = load_refiner(args.checkpoint)
    gen_info = json.loads((MODELS_DIR / "generator.json").read_text())
    if np.abs(np.array(gen_info["normalisation"]["mean"]) - np.array(meta["mean"])).max() > 1e-4:
        raise SystemExit("error: the refiner was trained with a different normalisation than the shipped generator's")
    args.out.mkdir(parents=True, exist_ok=True)
    onnx_path = args.out / "refiner.onnx"
    export_onnx(model, onnx_path)

    # Parity on generator-like frames: the validation streams cached by train_refiner when present, else noise.
    cached = sorted((REPO_ROOT / "cache").glob("refiner_generated_*_s101.npz"))
    frames = np.load(cached[0])["x"][:8, :21] if cached else \
        np.random.default_rng(0).normal(scale=0.5, size=(8, 21, model.dim)).astype(np.float32)
    worst = parity_error(model, onnx_path, frames)
    worst_step = step_parity(model, onnx_path, frames)
    if max(worst, worst_step) > PARITY_TOLERANCE:
        raise SystemExit(f"error: ONNX parity failed: {worst:.2e} (sequence), {worst_step:.2e} (step) > {PARITY_TOLERANCE:.0e}")
    print(f"parity ok: streaming vs torch sequence {worst:.2e}, vs torch step {worst_step:.2e}")
    cost = measure_cost(onnx_path, MODELS_DIR / "generator.onnx", model, gen_info["onnx"]["hidden"])
    print(f"cost: {json.dumps(cost)}")

    g = model.geometry
    s = state.get("state", {})
    info = {
        "id": "refiner", "kind": "refiner", "fps": meta["fps"], "file": "refiner.onnx", "bytes": onnx_path.stat().st_size,
        "pairs_with": "generator",
        "description": "Adversarial refiner (Wang, Chai, Xia §4.2): FC + LSTM + FC with a residual connection over the "
                       "generator's frames and their end-effector positions and velocities; causal, a chunk of frames per call (state in, state out).",
        "onnx": {"inputs": INPUTS, "outputs": OUTPUTS, "opset": OPSET, "hidden": model.hidden, "dim": model.dim,
                 "ends": 3 * model.ends, "state_shape": [1, "batch", model.hidden],
                 "shapes": {"x": ["batch", "frames", model.dim], "ends": ["batch", "frames", 3 * model.ends],
                            "ends_prev": ["batch", 3 * model.ends], "x_refined": ["batch", "frames", model.dim]},
                 "graph": "FC1 over [x, ends, ends_prev, cos(dry) ends, sin(dry) ends] (velocities and normalisation folded "
                          "in), one ONNX LSTM node over the frames, FC2 + x"},
        "end_effectors": {
            "names": g.end_names, "joints": g.end_index,
            "frame": "root frame: q = R_y(-yaw) (p - (root_x, 0, root_z)) per end effector, p the world position of the "
                     "decoded raw generator frame, yaw its heading (after its dry); q[1] = height above the floor. "
                     "Equivalently: FK with the root at (0, ty, 0) and the root rotation = reference[0] * exp(tilt) "
                     "(no heading).",
            "ends": "ends[t] = concat of q over `names` (x, y, z each), metres, of the raw frame x_t; "
                    "ends_prev = the same of the raw frame before the call's first (after a seed: the seed frame).",
            "velocity_in_graph": "v = fps * ((dtx, 0, dtz) + R_y(dry) q_t - q_(t-1)), R_y(a) q = (cos a qx + sin a qz, qy, "
                                 "-sin a qx + cos a qz), with dtx, dtz, dry of x_t",
        },
        "usage": "per chunk, after the generator sampled frames x_t..x_(t+T-1) (normalised, contacts snapped to 0/1 as "
                 "fed back): ends = rootFrameEnds(decode(frames)); x_ref = refiner(frames, ends, ends_prev, h, c); "
                 "ends_prev = ends of the last frame; "
                 "feed x_t (not x_ref) back to the generator; decode x_ref for display (contact on when its physical "
                 "value > 0.5), then the foot lock (training/footlock.py) on the decoded positions.",
        "normalisation": {"mean": [round(float(v), 7) for v in meta["mean"]], "std": [round(float(v), 7) for v in meta["std"]],
                          "note": "the generator's (generator.json)"},
        "contact_threshold": 0.5,
        "footlock": {"toe_ground_height": TOE_GROUND_HEIGHT, "blend_in_frames": BLEND_IN, "blend_out_frames": BLEND_OUT,
                     "reach": REACH, "implementation": "training/footlock.py (positions, two-bone IK, causal)"},
        "training": {"r_updates": s.get("r_updates"), "d_updates": s.get("d_updates"), "minutes": s.get("elapsed", 0) / 60,
                     "valid": state.get("valid"), "temperature": meta["temperature"], "args": meta["args"],
                     "checkpoint": str(args.checkpoint.relative_to(REPO_ROOT)) if args.checkpoint.is_relative_to(REPO_ROOT) else str(args.checkpoint)},
        "parity": {"max_abs_diff": worst, "step_max_abs_diff": worst_step, "measure": "|a - b| / max(1, |a|)",
                   "tolerance": PARITY_TOLERANCE, "batches": [1, 7], "steps": frames.shape[1] - 1,
                   "calls": "all frames in one call, one frame per call, and calls of 7 frames",
                   "reference": "torch full-sequence forward (nn.LSTM, torch FK) and torch RefinerStep"},
        "cost": cost,
    }
    (args.out / "refiner.json").write_text(json.dumps(info) + "\n")
    if args.out == MODELS_DIR:
        write_fixture(model, onnx_path, frames, info)
        register_model({"id": "refiner", "kind": "refiner", "skeleton": "cmu-canonical", "fps": info["fps"],
                        "bytes": info["bytes"], "file": info["file"]})
    print(f"wrote {onnx_path} ({onnx_path.stat().st_size / 1e6:.2f} MB) and refiner.json")


if __name__ == "__main__":
    main()
