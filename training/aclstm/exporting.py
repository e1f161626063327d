"""Exporting the dance models (acLSTM and its vanilla baseline): ONNX step plus JSON, parity checked.

public/models/<id>.onnx runs K steps in one call: x, style, h, c, steps -> ys (steps frames), h_out, c_out (the batch
dimension is dynamic; training/aclstm/graph.py); its large weights are stored as int8 by default (or float16/float32: --weights; training/onnx/compact.py).
<id>.json holds the skeleton, feature layout, normalisation, per-style seed motions (10 real frames each,
from held-out clips), the real per-second pose change per style, training and parity numbers.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import onnx
import torch

from ..data.dance import STYLES, DanceClip, decode, encode, load_clips, real_pose_change, resample_positions
from ..models.aclstm import DanceLSTM
from ..onnx.compact import compact_weights, weight_format
from ..onnx.manifest import register_model
from ..onnx.sessions import cpu_session
from ..paths import MODELS_DIR, REPO_ROOT
from .graph import OUTPUTS, check_parity, dance_graph, dance_model_from_onnx, graph_inputs

SEED_FRAMES = 10  # the paper's seed length (about 170 ms at 60 fps)
SEEDS_PER_STYLE = 8
FIXTURE = REPO_ROOT / "tests" / "fixtures" / "aclstm_reference.json"


def load_dance_model(checkpoint: Path) -> tuple[DanceLSTM, dict, dict]:
    state = torch.load(checkpoint, weights_only=False)
    meta = state["meta"]
    model = DanceLSTM(meta["dim"], len(meta["styles"]), meta["hidden"], meta["layers"], meta.get("head", "mean"),
                       meta.get("components", 10))
    model.load_state_dict(state["model"])
    return model.eval(), meta, state


def export_onnx(model: DanceLSTM, path: Path, weights: str = "float32") -> DanceLSTM:
    """Writes the step graph with its large weights stored as `weights`; returns the network the file computes
    (the weights as stored), the reference for the parity check."""
    onnx.save(compact_weights(dance_graph(model), weights), str(path))
    return dance_model_from_onnx(path, model.dim, model.styles, model.hidden, model.layers)


def pick_seeds(clips: list[DanceClip], styles: tuple[str, ...] | list[str] = STYLES) -> list[dict]:
    """SEEDS_PER_STYLE windows of SEED_FRAMES real feature frames per style, spread over the held-out clips."""
    seeds = []
    for style in styles:
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


FIXTURE_STEPS = 24


def write_reference_fixture(onnx_path: Path, info: dict) -> None:
    """ONNX calls at batch 2 for onnxruntime-web parity, one step and FIXTURE_STEPS steps from the same inputs, and a
    decoded seed (TypeScript decoder parity)."""
    session = cpu_session(onnx_path)
    mean, std = np.array(info["normalisation"]["mean"]), np.array(info["normalisation"]["std"])
    seeds = [info["seeds"][0], info["seeds"][-1]]
    x = np.array([(np.array(s["frames"][-1]) - mean) / std for s in seeds], np.float32)
    style = np.eye(len(STYLES), dtype=np.float32)[[STYLES.index(s["style"]) for s in seeds]]
    rng = np.random.default_rng(3)
    shape = (info["onnx"]["layers"], 2, info["onnx"]["hidden"])
    h, c = (rng.normal(scale=0.3, size=shape).astype(np.float32) for _ in range(2))
    inputs = {"x": x.ravel().tolist(), "style": style.ravel().tolist(), "h": h.ravel().tolist(), "c": c.ravel().tolist(), "batch": 2}
    gauss = "noise" in info["onnx"]["inputs"]
    noise = rng.normal(size=(FIXTURE_STEPS, 2, x.shape[1])).astype(np.float32)
    temperature = np.array([info.get("temperature", 1.0)], np.float32)

    def case(steps: int) -> dict:
        drawn = {"noise": noise[:steps], "temperature": temperature} if gauss else {}
        outs = session.run(OUTPUTS, {"x": x, "style": style, "h": h, "c": c, "steps": np.array([steps], np.int64), **drawn})
        listed = {"noise": noise[:steps].ravel().tolist(), "temperature": float(temperature[0])} if gauss else {}
        return {"inputs": {**inputs, "steps": steps, **listed}, "outputs": {n: np.asarray(o).ravel().tolist() for n, o in zip(OUTPUTS, outs)}}

    feats = np.array(seeds[0]["frames"])
    decoded = {"features": feats.ravel().tolist(), "frames": len(feats), "positions": decode(feats).ravel().tolist()}
    FIXTURE.write_text(json.dumps({"model": info["file"], "step": case(1), "steps": case(FIXTURE_STEPS), "decode": decoded}) + "\n")
    print(f"wrote {FIXTURE}")


def training_history(checkpoint: Path, iteration: int | None) -> dict:
    """The run's last history entry up to `iteration` (its minutes and validation), from its latest checkpoint."""
    latest = checkpoint.parent / "checkpoint.pt"
    if not latest.exists() or iteration is None:
        return {}
    upto = [h for h in torch.load(latest, weights_only=False).get("history", []) if h["iteration"] <= iteration]
    return upto[-1] if upto else {}


def training_minutes(checkpoint: Path, iteration: int | None) -> float | None:
    """Training time (minutes) up to `iteration`, from the run's latest checkpoint history."""
    minutes = training_history(checkpoint, iteration).get("minutes")
    return None if minutes is None else round(minutes, 1)


def write_dance_graph(model: DanceLSTM, onnx_path: Path, weights: str) -> tuple[dict, dict]:
    """Writes and parity-checks the graph; returns the JSON's `onnx` and `parity` fields."""
    stored = export_onnx(model, onnx_path, weights)
    parity = {**check_parity(stored, onnx_path), "reference": f"torch with the weights as stored ({weights})"}
    print(f"parity ok: max |torch - onnxruntime| = {parity['max_abs_diff']:.2e}")
    fields = {"inputs": graph_inputs(model), "outputs": OUTPUTS, "opset": 17, "layers": model.layers, "hidden": model.hidden,
              "dim": model.dim, "styles": model.styles, "head": model.head, "weights": weight_format(onnx.load(str(onnx_path))),
              "style_input": "one-hot over `styles`; x and ys are normalised features",
              "steps_input": "int64 (1,): steps run in the call, each output frame fed back as the next input; "
                             "ys is (steps, batch, dim)"}
    if model.head == "gauss":
        fields["noise_input"] = ("float32 (>= steps, batch, dim) standard normals, one row per step: each frame is "
                                 "mu + temperature * sigma * noise[step], the network's Gaussian draw")
        fields["temperature_input"] = "float32 (1,): scales sigma (0: the mean)"
    return fields, parity


def _publish(info: dict, onnx_path: Path, model_id: str, out: Path) -> None:
    """The JSON beside the graph; into MODELS_DIR also the manifest entry and, for the auto-conditioned model, the
    browser fixture."""
    info["bytes"] = onnx_path.stat().st_size
    (out / f"{model_id}.json").write_text(json.dumps(info) + "\n")
    if info["training_scheme"] == "auto-conditioned" and out == MODELS_DIR:
        write_reference_fixture(onnx_path, info)
    if out == MODELS_DIR:
        register_model({"id": model_id, "kind": "aclstm", "skeleton": "aclstm-standard", "fps": info["fps"],
                        "styles": info["styles"], "bytes": info["bytes"], "file": info["file"]}, "aclstm-dance")


def export_dance_model(checkpoint: Path, model_id: str, out: Path, mocap: str | None, weights: str = "int8",
                       temperature: float = 0.2) -> Path:
    """Writes out/<model_id>.onnx (parity checked) and out/<model_id>.json (see _publish). Returns the ONNX path.
    `temperature`: a Gaussian head's sampling temperature, kept in the JSON for the page and the evaluation."""
    model, meta, state = load_dance_model(checkpoint)
    out.mkdir(parents=True, exist_ok=True)
    onnx_path = out / f"{model_id}.onnx"
    onnx_fields, parity = write_dance_graph(model, onnx_path, weights)
    _, clips = load_clips(mocap)
    vanilla = meta["args"]["condition"] == 0
    info = {
        "id": model_id, "kind": "aclstm", "fps": meta["fps"], "file": onnx_path.name,
        "description": ("Vanilla 3-layer LSTM trained with teacher forcing only (the acLSTM paper's baseline)" if vanilla else
                        "Auto-conditioned LSTM (Zhou et al.), u = v = 5")
                       + (f", Gaussian output head drawn at temperature {temperature:g} and fed back" if model.head == "gauss" else "")
                       + ", one model for salsa, Indian and martial-arts dance.",
        "training_scheme": "teacher-forced" if vanilla else "auto-conditioned",
        **({"temperature": temperature} if model.head == "gauss" else {}),
        "styles": meta["styles"],
        "skeleton": meta["skeleton"],
        "features": {"dim": meta["dim"], "seed_frames": SEED_FRAMES,
                     "layout": "x = [root dx (m/frame), root height y (m), root dz (m/frame), then for each skeleton point "
                               "after the root: its position minus the root's (m, world axes)]; y up, " f"{meta['fps']:g} fps"},
        "onnx": onnx_fields,
        "normalisation": {"mean": [round(float(v), 7) for v in meta["mean"]], "std": [round(float(v), 7) for v in meta["std"]]},
        "real_pose_change": real_pose_change(clips),
        "seeds": pick_seeds(clips),
        "training": {"iterations": state.get("iteration"), "minutes": training_minutes(checkpoint, state.get("iteration")),
                     # last.pt keeps no validation: the last one measured before it (up to 250 iterations earlier)
                     "valid": state.get("valid") or training_history(checkpoint, state.get("iteration")).get("valid"),
                     "valid_files": meta["valid_files"], "args": meta["args"]},
        "parity": parity,
    }
    _publish(info, onnx_path, model_id, out)
    return onnx_path


def rewrite_dance_model(source: Path, model_id: str, out: Path, weights: str) -> Path:
    """The exported model `source`/<model_id>.{json,onnx} written again with this graph and weight format, without
    its checkpoint: the network is read back from the ONNX file, everything else of the JSON is kept."""
    info = json.loads((source / f"{model_id}.json").read_text())
    o = info["onnx"]
    model = dance_model_from_onnx(source / info["file"], o["dim"], o["styles"], o["hidden"], o["layers"])
    out.mkdir(parents=True, exist_ok=True)
    onnx_path = out / f"{model_id}.onnx"
    info["onnx"], info["parity"] = write_dance_graph(model, onnx_path, weights)
    info["file"] = onnx_path.name
    _publish(info, onnx_path, model_id, out)
    return onnx_path
