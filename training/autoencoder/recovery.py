"""Rebuilding the motion autoencoder's torch checkpoint from the shipped ONNX graphs and manifold.json
(python -m training.autoencoder.recover).

For when runs/autoencoder/best.pt is gone (runs/ is not in git) but the models built on the manifold (the
latent ERD) have to be trained or exported again. The four convolutions come from the initializers of
manifold-encoder.onnx (the encoder's two) and manifold-decoder.onnx (the decoder's two), as the graphs compute
with them whatever their storage format (float32, float16 or int8: exporting.py autoencoder_from_onnx); the meta (dim,
hidden, latent, fps, window, normalisation) from manifold.json, in the format training/autoencoder/training.py
saves. The rebuilt model is checked against both graphs with onnxruntime before anything is written.

What cannot be recovered: the optimiser state (so no --resume from it) and the unrounded normalisation (the
JSON keeps 6 decimals; the ERD's training recomputes it from the corpus anyway).
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import torch

from ..models.autoencoder import MotionAutoencoder
from ..onnx.sessions import cpu_session
from .exporting import PARITY_TOLERANCE, RADIUS, ValidDecoder, autoencoder_from_onnx, shipped_meta


def rebuild(info: dict, encoder_path: Path, decoder_path: Path) -> tuple[MotionAutoencoder, float]:
    """The model (eval mode) from the two graphs, and its largest difference from them in onnxruntime."""
    rows = info["rows"]["dim"]
    model = autoencoder_from_onnx(encoder_path, decoder_path, rows, info["hidden"], info["latent"])
    x = np.random.default_rng(0).normal(size=(2, 4 * (2 * RADIUS + 3), rows)).astype(np.float32)
    with torch.no_grad():
        z = model.encode(torch.from_numpy(x))
        decoded = ValidDecoder(model)(z).numpy()
    worst = max(float(np.abs(cpu_session(encoder_path).run(["latent"], {"rows": x})[0] - z.numpy()).max()),
                float(np.abs(cpu_session(decoder_path).run(["rows"], {"latent": z.numpy()})[0] - decoded).max()))
    if worst > PARITY_TOLERANCE:
        raise ValueError(f"the rebuilt autoencoder differs from the ONNX graphs by {worst:.2e} (tolerance {PARITY_TOLERANCE})")
    return model, worst


def recover_checkpoint(info_path: Path, out: Path) -> tuple[dict, float]:
    """Write a checkpoint that training.autoencoder.training.load_autoencoder reads; returns it and the parity."""
    info = json.loads(info_path.read_text())
    encoder_path, decoder_path = (info_path.parent / info["files"][k] for k in ("encoder", "decoder"))
    model, worst = rebuild(info, encoder_path, decoder_path)
    digest = {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in (encoder_path, decoder_path)}
    state = {"model": model.state_dict(), "meta": shipped_meta(info), "recovered_from": digest}
    out.parent.mkdir(parents=True, exist_ok=True)
    torch.save(state, out)
    return state, worst
