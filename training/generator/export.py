"""Export the trained generator to ONNX plus its JSON, with seed states and a parity check.

    python -m training.export_generator [--checkpoint runs/generator/best.pt]

Writes public/models/generator.onnx (one step: x, h, c -> weights, mu, sigma, h_out, c_out; the batch
dimension is dynamic; the graph is built directly, see step_graph) and public/models/generator.json (skeleton, feature layout, normalisation,
rotation references, seed states estimated as in eq. 26, training and parity numbers).
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import onnx
import onnxruntime as ort
import torch

from ..data.features import FIXED_JOINTS, FeatureCodec, feature_names
from ..models.generator import LOG_SIGMA_MIN, GeneratorStep, MixtureLSTM, mixture_nll
from ..onnx.manifest import register_model
from ..onnx.graph import OPSET, GraphBuilder
from ..paths import MODELS_DIR, REPO_ROOT
from ..mocap.rotations import matrix_to_quat
from ..runs import RUNS_DIR
from ..mocap.skeleton import canonical_skeleton
from .train import load_clips

INPUTS, OUTPUTS = ["x", "h", "c"], ["weights", "mu", "sigma", "h_out", "c_out"]
PARITY_TOLERANCE = 1e-4


def load_generator(checkpoint: Path) -> tuple[MixtureLSTM, dict, dict]:
    state = torch.load(checkpoint, weights_only=False)
    meta = state["meta"]
    model = MixtureLSTM(meta["dim"], meta["hidden"], meta["mixtures"])
    model.load_state_dict(state["model"])
    return model.eval(), meta, state


GATE_ORDER = [0, 1, 3, 2]  # the graph's gate blocks (i, f, o, g) from PyTorch's (i, f, g, o): one Sigmoid covers i, f, o


def step_graph(model: MixtureLSTM) -> onnx.ModelProto:
    """The generator step written directly as an ONNX graph: x (B, D), h, c (2, B, H) -> weights (B, M),
    mu, sigma (B, M, D), h_out, c_out (2, B, H); the batch dimension is dynamic.

    Each LSTM layer is written out at gate level: gates = Gemm(input, W_ih) + Gemm(h, W_hh, b_ih + b_hh) (the
    second Gemm is the first's C input, so no separate Add or Concat), then one Sigmoid over (i, f, o), one
    Tanh over g, and the cell update. fc1 and fc2 are Gemm + Relu (fused by onnxruntime); fc3 is three
    Gemms (mixture logits, means, log standard deviations), so no output is a slice of a larger tensor.
    Initializers are named after the torch layers; training/recover_generator.py reads them back.
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

    y = node("Relu", [gemm("x", "fc1", sd["fc1.weight"], sd["fc1.bias"], "fc1")], ["fc1_relu"])
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
        rec = gemm(h_rows, f"lstm{layer}_hh", gates(w_hh), gates(b), f"rec{layer}")
        pre = gemm(y, f"lstm{layer}_ih", gates(w_ih), None, f"gates{layer}", c=rec)
        sig_in, tanh_in = node("Split", [pre, gate_split], [f"sig_in{layer}", f"tanh_in{layer}"], axis=1)
        i, f, o = node("Split", [node("Sigmoid", [sig_in], [f"sig{layer}"]), ifo_split], [f"i{layer}", f"f{layer}", f"o{layer}"], axis=1)
        g = node("Tanh", [tanh_in], [f"g{layer}"])
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

    return builder.model("generator_step",
        [("x", ["batch", D]), ("h", [2, "batch", H]), ("c", [2, "batch", H])],
        [("weights", ["batch", M]), ("mu", ["batch", M, D]), ("sigma", ["batch", M, D]),
         ("h_out", [2, "batch", H]), ("c_out", [2, "batch", H])],
        "training.export_generator")


def export_onnx(model: MixtureLSTM, path: Path) -> None:
    onnx.save(step_graph(model.eval()), str(path))


def parity_error(model: MixtureLSTM, path: Path, batches=(1, 7), steps: int = 20, seed: int = 1,
                 state_scale: float = 0.0) -> float:
    """Largest |torch - onnxruntime| / max(1, |torch|) over all outputs: torch (GeneratorStep: nn.LSTM, as
    trained) and onnxruntime side by side for `steps` steps at each batch size, random inputs, states fed
    forward from torch and starting from zero (state_scale 0) or random states of that scale."""
    session = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
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


def estimate_initial_state(model: MixtureLSTM, x: torch.Tensor, iterations: int = 300) -> tuple[torch.Tensor, torch.Tensor, float, float]:
    """Eq. 26: find (h, c) for the first frame that make the following real frames likely.

    x holds a few real normalised frames (time, dim). Returns h, c and the NLL of the frames after the
    first, from a zero state and from the estimated one."""
    h0, c0 = model.zero_state(1)
    h = h0.clone().requires_grad_(True)
    c = c0.clone().requires_grad_(True)
    inputs, targets = x[:-1].unsqueeze(0), x[1:].unsqueeze(0)

    def nll(h_, c_):
        logits, mu, log_sigma, _ = model(inputs, (h_, c_))
        return mixture_nll(logits, mu, log_sigma, targets).mean()

    with torch.no_grad():
        zero_nll = float(nll(h0, c0))
    opt = torch.optim.Adam([h, c], lr=0.05)
    for _ in range(iterations):
        opt.zero_grad()
        loss = nll(h, c)
        loss.backward()
        opt.step()
    with torch.no_grad():
        return h.detach(), c.detach(), zero_nll, float(nll(h, c))


def pick_seeds(clips: list[dict], codec: FeatureCodec, mean: np.ndarray, std: np.ndarray, count_per_category=(6, 2)):
    """Seed frames from held-out and training clips: a spread of walking speeds and some running."""
    seeds = []
    for category, count in zip(("walk", "run"), count_per_category):
        pool = sorted((c for c in clips if c["category"] == category and len(c["root"]) > 12), key=lambda c: c["file"])
        for k in np.linspace(0, len(pool) - 1, count).round().astype(int):
            c = pool[k]
            x = codec.encode(c["root"], c["rotations"], c["contacts"])
            start = len(x) // 3
            seeds.append({"name": f"{category} {c['file'].split('/')[-1].split('.')[0]}", "file": c["file"],
                          "category": category, "frames": ((x[start:start + 6] - mean) / std).astype(np.float32)})
    return seeds


FIXTURE = REPO_ROOT / "tests" / "fixtures" / "generator_reference.json"


def write_reference_fixture(onnx_path: Path, info: dict, codec: FeatureCodec) -> None:
    """Numbers the browser tests compare against: one ONNX step at batch 2 (onnxruntime-web parity) and
    the decoding of a few real feature frames into joint positions (TypeScript decoder parity)."""
    session = ort.InferenceSession(str(onnx_path), providers=["CPUExecutionProvider"])
    hidden = info["onnx"]["hidden"]
    s0, s1 = info["seeds"][0], info["seeds"][-1]
    x = np.array([s0["x"], s1["x"]], np.float32)
    h = np.stack([np.array(s["h"], np.float32).reshape(2, hidden) for s in (s0, s1)], axis=1)
    c = np.stack([np.array(s["c"], np.float32).reshape(2, hidden) for s in (s0, s1)], axis=1)
    outs = session.run(OUTPUTS, {"x": x, "h": h, "c": c})
    mean, std = np.array(info["normalisation"]["mean"]), np.array(info["normalisation"]["std"])
    frames = np.array([s["x"] for s in info["seeds"]]) * std + mean  # physical units, one real frame per seed
    frames[:, 0] += 0.01  # keep the character moving so the decoder's integration is exercised
    positions = codec.positions(frames)
    step = {"inputs": {"x": x.ravel().tolist(), "h": h.ravel().tolist(), "c": c.ravel().tolist(), "batch": 2},
            "outputs": {name: np.asarray(o).ravel().tolist() for name, o in zip(OUTPUTS, outs)}}
    decode = {"features": frames.ravel().tolist(), "frames": len(frames), "positions": positions.ravel().tolist()}
    FIXTURE.write_text(json.dumps({"model": info["file"], "step": step, "decode": decode}) + "\n")
    print(f"wrote {FIXTURE}")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--checkpoint", type=Path, default=RUNS_DIR / "generator" / "best.pt")
    parser.add_argument("--out", type=Path, default=MODELS_DIR)
    parser.add_argument("--mocap", default=None)
    args = parser.parse_args(argv)
    if not args.checkpoint.exists():
        raise SystemExit(f"error: no checkpoint at {args.checkpoint}; train first with python -m training.train_generator")
    model, meta, state = load_generator(args.checkpoint)
    args.out.mkdir(parents=True, exist_ok=True)
    onnx_path = args.out / "generator.onnx"
    export_onnx(model, onnx_path)
    parity = check_parity(model, onnx_path)
    print(f"parity ok: max |torch - onnxruntime| = {parity['max_abs_diff']:.2e}")

    skel = canonical_skeleton()
    codec = FeatureCodec(skel, np.array(meta["references"]))
    mean, std = np.array(meta["mean"]), np.array(meta["std"])
    seeds = []
    for seed in pick_seeds(load_clips(args.mocap), codec, mean, std):
        frames = torch.from_numpy(seed["frames"])
        h, c, zero_nll, est_nll = estimate_initial_state(model, frames)
        seeds.append({"name": seed["name"], "file": seed["file"], "category": seed["category"],
                      "x": [round(float(v), 6) for v in seed["frames"][0]],
                      "h": [round(float(v), 6) for v in h.reshape(-1)], "c": [round(float(v), 6) for v in c.reshape(-1)],
                      "nll_zero_state": round(zero_nll, 3), "nll_estimated_state": round(est_nll, 3)})
        print(f"seed {seed['name']}: NLL of the next frames {zero_nll:.1f} from a zero state, {est_nll:.1f} estimated")
    fixed = [skel.index(n) for n in FIXED_JOINTS]
    info = {
        "id": "generator", "kind": "lstm-gmm", "fps": meta["fps"], "file": "generator.onnx",
        "bytes": onnx_path.stat().st_size,
        "description": "Contact-aware LSTM with a 5-component Gaussian mixture over the next frame (Wang, Chai, Xia §4.1), "
                       "trained on CMU walking and running.",
        "skeleton": skel.to_json(),
        "onnx": {"inputs": INPUTS, "outputs": OUTPUTS, "opset": OPSET, "layers": 2, "hidden": meta["hidden"],
                 "graph": "gate-level LSTM layers (Gemm + gate maths, no LSTM op), fc3 as three Gemms",
                 "mixtures": meta["mixtures"], "dim": meta["dim"]},
        "features": {
            "names": feature_names(skel), "joints": codec.joints, "fixed_joints": fixed,
            "layout": "x = [dtx, dtz, dry, ty, root tilt rotvec(3), joint rotvecs (3 per joint in `joints`), contact L, contact R]; "
                      "dtx/dtz: root step in the previous frame's heading frame (m); dry: heading change (rad, about +y); "
                      "rotvecs are relative to `references` (local rotation = reference * exp(rotvec)); "
                      "references[0] is the root tilt's, references[j] joint j's; fixed joints keep their reference.",
            "references": [[round(float(v), 7) for v in q] for q in matrix_to_quat(codec.references)],
        },
        "normalisation": {"mean": [round(float(v), 7) for v in mean], "std": [round(float(v), 7) for v in std]},
        "seeds": seeds,
        "training": {"epochs": state.get("epoch"), "valid_nll_per_frame": state.get("valid_nll"),
                     "valid_files": meta["valid_files"], "train_frames": meta["train_frames"],
                     "args": meta["args"]},
        "parity": parity,
    }
    (args.out / "generator.json").write_text(json.dumps(info) + "\n")
    if args.out == MODELS_DIR:  # a candidate exported elsewhere must not replace the shipped model's fixture
        write_reference_fixture(onnx_path, info, codec)
        register_model({"id": "generator", "kind": info["kind"], "skeleton": "cmu-canonical", "fps": info["fps"],
                        "bytes": info["bytes"], "file": info["file"]})
    print(f"wrote {onnx_path} ({onnx_path.stat().st_size / 1e6:.2f} MB) and generator.json")


if __name__ == "__main__":
    main()
