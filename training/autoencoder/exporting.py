"""Exporting the motion autoencoder: two ONNX graphs and their JSON, parity checked.

- manifold-encoder.onnx: rows (batch, frames, 80) normalised, frames a multiple of 4 -> latent (batch,
  frames / 4, latent), with the training's zero padding at the ends ('same' convolutions).
- manifold-decoder.onnx: latent (batch, steps, latent) -> rows (batch, 4 × (steps - 2 × RADIUS), 80)
  normalised. Its convolutions are unpadded ('valid'), so it returns only the frames whose whole receptive
  field is in the input: a window of 2 × RADIUS + 1 latent steps gives the 4 frames of its centre step
  (what the online stream emits), and a whole clip padded by RADIUS steps at each end gives every frame.
  Inside a sequence it equals the trained decoder exactly (check_parity compares them).

Both store their convolution weights as float32, float16 or int8 with a scale per output channel
(training/onnx/compact.py; the export command's default is int8), made float32 again inside the graph when the
session is created. The parity check compares onnxruntime with torch holding the weights as stored
(`autoencoder_from_onnx`, read back from the files), and the held-out report in manifold.json is measured on them.
`rewrite_autoencoder` writes the exported files again (another weight format) without the checkpoint.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import onnx
import torch
import torch.nn.functional as F
from torch import nn

from ..data.windows import CONTACT_SLICE, CONTROL_SLICE, JOINTS, POSITION_DIM, WindowCorpus
from ..mocap.skeleton import canonical_skeleton
from ..models.autoencoder import KERNEL, POOLING, MotionAutoencoder
from ..onnx.compact import compact_weights, float_initializers, weight_format
from ..onnx.manifest import register_model
from ..onnx.sessions import cpu_session
from ..paths import MODELS_DIR
from .training import control_rmse, live_channels, position_error_cm

# Latent steps each side of a frame's step that its decoded value depends on: the two unpadded
# convolutions reach 12 samples each way at 2 and at 4 times the latent rate, 12/2 + 12/4 = 9 steps
# (check_parity confirms the alignment against the trained decoder).
RADIUS = (KERNEL // 2) // 2 + (KERNEL // 2) // 4
PARITY_TOLERANCE = 1e-4
# Initializer names of the exported graphs -> the trained model's state dict.
ENCODER_WEIGHTS = {f"model.encoder.{i}.{p}": f"encoder.{i}.{p}" for i in (0, 3) for p in ("weight", "bias")}
DECODER_WEIGHTS = {f"{conv}.{p}": f"decoder.{i}.{p}" for conv, i in (("conv1", 2), ("conv2", 6)) for p in ("weight", "bias")}


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


def export_graphs(model: MotionAutoencoder, encoder_path: Path, decoder_path: Path, weights: str = "float32") -> MotionAutoencoder:
    """Writes both graphs with their large weights stored as `weights`; returns the autoencoder the files compute
    (the weights as stored, eval mode), the reference for the parity check."""
    rows = torch.zeros(1, 40, model.dim)
    latent = torch.zeros(1, 2 * RADIUS + 1, model.latent)
    torch.onnx.export(Encoder(model).eval(), (rows,), str(encoder_path), input_names=["rows"], output_names=["latent"],
                      opset_version=17, dynamo=False,
                      dynamic_axes={"rows": {0: "batch", 1: "frames"}, "latent": {0: "batch", 1: "steps"}})
    torch.onnx.export(ValidDecoder(model).eval(), (latent,), str(decoder_path), input_names=["latent"], output_names=["rows"],
                      opset_version=17, dynamo=False,
                      dynamic_axes={"latent": {0: "batch", 1: "steps"}, "rows": {0: "batch", 1: "frames"}})
    for path in (encoder_path, decoder_path):
        onnx.save(compact_weights(onnx.load(str(path)), weights), str(path))
    return autoencoder_from_onnx(encoder_path, decoder_path, model.dim, model.hidden, model.latent)


def _initializers(path: Path, names: dict[str, str]) -> dict[str, torch.Tensor]:
    inits = float_initializers(onnx.load(str(path)))
    missing = sorted(set(names) - set(inits))
    if missing:
        raise ValueError(f"{path.name} has no initializer {', '.join(missing)}: not an export of training/autoencoder/exporting.py")
    return {key: torch.from_numpy(np.array(inits[name])) for name, key in names.items()}


def autoencoder_from_onnx(encoder_path: Path, decoder_path: Path, dim: int, hidden: int, latent: int) -> MotionAutoencoder:
    """The autoencoder (eval mode) two exported graphs hold, whatever their weight format: weights stored in lower
    precision come back as the float32 values the graphs compute with."""
    model = MotionAutoencoder(dim, hidden, latent)
    model.load_state_dict(_initializers(encoder_path, ENCODER_WEIGHTS) | _initializers(decoder_path, DECODER_WEIGHTS))
    return model.eval()


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


def held_out_report(model: MotionAutoencoder, corpus: WindowCorpus, windows: np.ndarray) -> dict:
    """manifold.json's `report`: reconstruction errors on the held-out windows and the live latent channels."""
    return {"held_out_windows": len(windows),
            "reconstruction_cm_clean": round(position_error_cm(model, corpus, windows), 3),
            "reconstruction_cm_masked_0.3": round(position_error_cm(model, corpus, windows, 0.3), 3),
            "control_rmse": [round(float(v), 4) for v in control_rmse(model, corpus, windows)],
            "live_latent_channels": live_channels(model, corpus)}


def export_autoencoder(model: MotionAutoencoder, meta: dict, corpus: WindowCorpus, out: Path = MODELS_DIR,
                       weights: str = "float32") -> dict:
    """Writes out/manifold-{encoder,decoder}.onnx (weights stored as `weights`, parity checked) and manifold.json with
    the held-out report of the network as stored; into MODELS_DIR also the manifest entry."""
    out.mkdir(parents=True, exist_ok=True)
    encoder_path, decoder_path = out / "manifold-encoder.onnx", out / "manifold-decoder.onnx"
    stored = export_graphs(model, encoder_path, decoder_path, weights)
    windows = corpus.valid_windows()
    parity = check_parity(stored, encoder_path, decoder_path, windows)
    info = manifold_info(meta, model, held_out_report(stored, corpus, windows))
    info["parity_max_abs"] = parity
    info["parity_reference"] = f"torch with the weights as stored ({weights})"
    info["weights"] = weight_format(onnx.load(str(encoder_path)))
    info["bytes"] = encoder_path.stat().st_size + decoder_path.stat().st_size
    (out / "manifold.json").write_text(json.dumps(info) + "\n")
    if out == MODELS_DIR:
        register_model({"id": "manifold", "kind": "autoencoder", "skeleton": "cmu-canonical", "fps": meta["fps"],
                        "bytes": info["bytes"], "file": "manifold-decoder.onnx", "files": info["files"]}, "cmu-locomotion")
    print(f"wrote {encoder_path}, {decoder_path} ({info['bytes'] / 1e6:.2f} MB, {weights}), parity {parity}, "
          f"held-out reconstruction {info['report']['reconstruction_cm_clean']} cm")
    return info


def shipped_meta(info: dict) -> dict:
    """The checkpoint meta (training/autoencoder/training.py) that an exported manifold.json carries: the
    normalisation as the JSON rounds it (6 decimals)."""
    return {"dim": info["rows"]["dim"], "hidden": info["hidden"], "latent": info["latent"], "fps": info["fps"],
            "window": info["window"], "mean": info["normalisation"]["mean"], "std": info["normalisation"]["std"]}


def shipped_autoencoder(info_path: Path) -> MotionAutoencoder:
    """The autoencoder an exported manifold.json and its two graphs hold (the weights as stored)."""
    info = json.loads(info_path.read_text())
    encoder_path, decoder_path = (info_path.parent / info["files"][k] for k in ("encoder", "decoder"))
    return autoencoder_from_onnx(encoder_path, decoder_path, info["rows"]["dim"], info["hidden"], info["latent"])


def rewrite_autoencoder(source: Path, corpus: WindowCorpus, out: Path, weights: str) -> dict:
    """The exported autoencoder `source`/manifold.json and its graphs written again into `out` with its weights stored
    as `weights`, without the checkpoint: the network is read back from the graphs, the meta from the JSON, and the
    held-out report measured again on the network as now stored. Rounding twice is harmless for int8 (a stored
    weight quantises to itself), but compact from a float32 export to keep one rounding."""
    info = json.loads((source / "manifold.json").read_text())
    model = shipped_autoencoder(source / "manifold.json")
    return export_autoencoder(model, shipped_meta(info), corpus, out, weights)
