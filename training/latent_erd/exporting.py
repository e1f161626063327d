"""Exporting the latent ERD: the ONNX step, latent-erd.json with seeds, the manifest entry, and
tests/fixtures/latent_erd_reference.json for the browser's parity tests.

latent-erd.onnx is one step: z (batch, latent) normalised, control (batch, 12) normalised, h and c
(layers, batch, hidden) -> z_next, h_out, c_out. The batch dimension is dynamic.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import torch
from torch import nn

from ..autoencoder.exporting import RADIUS
from ..data.windows import CONTROL_SLICE, WindowCorpus
from ..models.autoencoder import POOLING, MotionAutoencoder
from ..models.erd import ControlERD
from ..onnx.manifest import register_model
from ..onnx.sessions import cpu_session
from ..paths import MODELS_DIR, REPO_ROOT
from .sequences import encode_clip, step_control
from .streaming import LOOKAHEAD, LatentStream, Normalisation, OnnxBackend, run_stream

INPUTS, OUTPUTS = ["z", "control", "h", "c"], ["z_next", "h_out", "c_out"]
PARITY_TOLERANCE = 1e-4
# Real latent steps a stream is warmed up on: 8 steps, 32 frames (1.07 s). With the thesis's shortest seed, 4 steps,
# one of the five 10,000-frame random-control runs in the page sank into a crouch 3 s after its seed (walk 35_13)
# and spent 2 s below the freeze line; warmed up on 8 steps none of them has such a second, and running paths
# follow better (the report's prediction tables keep their own 16-frame seeds).
SEED_STEPS = 8
FIXTURE = REPO_ROOT / "tests" / "fixtures" / "latent_erd_reference.json"


class ERDStep(nn.Module):
    def __init__(self, erd: ControlERD):
        super().__init__()
        self.erd = erd

    def forward(self, z, control, h, c):
        y, (h2, c2) = self.erd(z[:, None], control[:, None], (h, c))
        return y[:, 0], h2, c2


def export_step(erd: ControlERD, path: Path) -> None:
    z, control = torch.zeros(1, erd.dim), torch.zeros(1, erd.control)
    h, c = erd.zero_state(1)
    b, s = {0: "batch"}, {1: "batch"}
    torch.onnx.export(ERDStep(erd).eval(), (z, control, h, c), str(path), input_names=INPUTS, output_names=OUTPUTS,
                      opset_version=17, dynamo=False,
                      dynamic_axes={"z": b, "control": b, "h": s, "c": s, "z_next": b, "h_out": s, "c_out": s})


def check_parity(erd: ControlERD, path: Path, steps: int = 20) -> float:
    """torch against onnxruntime for `steps` steps at batch 1 and 4, outputs and states fed back."""
    session, step = cpu_session(path), ERDStep(erd).eval()
    rng = np.random.default_rng(1)
    worst = 0.0
    for batch in (1, 4):
        z = rng.normal(size=(batch, erd.dim)).astype(np.float32)
        h, c = (t.numpy() for t in erd.zero_state(batch))
        for _ in range(steps):
            control = rng.normal(size=(batch, erd.control)).astype(np.float32)
            with torch.no_grad():
                ref = [t.numpy() for t in step(*(torch.from_numpy(a) for a in (z, control, h, c)))]
            got = session.run(OUTPUTS, {"z": z, "control": control, "h": h, "c": c})
            worst = max(worst, max(float(np.abs(a - b).max()) for a, b in zip(ref, got)))
            z, h, c = ref
    if worst > PARITY_TOLERANCE:
        raise SystemExit(f"error: latent ERD parity {worst:.2e} exceeds {PARITY_TOLERANCE}")
    return worst


def pick_seeds(corpus: WindowCorpus, autoencoder: MotionAutoencoder, norm: Normalisation, control_sigma: float,
               per_category=(6, 2)) -> list[dict]:
    """SEED_STEPS real latent steps from held-out clips: a spread of walks and some runs, a third of the way in (or
    as far in as the clip allows), with their control as the ERD reads it (smoothed over `control_sigma` frames)."""
    seeds = []
    for category, count in zip(("walk", "run"), per_category):
        pool = sorted((i for i, c in enumerate(corpus.valid_clips) if c.category == category and len(c.rows) >= POOLING * (SEED_STEPS + 1)),
                      key=lambda i: corpus.valid_clips[i].file)
        for k in np.linspace(0, len(pool) - 1, count).round().astype(int):
            i = pool[k]
            rows = corpus.valid[i]
            z = encode_clip(autoencoder, rows)
            start = min(len(z) // 3, len(z) - SEED_STEPS)
            latents = (z[start:start + SEED_STEPS] - norm.latent_mean) / norm.latent_std
            controls = step_control(rows, len(z), control_sigma)[start:start + SEED_STEPS]
            clip = corpus.valid_clips[i]
            seeds.append({"name": f"{category} {clip.file.split('/')[-1].split('.')[0]}", "file": clip.file, "category": category,
                          "latents": np.round(latents, 6).tolist(), "controls": np.round(controls, 6).tolist()})
    return seeds


def control_range(corpus: WindowCorpus) -> dict:
    allc = np.concatenate([c.rows[:, CONTROL_SLICE] for c in corpus.train_clips])
    lo, hi = np.percentile(allc, 1, axis=0), np.percentile(allc, 99, axis=0)
    return {name: [round(float(a), 3), round(float(b), 3)] for name, a, b in zip(("forward", "sideways", "turn"), lo, hi)}


def stream_for(backend, info: dict, norm: Normalisation, seed: int) -> LatentStream:
    s = info["seeds"][seed]
    return LatentStream(backend, norm, np.array(s["latents"], np.float32), np.array(s["controls"], np.float32),
                        (info["layers"], info["hidden"]), info["fps"], info["lookahead"])


def fixture_control(frames: int = 48) -> np.ndarray:
    """Walk forward, then turn left and speed up: a control that exercises the root integration."""
    t = np.arange(frames) / 30.0
    return np.stack([1.0 + 0.5 * (t > 0.8), 0.05 * np.sin(3 * t), 1.2 * (t > 0.5)], axis=1)


def write_reference_fixture(erd_path: Path, decoder_path: Path, info: dict, norm: Normalisation) -> None:
    """One ERD step at batch 2, one decoder window, and a whole stream (seed 0, fixture_control) from
    onnxruntime: the browser runs the same and compares."""
    backend = OnnxBackend(erd_path, decoder_path)
    rng = np.random.default_rng(3)
    z = np.array([s["latents"][-1] for s in info["seeds"][:2]], np.float32)
    control = rng.normal(size=(2, 12)).astype(np.float32)
    h = rng.normal(scale=0.1, size=(info["layers"], 2, info["hidden"])).astype(np.float32)
    c = rng.normal(scale=0.1, size=(info["layers"], 2, info["hidden"])).astype(np.float32)
    z2, h2, c2 = backend.step(z, control, h, c)
    window = (np.repeat(z[:1], 2 * RADIUS + 1, 0) * norm.latent_std + norm.latent_mean)[None].astype(np.float32)
    rows = backend.decode(window)
    controls = fixture_control()
    out = run_stream(stream_for(backend, info, norm, 0), controls, known_future=False)
    data = {"model": info["file"],
            "step": {"inputs": {"z": z.ravel().tolist(), "control": control.ravel().tolist(), "h": h.ravel().tolist(),
                                "c": c.ravel().tolist(), "batch": 2},
                     "outputs": {"z_next": z2.ravel().tolist(), "h_out": h2.ravel().tolist(), "c_out": c2.ravel().tolist()}},
            "decode": {"latent": window.ravel().tolist(), "steps": 2 * RADIUS + 1, "rows": rows.ravel().tolist()},
            "stream": {"seed": 0, "lookahead": info["lookahead"], "control": controls.ravel().tolist(), "frames": len(controls),
                       "rows": out.rows.ravel().tolist(), "positions": out.positions.ravel().tolist(),
                       "roots": out.roots.ravel().tolist(), "contacts": out.contacts.ravel().tolist()}}
    FIXTURE.write_text(json.dumps(data) + "\n")
    print(f"wrote {FIXTURE}")


def export_latent_erd(erd: ControlERD, meta: dict, autoencoder: MotionAutoencoder, corpus: WindowCorpus,
                      report: dict, out: Path = MODELS_DIR) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    path = out / "latent-erd.onnx"
    export_step(erd, path)
    parity = check_parity(erd, path)
    norm = Normalisation.from_meta(meta)
    control_sigma = float(meta.get("control_sigma", 0.0))
    info = {"id": "latent-erd", "kind": "latent-erd", "file": path.name, "manifold": "manifold.json", "fps": meta["fps"],
            "pooling": POOLING, "radius": RADIUS, "lookahead": LOOKAHEAD, "latent": erd.dim, "control_dim": erd.control,
            "hidden": erd.hidden, "layers": erd.layers,
            "inputs": INPUTS, "outputs": OUTPUTS,
            "latent_normalisation": {"mean": np.round(norm.latent_mean, 6).tolist(), "std": np.round(norm.latent_std, 6).tolist()},
            "control_range": control_range(corpus), "seeds": pick_seeds(corpus, autoencoder, norm, control_sigma),
            "control_smoothing_frames": control_sigma,
            "parity_max_abs": parity, "report": report, "bytes": path.stat().st_size}
    (out / "latent-erd.json").write_text(json.dumps(info) + "\n")
    if out == MODELS_DIR:
        write_reference_fixture(path, out / "manifold-decoder.onnx", info, norm)
        register_model({"id": "latent-erd", "kind": "latent-erd", "skeleton": "cmu-canonical", "fps": meta["fps"],
                        "bytes": info["bytes"], "file": path.name})
    print(f"wrote {path} ({info['bytes'] / 1e6:.1f} MB), parity {parity:.1e}")
    return info


def reseed(out: Path, autoencoder: MotionAutoencoder, corpus: WindowCorpus) -> dict:
    """Rewrite the seeds of an exported latent-erd.json (pick_seeds) for its latent-erd.onnx as it is, without the
    network's checkpoint, and for public/models the parity fixture: for a change in how streams are seeded. The
    normalisations are the JSON's (6 decimals), as the page reads them."""
    path = out / "latent-erd.json"
    info = json.loads(path.read_text())
    manifold = json.loads((out / info["manifold"]).read_text())
    norm = Normalisation(*(np.asarray(v, np.float64) for v in (
        info["latent_normalisation"]["mean"], info["latent_normalisation"]["std"],
        manifold["normalisation"]["mean"], manifold["normalisation"]["std"])))
    info["seeds"] = pick_seeds(corpus, autoencoder, norm, float(info.get("control_smoothing_frames", 0.0)))
    path.write_text(json.dumps(info) + "\n")
    if out == MODELS_DIR:
        write_reference_fixture(out / info["file"], out / "manifold-decoder.onnx", info, norm)
    print(f"wrote {path}: {len(info['seeds'])} seeds of {SEED_STEPS} latent steps")
    return info
