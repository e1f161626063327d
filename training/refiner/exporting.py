"""Exporting a trained refiner: public/models/refiner.onnx (graph.py) and refiner.json with its cost against the
generator, the manifest entry, tests/fixtures/refiner_reference.json (two calls at batch 2, for the browser's
parity test and its end-effector computation), and rebuilding a torch checkpoint from the shipped export."""
from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import torch

from ..footlock import BLEND_IN, BLEND_OUT, REACH, TOE_GROUND_HEIGHT
from ..models.refiner import Refiner
from ..onnx.graph import OPSET
from ..onnx.manifest import register_model
from ..onnx.sessions import cpu_session
from ..paths import DEFAULT_CACHE, MODELS_DIR, REPO_ROOT
from .graph import INPUTS, OUTPUTS, PARITY_TOLERANCE, export_onnx, parity_error, refiner_from_onnx, step_parity, stream_inputs
from .training import load_refiner

FIXTURE = REPO_ROOT / "tests" / "fixtures" / "refiner_reference.json"


def time_steps(path: Path, batch: int, inputs_fn, repeats: int = 3000) -> float:
    """Median over 5 runs of the mean ms per session.run at one thread."""
    session = cpu_session(path, threads=1)
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
    session = cpu_session(path)
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
    a, b = (cpu_session(p) for p in (onnx_path, tmp))
    feed = {"x": rng.normal(size=(5, 4, model.dim)).astype(np.float32), "ends": rng.normal(size=(5, 4, 3 * model.ends)).astype(np.float32),
            "ends_prev": rng.normal(size=(5, 3 * model.ends)).astype(np.float32),
            "h": rng.normal(size=(1, 5, model.hidden)).astype(np.float32), "c": rng.normal(size=(1, 5, model.hidden)).astype(np.float32)}
    diff = max(float(np.abs(u - v).max()) for u, v in zip(a.run(OUTPUTS, feed), b.run(OUTPUTS, feed)))
    tmp.unlink()
    return diff


def export_refiner(checkpoint: Path, out: Path) -> Path:
    """Writes out/refiner.onnx (parity checked against torch) and out/refiner.json (end-effector conventions,
    foot-lock settings, training, parity and cost numbers); into MODELS_DIR also the fixture and the manifest
    entry. Returns the ONNX path."""
    model, meta, state = load_refiner(checkpoint)
    gen_info = json.loads((MODELS_DIR / "generator.json").read_text())
    if np.abs(np.array(gen_info["normalisation"]["mean"]) - np.array(meta["mean"])).max() > 1e-4:
        raise SystemExit("error: the refiner was trained with a different normalisation than the shipped generator's")
    out.mkdir(parents=True, exist_ok=True)
    onnx_path = out / "refiner.onnx"
    export_onnx(model, onnx_path)

    # Parity on generator-like frames: the validation streams cached by refiner training when present, else noise.
    cached = sorted(DEFAULT_CACHE.glob("refiner_generated_*_s101.npz"))
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
                     "checkpoint": str(checkpoint.relative_to(REPO_ROOT)) if checkpoint.is_relative_to(REPO_ROOT) else str(checkpoint)},
        "parity": {"max_abs_diff": worst, "step_max_abs_diff": worst_step, "measure": "|a - b| / max(1, |a|)",
                   "tolerance": PARITY_TOLERANCE, "batches": [1, 7], "steps": frames.shape[1] - 1,
                   "calls": "all frames in one call, one frame per call, and calls of 7 frames",
                   "reference": "torch full-sequence forward (nn.LSTM, torch FK) and torch RefinerStep"},
        "cost": cost,
    }
    (out / "refiner.json").write_text(json.dumps(info) + "\n")
    if out == MODELS_DIR:
        write_fixture(model, onnx_path, frames, info)
        register_model({"id": "refiner", "kind": "refiner", "skeleton": "cmu-canonical", "fps": info["fps"],
                        "bytes": info["bytes"], "file": info["file"]}, "cmu-locomotion")
    return onnx_path
