"""Exporting a trained generator: the ONNX step (graph.py), generator.json with seed states estimated as in
eq. 26, the manifest entry, and tests/fixtures/generator_reference.json for the browser's parity tests."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import onnx
import torch

from ..data.features import FIXED_JOINTS, FeatureCodec, feature_names
from ..data.locomotion import LocomotionClip, load_clips
from ..mocap.rotations import matrix_to_quat, quat_to_matrix
from ..mocap.skeleton import canonical_skeleton
from ..models.generator import MixtureLSTM, mixture_nll
from ..onnx.compact import weight_format
from ..onnx.graph import OPSET
from ..onnx.manifest import register_model
from ..onnx.sessions import cpu_session
from ..paths import MODELS_DIR, REPO_ROOT
from .graph import INPUTS, OUTPUTS, check_parity, export_onnx
from .recovery import model_from_onnx
from .sampling import NOISE_CORRELATION
from .shipped import seed_batch
from .training import load_generator

FIXTURE = REPO_ROOT / "tests" / "fixtures" / "generator_reference.json"


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
    # The best state seen is kept: on some models the steps overshoot and end worse than they started (the style
    # generator's Bandai seeds went from -60 to -13 nats), and a state worse than the zero state is never returned.
    best = (zero_nll, h0.clone(), c0.clone())
    for _ in range(iterations):
        opt.zero_grad()
        loss = nll(h, c)
        if loss.item() < best[0]:
            best = (loss.item(), h.detach().clone(), c.detach().clone())
        loss.backward()
        opt.step()
    with torch.no_grad():
        last = float(nll(h, c))
        if last < best[0]:
            best = (last, h.detach().clone(), c.detach().clone())
    return best[1], best[2], zero_nll, best[0]


def pick_seeds(clips: list[LocomotionClip], codec: FeatureCodec, mean: np.ndarray, std: np.ndarray,
               count_per_category=(6, 2)) -> list[dict]:
    """Seed frames from held-out and training clips: a spread of walking speeds and some running."""
    seeds = []
    for category, count in zip(("walk", "run"), count_per_category):
        pool = sorted((c for c in clips if c.category == category and len(c.root) > 12), key=lambda c: c.file)
        for k in np.linspace(0, len(pool) - 1, count).round().astype(int):
            c = pool[k]
            x = codec.encode(c.root, c.rotations, c.contacts)
            start = len(x) // 3
            seeds.append({"name": f"{category} {c.file.split('/')[-1].split('.')[0]}", "file": c.file,
                          "category": category, "frames": ((x[start:start + 6] - mean) / std).astype(np.float32)})
    return seeds


def estimated_seeds(model: MixtureLSTM, clips: list[LocomotionClip], codec: FeatureCodec, mean: np.ndarray,
                    std: np.ndarray) -> list[dict]:
    """generator.json's seeds: pick_seeds with their first frame and estimated (h, c), rounded."""
    seeds = []
    for seed in pick_seeds(clips, codec, mean, std):
        frames = torch.from_numpy(seed["frames"])
        h, c, zero_nll, est_nll = estimate_initial_state(model, frames)
        seeds.append({"name": seed["name"], "file": seed["file"], "category": seed["category"],
                      "x": [round(float(v), 6) for v in seed["frames"][0]],
                      "h": [round(float(v), 6) for v in h.reshape(-1)], "c": [round(float(v), 6) for v in c.reshape(-1)],
                      "nll_zero_state": round(zero_nll, 3), "nll_estimated_state": round(est_nll, 3)})
        print(f"seed {seed['name']}: NLL of the next frames {zero_nll:.1f} from a zero state, {est_nll:.1f} estimated")
    return seeds


def write_reference_fixture(onnx_path: Path, info: dict, codec: FeatureCodec) -> None:
    """Numbers the browser tests compare against: one ONNX step at batch 2 (onnxruntime-web parity) and
    the decoding of a few real feature frames into joint positions (TypeScript decoder parity)."""
    session = cpu_session(onnx_path)
    x, h, c = seed_batch(info, [0, len(info["seeds"]) - 1])  # the first and the last seed state
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


def _write_graph(model: MixtureLSTM, onnx_path: Path, weights: str) -> dict:
    """Writes the step graph with its weights stored as `weights` and checks it against torch holding the weights
    as stored (read back from the file); returns the JSON's parity field."""
    export_onnx(model, onnx_path, weights)
    stored = model_from_onnx(onnx_path, model.dim, model.hidden, model.mixtures)
    parity = {**check_parity(stored, onnx_path), "reference": f"torch with the weights as stored ({weights})"}
    print(f"parity ok: max |torch - onnxruntime| = {parity['max_abs_diff']:.2e}")
    return parity


def rewrite_generator(source: Path, out: Path, weights: str) -> Path:
    """The export in `source` (generator.onnx and .json) written again with its weights stored as `weights`,
    without the checkpoint: the network is read back from the file; seeds and the rest of the JSON are kept."""
    info = json.loads((source / "generator.json").read_text())
    o = info["onnx"]
    model = model_from_onnx(source / info["file"], o["dim"], o["hidden"], o["mixtures"])
    out.mkdir(parents=True, exist_ok=True)
    onnx_path = out / "generator.onnx"
    info["parity"] = _write_graph(model, onnx_path, weights)
    info["bytes"] = onnx_path.stat().st_size
    info["weights"] = weight_format(onnx.load(str(onnx_path)))
    (out / "generator.json").write_text(json.dumps(info) + "\n")
    if out == MODELS_DIR:
        codec = FeatureCodec(canonical_skeleton(), quat_to_matrix(np.array(info["features"]["references"], np.float64)))
        write_reference_fixture(onnx_path, info, codec)
        register_model({"id": "generator", "kind": info["kind"], "skeleton": "cmu-canonical", "fps": info["fps"],
                        "bytes": info["bytes"], "file": info["file"]}, "cmu-locomotion")
    return onnx_path


def sampling_info() -> dict:
    """generator.json's "sampling": how the page draws from the mixture (training/generator/sampling.py)."""
    return {"noise_correlation": NOISE_CORRELATION,
            "rule": "per frame and row: one uniform picks the component (weights^(1/temperature)), then dim fresh normals n; "
                    "z = noise_correlation * z_previous + sqrt(1 - noise_correlation^2) * n (z = n on a stream's first frame); "
                    "x = mu + sigma * temperature * z"}


def export_generator(checkpoint: Path, out: Path, mocap: str | None, weights: str = "int8") -> Path:
    """Writes out/generator.onnx and out/generator.json (skeleton, feature layout, normalisation, rotation
    references, seed states, training and parity numbers); into MODELS_DIR also the fixture and the manifest
    entry. Returns the ONNX path."""
    model, meta, state = load_generator(checkpoint)
    out.mkdir(parents=True, exist_ok=True)
    onnx_path = out / "generator.onnx"
    parity = _write_graph(model, onnx_path, weights)

    skel = canonical_skeleton()
    codec = FeatureCodec(skel, np.array(meta["references"]))
    mean, std = np.array(meta["mean"]), np.array(meta["std"])
    seeds = estimated_seeds(model, load_clips(mocap), codec, mean, std)
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
        "sampling": sampling_info(),
        "training": {"epochs": state.get("epoch"), "valid_nll_per_frame": state.get("valid_nll"),
                     "valid_files": meta["valid_files"], "train_frames": meta["train_frames"],
                     "args": meta["args"]},
        "parity": parity,
        "weights": weight_format(onnx.load(str(onnx_path))),
    }
    (out / "generator.json").write_text(json.dumps(info) + "\n")
    if out == MODELS_DIR:  # a candidate exported elsewhere must not replace the shipped model's fixture
        write_reference_fixture(onnx_path, info, codec)
        register_model({"id": "generator", "kind": info["kind"], "skeleton": "cmu-canonical", "fps": info["fps"],
                        "bytes": info["bytes"], "file": info["file"]}, "cmu-locomotion")
    return onnx_path
