"""Exporting the motion autoencoder: two ONNX graphs and their JSON, parity checked.

- manifold-encoder.onnx: rows (batch, frames, 80) normalised, frames a multiple of 4 -> latent (batch,
  frames / 4, latent), with the training's zero padding at the ends ('same' convolutions).
- manifold-decoder.onnx: latent (batch, steps, latent) -> rows (batch, 4 × (steps - 2 × RADIUS), 80)
  normalised. Its convolutions are unpadded ('valid'), so it returns only the frames whose whole receptive
  field is in the input: a window of 2 × RADIUS + 1 latent steps gives the 4 frames of its centre step
  (what the online stream emits), and a whole clip padded by RADIUS steps at each end gives every frame.
  Inside a sequence it equals the trained decoder exactly (check_parity compares them).
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import torch
import torch.nn.functional as F
from torch import nn

from ..data.windows import CONTACT_SLICE, CONTROL_SLICE, JOINTS, POSITION_DIM
from ..mocap.skeleton import canonical_skeleton
from ..models.autoencoder import KERNEL, POOLING, MotionAutoencoder
from ..onnx.manifest import register_model
from ..onnx.sessions import cpu_session
from ..paths import MODELS_DIR

# Latent steps each side of a frame's step that its decoded value depends on: the two unpadded
# convolutions reach 12 samples each way at 2 and at 4 times the latent rate, 12/2 + 12/4 = 9 steps
# (check_parity confirms the alignment against the trained decoder).
RADIUS = (KERNEL // 2) // 2 + (KERNEL // 2) // 4
PARITY_TOLERANCE = 1e-4


class Encoder(nn.Module):
    def __init__(self, model: MotionAutoencoder):
        super().__init__()
        self.model = model

    def forward(self, rows: torch.Tensor) -> torch.Tensor:
        return self.model.encode(rows)


class ValidDecoder(nn.Module):
    """The trained decoder with unpadded convolutions (see the module docstring)."""

    def __init__(self, model: MotionAutoencoder):
        super().__init__()
        self.conv1, self.conv2 = model.decoder[2], model.decoder[6]

    def forward(self, latent: torch.Tensor) -> torch.Tensor:
        z = latent.transpose(1, 2)
        z = F.relu(F.conv1d(F.interpolate(z, scale_factor=2.0, mode="nearest"), self.conv1.weight, self.conv1.bias))
        z = F.conv1d(F.interpolate(z, scale_factor=2.0, mode="nearest"), self.conv2.weight, self.conv2.bias)
        return z.transpose(1, 2)


def decode_clip(model: MotionAutoencoder, latent: np.ndarray) -> np.ndarray:
    """Rows (4 × steps, 80) of a whole latent sequence (steps, latent) through the unpadded decoder, the ends
    padded by repeating the first and last steps (what the page does)."""
    pad = np.concatenate([np.repeat(latent[:1], RADIUS, 0), latent, np.repeat(latent[-1:], RADIUS, 0)])
    with torch.no_grad():
        return ValidDecoder(model)(torch.from_numpy(pad[None].astype(np.float32))).numpy()[0]


def export_graphs(model: MotionAutoencoder, encoder_path: Path, decoder_path: Path) -> None:
    rows = torch.zeros(1, 40, model.dim)
    latent = torch.zeros(1, 2 * RADIUS + 1, model.latent)
    torch.onnx.export(Encoder(model).eval(), (rows,), str(encoder_path), input_names=["rows"], output_names=["latent"],
                      opset_version=17, dynamo=False,
                      dynamic_axes={"rows": {0: "batch", 1: "frames"}, "latent": {0: "batch", 1: "steps"}})
    torch.onnx.export(ValidDecoder(model).eval(), (latent,), str(decoder_path), input_names=["latent"], output_names=["rows"],
                      opset_version=17, dynamo=False,
                      dynamic_axes={"latent": {0: "batch", 1: "steps"}, "rows": {0: "batch", 1: "frames"}})


def check_parity(model: MotionAutoencoder, encoder_path: Path, decoder_path: Path, windows: np.ndarray) -> dict:
    """torch against onnxruntime for both graphs at batch 1 and 3, and the unpadded decoder against the trained
    one on the frames inside the sequence."""
    enc, dec = cpu_session(encoder_path), cpu_session(decoder_path)
    worst = {"encoder": 0.0, "decoder": 0.0, "valid_vs_trained_decoder": 0.0}
    for batch in (1, 3):
        x = windows[:batch]
        with torch.no_grad():
            z_ref = model.encode(torch.from_numpy(x))
            full = model.decode(z_ref).numpy()
            valid = ValidDecoder(model)(z_ref).numpy()
        z = enc.run(["latent"], {"rows": x})[0]
        rows = dec.run(["rows"], {"latent": z_ref.numpy()})[0]
        inner = full[:, POOLING * RADIUS: POOLING * RADIUS + valid.shape[1]]
        worst["encoder"] = max(worst["encoder"], float(np.abs(z - z_ref.numpy()).max()))
        worst["decoder"] = max(worst["decoder"], float(np.abs(rows - valid).max()))
        worst["valid_vs_trained_decoder"] = max(worst["valid_vs_trained_decoder"], float(np.abs(valid - inner).max()))
    for key, value in worst.items():
        if value > PARITY_TOLERANCE:
            raise SystemExit(f"error: {key} parity {value:.2e} exceeds {PARITY_TOLERANCE}")
    return worst


def manifold_info(meta: dict, model: MotionAutoencoder, report: dict) -> dict:
    skel = canonical_skeleton()
    return {
        "id": "manifold", "kind": "autoencoder", "fps": meta["fps"], "window": meta["window"], "pooling": POOLING,
        "radius": RADIUS, "kernel": KERNEL, "latent": model.latent, "hidden": model.hidden,
        "files": {"encoder": "manifold-encoder.onnx", "decoder": "manifold-decoder.onnx"},
        "skeleton": {"joints": skel.joints, "parents": skel.parents, "offsets": skel.offsets.round(6).tolist()},
        "rows": {"dim": model.dim, "positions": [0, POSITION_DIM], "control": [CONTROL_SLICE.start, CONTROL_SLICE.stop],
                 "contacts": [CONTACT_SLICE.start, CONTACT_SLICE.stop], "joints": JOINTS,
                 "positions_frame": "each frame's ground-projected root facing frame: x left, y up (height above the floor), z forward",
                 "control_channels": ["forward m/s", "sideways m/s (+ left)", "turn rad/s (+ from +z towards +x)"]},
        "normalisation": {"mean": [round(float(v), 6) for v in meta["mean"]], "std": [round(float(v), 6) for v in meta["std"]]},
        "report": report,
    }


def export_autoencoder(model: MotionAutoencoder, meta: dict, windows: np.ndarray, report: dict, out: Path = MODELS_DIR) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    encoder_path, decoder_path = out / "manifold-encoder.onnx", out / "manifold-decoder.onnx"
    export_graphs(model, encoder_path, decoder_path)
    parity = check_parity(model, encoder_path, decoder_path, windows)
    info = manifold_info(meta, model, report)
    info["parity_max_abs"] = parity
    info["bytes"] = encoder_path.stat().st_size + decoder_path.stat().st_size
    (out / "manifold.json").write_text(json.dumps(info) + "\n")
    if out == MODELS_DIR:
        register_model({"id": "manifold", "kind": "autoencoder", "skeleton": "cmu-canonical", "fps": meta["fps"],
                        "bytes": info["bytes"], "file": "manifold-decoder.onnx", "files": info["files"]})
    print(f"wrote {encoder_path}, {decoder_path} ({info['bytes'] / 1e6:.1f} MB), parity {parity}")
    return info
