"""Exporting the latent ERD: the ONNX step, latent-erd.json with seeds, the manifest entry, and
tests/fixtures/latent_erd_reference.json for the browser's parity tests.

latent-erd.onnx is one step: z (batch, latent) normalised, control (batch, 12) normalised, h and c
(layers, batch, hidden) -> z_next, h_out, c_out. The batch dimension is dynamic. Its large weights are stored as
float32, float16 or int8 with a scale per output channel (training/onnx/compact.py; the export command's default is
int8), made float32 again inside the graph when the session is created; the parity check compares onnxruntime with
torch holding the weights as stored (`erd_from_onnx`, read back from the file). `rewrite_latent_erd` writes the
exported file again (another weight format, new seeds through the shipped autoencoder, the fixture) without the
checkpoint.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import onnx
import torch
from torch import nn

from ..autoencoder.exporting import RADIUS, shipped_autoencoder
from ..data.windows import CONTROL_SLICE, WindowCorpus
from ..models.autoencoder import POOLING, MotionAutoencoder
from ..models.erd import ControlERD
from ..onnx.compact import compact_weights, float_initializers, weight_format
from ..onnx.lstm import lstm_node_weights
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


def export_step(erd: ControlERD, path: Path, weights: str = "float32") -> ControlERD:
    """Writes the step graph with its large weights stored as `weights`; returns the ERD the file computes (the
    weights as stored, eval mode), the reference for the parity check."""
    z, control = torch.zeros(1, erd.dim), torch.zeros(1, erd.control)
    h, c = erd.zero_state(1)
    b, s = {0: "batch"}, {1: "batch"}
    torch.onnx.export(ERDStep(erd).eval(), (z, control, h, c), str(path), input_names=INPUTS, output_names=OUTPUTS,
                      opset_version=17, dynamo=False,
                      dynamic_axes={"z": b, "control": b, "h": s, "c": s, "z_next": b, "h_out": s, "c_out": s})
    onnx.save(compact_weights(onnx.load(str(path)), weights), str(path))
    return erd_from_onnx(path, erd.dim, erd.control, erd.hidden, erd.layers)


def erd_from_onnx(path: Path, dim: int, control: int, hidden: int, layers: int) -> ControlERD:
    """The ControlERD (eval mode) an export_step file holds, whatever its weight format: the encoder's and the
    decoder's MatMul and the Add of its bias, one ONNX LSTM node per layer (W, R (1, 4H, in), B (1, 8H): input and
    recurrent biases), and the output clamp's Max and Min. Weights stored in lower precision come back as the float32
    values the graph computes with."""
    graph = onnx.load(str(path))
    w = float_initializers(graph)
    nodes = list(graph.graph.node)
    lstms = [n for n in nodes if n.op_type == "LSTM"]
    matmuls = [n for n in nodes if n.op_type == "MatMul" and n.input[1] in w]
    if len(lstms) != layers or len(matmuls) != 2:
        raise ValueError(f"{path.name} has {len(lstms)} LSTM and {len(matmuls)} weight MatMul nodes (expected {layers} and 2): "
                         "not an export of training/latent_erd/exporting.py")

    def bias_of(matmul) -> np.ndarray:
        add = next(n for n in nodes if n.op_type == "Add" and matmul.output[0] in n.input)
        return w[next(i for i in add.input if i in w)]

    def clamp(op: str) -> np.ndarray:
        return w[next(i for n in nodes if n.op_type == op for i in n.input if i in w)]

    sd = {"encoder.0.weight": w[matmuls[0].input[1]].T, "encoder.0.bias": bias_of(matmuls[0]),
          "decoder.weight": w[matmuls[1].input[1]].T, "decoder.bias": bias_of(matmuls[1]),
          "low": clamp("Max"), "high": clamp("Min")}
    for l, n in enumerate(lstms):
        sd.update({f"lstms.{l}.{k}_l0": v for k, v in lstm_node_weights(n, w, hidden).items()})
    erd = ControlERD(dim, control, hidden, layers)
    erd.load_state_dict({k: torch.from_numpy(np.ascontiguousarray(v, np.float32)) for k, v in sd.items()})
    return erd.eval()


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


def _publish(info: dict, out: Path, norm: Normalisation) -> None:
    """latent-erd.json beside the graph; into MODELS_DIR also the parity fixture and the manifest entry."""
    path = out / info["file"]
    info["bytes"] = path.stat().st_size
    (out / "latent-erd.json").write_text(json.dumps(info) + "\n")
    if out == MODELS_DIR:
        write_reference_fixture(path, out / "manifold-decoder.onnx", info, norm)
        register_model({"id": "latent-erd", "kind": "latent-erd", "skeleton": "cmu-canonical", "fps": info["fps"],
                        "bytes": info["bytes"], "file": path.name}, "cmu-locomotion")


def _write_step(erd: ControlERD, path: Path, weights: str) -> dict:
    """Writes and parity-checks the step graph; returns the JSON's parity and weight fields."""
    parity = check_parity(export_step(erd, path, weights), path)
    return {"parity_max_abs": parity, "parity_reference": f"torch with the weights as stored ({weights})",
            "weights": weight_format(onnx.load(str(path)))}


def export_latent_erd(erd: ControlERD, meta: dict, autoencoder: MotionAutoencoder, corpus: WindowCorpus,
                      report: dict, out: Path = MODELS_DIR, weights: str = "float32") -> dict:
    out.mkdir(parents=True, exist_ok=True)
    path = out / "latent-erd.onnx"
    stored = _write_step(erd, path, weights)
    norm = Normalisation.from_meta(meta)
    control_sigma = float(meta.get("control_sigma", 0.0))
    info = {"id": "latent-erd", "kind": "latent-erd", "file": path.name, "manifold": "manifold.json", "fps": meta["fps"],
            "pooling": POOLING, "radius": RADIUS, "lookahead": LOOKAHEAD, "latent": erd.dim, "control_dim": erd.control,
            "hidden": erd.hidden, "layers": erd.layers,
            "inputs": INPUTS, "outputs": OUTPUTS,
            "latent_normalisation": {"mean": np.round(norm.latent_mean, 6).tolist(), "std": np.round(norm.latent_std, 6).tolist()},
            "control_range": control_range(corpus), "seeds": pick_seeds(corpus, autoencoder, norm, control_sigma),
            "control_smoothing_frames": control_sigma, **stored, "report": report}
    _publish(info, out, norm)
    print(f"wrote {path} ({info['bytes'] / 1e6:.2f} MB, {weights}), parity {info['parity_max_abs']:.1e}")
    return info


def _json_normalisation(out: Path, info: dict) -> Normalisation:
    """The normalisations as the page reads them: latent-erd.json's and its manifold.json's (6 decimals)."""
    manifold = json.loads((out / info["manifold"]).read_text())
    return Normalisation(*(np.asarray(v, np.float64) for v in (
        info["latent_normalisation"]["mean"], info["latent_normalisation"]["std"],
        manifold["normalisation"]["mean"], manifold["normalisation"]["std"])))


def reseed(out: Path, corpus: WindowCorpus) -> dict:
    """Rewrite the seeds of an exported latent-erd.json (pick_seeds, through the autoencoder of out/manifold.json as
    exported) for its latent-erd.onnx as it is, without a checkpoint, and for public/models the parity fixture: for a
    change in how streams are seeded."""
    path = out / "latent-erd.json"
    info = json.loads(path.read_text())
    norm = _json_normalisation(out, info)
    info["seeds"] = pick_seeds(corpus, shipped_autoencoder(out / info["manifold"]), norm, float(info.get("control_smoothing_frames", 0.0)))
    path.write_text(json.dumps(info) + "\n")
    if out == MODELS_DIR:
        write_reference_fixture(out / info["file"], out / "manifold-decoder.onnx", info, norm)
    print(f"wrote {path}: {len(info['seeds'])} seeds of {SEED_STEPS} latent steps")
    return info


def rewrite_latent_erd(source: Path, out: Path, corpus: WindowCorpus, weights: str) -> dict:
    """The exported latent ERD `source`/latent-erd.{json,onnx} written again into `out` with its weights stored as
    `weights`, without the checkpoint: the network is read back from the ONNX file (erd_from_onnx), the seeds picked
    again through the autoencoder exported into `out` (export it first: the seeds are what its encoder gives), and
    for public/models the fixture made from the files as written. The rest of the JSON is kept."""
    info = json.loads((source / "latent-erd.json").read_text())
    erd = erd_from_onnx(source / info["file"], info["latent"], info["control_dim"], info["hidden"], info["layers"])
    out.mkdir(parents=True, exist_ok=True)
    path = out / "latent-erd.onnx"
    info.update(_write_step(erd, path, weights), file=path.name)
    norm = _json_normalisation(out, info)
    info["seeds"] = pick_seeds(corpus, shipped_autoencoder(out / info["manifold"]), norm, float(info.get("control_smoothing_frames", 0.0)))
    _publish(info, out, norm)
    print(f"wrote {path} ({info['bytes'] / 1e6:.2f} MB, {weights}), parity {info['parity_max_abs']:.1e}")
    return info
