"""Exporting the dance models (acLSTM and its vanilla baseline): ONNX step plus JSON, parity checked.

public/models/<id>.onnx is one step: x, style, h, c -> y, h_out, c_out (the batch dimension is dynamic);
<id>.json holds the skeleton, feature layout, normalisation, per-style seed motions (10 real frames each,
from held-out clips), the real per-second pose change per style, training and parity numbers.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import torch

from ..data.dance import STYLES, DanceClip, decode, encode, load_clips, real_pose_change, resample_positions
from ..models.aclstm import DanceLSTM, DanceStep
from ..onnx.manifest import register_model
from ..onnx.sessions import cpu_session
from ..paths import MODELS_DIR, REPO_ROOT


INPUTS, OUTPUTS = ["x", "style", "h", "c"], ["y", "h_out", "c_out"]
PARITY_TOLERANCE = 1e-4
SEED_FRAMES = 10  # the paper's seed length (about 170 ms at 60 fps)
SEEDS_PER_STYLE = 8
FIXTURE = REPO_ROOT / "tests" / "fixtures" / "aclstm_reference.json"


def load_dance_model(checkpoint: Path) -> tuple[DanceLSTM, dict, dict]:
    state = torch.load(checkpoint, weights_only=False)
    meta = state["meta"]
    model = DanceLSTM(meta["dim"], len(meta["styles"]), meta["hidden"], meta["layers"])
    model.load_state_dict(state["model"])
    return model.eval(), meta, state


def export_onnx(model: DanceLSTM, path: Path) -> None:
    step = DanceStep(model).eval()
    x, style = torch.zeros(1, model.dim), torch.zeros(1, model.styles)
    h, c = model.zero_state(1)
    b = {0: "batch"}
    torch.onnx.export(step, (x, style, h, c), str(path), input_names=INPUTS, output_names=OUTPUTS, opset_version=17,
                      dynamo=False, dynamic_axes={"x": b, "style": b, "h": {1: "batch"}, "c": {1: "batch"}, "y": b,
                                                  "h_out": {1: "batch"}, "c_out": {1: "batch"}})


def check_parity(model: DanceLSTM, path: Path, steps: int = 20) -> dict:
    """torch against onnxruntime for several steps at batch 1 and 5, feeding outputs and states back."""
    session = cpu_session(path)
    step = DanceStep(model).eval()
    rng = np.random.default_rng(1)
    worst = 0.0
    for batch in (1, 5):
        x = rng.normal(size=(batch, model.dim)).astype(np.float32)
        style = np.eye(model.styles, dtype=np.float32)[rng.integers(0, model.styles, batch)]
        h, c = (s.numpy() for s in model.zero_state(batch))
        for _ in range(steps):
            with torch.no_grad():
                ref = [t.numpy() for t in step(*(torch.from_numpy(a) for a in (x, style, h, c)))]
            got = session.run(OUTPUTS, {"x": x, "style": style, "h": h, "c": c})
            worst = max(worst, max(float(np.abs(a - b).max()) for a, b in zip(ref, got)))
            x, h, c = ref
    if worst > PARITY_TOLERANCE:
        raise SystemExit(f"error: ONNX parity failed, max |torch - onnxruntime| = {worst:.2e} > {PARITY_TOLERANCE:.0e}")
    return {"max_abs_diff": worst, "tolerance": PARITY_TOLERANCE, "batches": [1, 5], "steps": steps}


def pick_seeds(clips: list[DanceClip]) -> list[dict]:
    """SEEDS_PER_STYLE windows of SEED_FRAMES real feature frames per style, spread over the held-out clips."""
    seeds = []
    for style in STYLES:
        held = [c for c in clips if c.style == style and c.held_out]
        for k in range(SEEDS_PER_STYLE):
            c = held[k % len(held)]
            secs = c.seconds
            start = (k // len(held) + 1) / (SEEDS_PER_STYLE // len(held) + 2) * secs
            pos = resample_positions(c.positions, c.fps, start, SEED_FRAMES + 1)
            pos[..., [0, 2]] -= pos[-1:, :1, [0, 2]]  # the seed ends with the root over the origin
            seeds.append({"style": style, "name": f"{style} {Path(c.file).name.split('.')[0]} @{start:.1f}s",
                          "file": c.file, "start_seconds": round(start, 2),
                          "frames": [[round(float(v), 5) for v in f] for f in encode(pos)]})
    return seeds


def write_reference_fixture(onnx_path: Path, info: dict) -> None:
    """One ONNX step at batch 2 (onnxruntime-web parity) and a decoded seed (TypeScript decoder parity)."""
    session = cpu_session(onnx_path)
    mean, std = np.array(info["normalisation"]["mean"]), np.array(info["normalisation"]["std"])
    seeds = [info["seeds"][0], info["seeds"][-1]]
    x = np.array([(np.array(s["frames"][-1]) - mean) / std for s in seeds], np.float32)
    style = np.eye(len(STYLES), dtype=np.float32)[[STYLES.index(s["style"]) for s in seeds]]
    rng = np.random.default_rng(3)
    shape = (info["onnx"]["layers"], 2, info["onnx"]["hidden"])
    h, c = (rng.normal(scale=0.3, size=shape).astype(np.float32) for _ in range(2))
    outs = session.run(OUTPUTS, {"x": x, "style": style, "h": h, "c": c})
    feats = np.array(seeds[0]["frames"])
    step = {"inputs": {"x": x.ravel().tolist(), "style": style.ravel().tolist(), "h": h.ravel().tolist(),
                       "c": c.ravel().tolist(), "batch": 2},
            "outputs": {n: np.asarray(o).ravel().tolist() for n, o in zip(OUTPUTS, outs)}}
    decoded = {"features": feats.ravel().tolist(), "frames": len(feats), "positions": decode(feats).ravel().tolist()}
    FIXTURE.write_text(json.dumps({"model": info["file"], "step": step, "decode": decoded}) + "\n")
    print(f"wrote {FIXTURE}")


def training_minutes(checkpoint: Path, iteration: int | None) -> float | None:
    """Training time (minutes) up to `iteration`, from the run's latest checkpoint history."""
    latest = checkpoint.parent / "checkpoint.pt"
    if not latest.exists() or iteration is None:
        return None
    history = torch.load(latest, weights_only=False).get("history", [])
    upto = [h["minutes"] for h in history if h["iteration"] <= iteration]
    return round(upto[-1], 1) if upto else None


def export_dance_model(checkpoint: Path, model_id: str, out: Path, mocap: str | None) -> Path:
    """Writes out/<model_id>.onnx (parity checked) and out/<model_id>.json; into MODELS_DIR also the manifest
    entry and, for the auto-conditioned model, the browser fixture. Returns the ONNX path."""
    model, meta, state = load_dance_model(checkpoint)
    out.mkdir(parents=True, exist_ok=True)
    onnx_path = out / f"{model_id}.onnx"
    export_onnx(model, onnx_path)
    parity = check_parity(model, onnx_path)
    print(f"parity ok: max |torch - onnxruntime| = {parity['max_abs_diff']:.2e}")
    _, clips = load_clips(mocap)
    vanilla = meta["args"]["condition"] == 0
    info = {
        "id": model_id, "kind": "aclstm", "fps": meta["fps"], "file": onnx_path.name, "bytes": onnx_path.stat().st_size,
        "description": ("Vanilla 3-layer LSTM trained with teacher forcing only (the acLSTM paper's baseline)" if vanilla else
                        "Auto-conditioned LSTM (Zhou et al.), u = v = 5") + ", one model for salsa, Indian and martial-arts dance.",
        "training_scheme": "teacher-forced" if vanilla else "auto-conditioned",
        "styles": meta["styles"],
        "skeleton": meta["skeleton"],
        "features": {"dim": meta["dim"], "seed_frames": SEED_FRAMES,
                     "layout": "x = [root dx (m/frame), root height y (m), root dz (m/frame), then for each skeleton point "
                               "after the root: its position minus the root's (m, world axes)]; y up, " f"{meta['fps']:g} fps"},
        "onnx": {"inputs": INPUTS, "outputs": OUTPUTS, "opset": 17, "layers": meta["layers"], "hidden": meta["hidden"],
                 "dim": meta["dim"], "styles": len(meta["styles"]),
                 "style_input": "one-hot over `styles`; x and y are normalised features"},
        "normalisation": {"mean": [round(float(v), 7) for v in meta["mean"]], "std": [round(float(v), 7) for v in meta["std"]]},
        "real_pose_change": real_pose_change(clips),
        "seeds": pick_seeds(clips),
        "training": {"iterations": state.get("iteration"), "minutes": training_minutes(checkpoint, state.get("iteration")),
                     "valid": state.get("valid"), "valid_files": meta["valid_files"], "args": meta["args"]},
        "parity": parity,
    }
    (out / f"{model_id}.json").write_text(json.dumps(info) + "\n")
    if not vanilla and out == MODELS_DIR:
        write_reference_fixture(onnx_path, info)
    if out == MODELS_DIR:
        register_model({"id": model_id, "kind": "aclstm", "skeleton": "aclstm-standard", "fps": info["fps"],
                        "styles": info["styles"], "bytes": info["bytes"], "file": info["file"]})
    return onnx_path
