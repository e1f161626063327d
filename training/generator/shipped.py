"""Sampling motion from the exported generator with onnxruntime (the same artefact the browser runs)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import onnxruntime as ort
from tqdm import tqdm

from ..data.features import FeatureCodec
from ..mocap.rotations import quat_to_matrix
from ..mocap.skeleton import canonical_skeleton


class ShippedGenerator:
    def __init__(self, models_dir: Path):
        self.info = json.loads((models_dir / "generator.json").read_text())
        options = ort.SessionOptions()
        options.intra_op_num_threads = 1
        self.session = ort.InferenceSession(str(models_dir / self.info["file"]), options, providers=["CPUExecutionProvider"])
        self.mean = np.array(self.info["normalisation"]["mean"], np.float32)
        self.std = np.array(self.info["normalisation"]["std"], np.float32)
        self.hidden = self.info["onnx"]["hidden"]
        self.skel = canonical_skeleton()
        refs = quat_to_matrix(np.array(self.info["features"]["references"]))
        self.codec = FeatureCodec(self.skel, refs)

    def sample(self, seeds: list[int], frames: int, temperature: float = 1.0, rng: np.random.Generator | None = None,
               progress: bool = False) -> np.ndarray:
        """Features (len(seeds), frames, dim) in physical units, one stream per seed, batched in one session call per step."""
        rng = rng or np.random.default_rng(0)
        b = len(seeds)
        chosen = [self.info["seeds"][s] for s in seeds]
        x = np.array([s["x"] for s in chosen], np.float32)
        h = np.stack([np.array(s["h"], np.float32).reshape(2, self.hidden) for s in chosen], axis=1)
        c = np.stack([np.array(s["c"], np.float32).reshape(2, self.hidden) for s in chosen], axis=1)
        out = np.zeros((b, frames, len(self.mean)), np.float32)
        contact_lo, contact_hi = (0 - self.mean[-2:]) / self.std[-2:], (1 - self.mean[-2:]) / self.std[-2:]
        for t in tqdm(range(frames), desc="sampling", unit="frame", disable=not progress):
            w, mu, sigma, h, c = self.session.run(None, {"x": x, "h": h, "c": c})
            x = sample_mixture(w, mu, sigma, temperature, rng)
            # Contacts are bits: feed back a clean 0 or 1, as in the training data.
            on = x[:, -2:] * self.std[-2:] + self.mean[-2:] > 0.5
            x[:, -2:] = np.where(on, contact_hi, contact_lo)
            out[:, t] = x * self.std + self.mean
        return out

    def positions(self, features: np.ndarray) -> np.ndarray:
        return self.codec.positions(features.astype(np.float64))


def sample_mixture(w: np.ndarray, mu: np.ndarray, sigma: np.ndarray, temperature: float, rng: np.random.Generator) -> np.ndarray:
    """One draw per row from diagonal Gaussian mixtures; temperature sharpens the weights and scales sigma."""
    if temperature <= 0:
        k = w.argmax(axis=1)
        return mu[np.arange(len(w)), k]
    logits = np.log(np.maximum(w, 1e-12)) / temperature
    p = np.exp(logits - logits.max(axis=1, keepdims=True))
    p /= p.sum(axis=1, keepdims=True)
    k = np.array([rng.choice(len(row), p=row) for row in p])
    rows = np.arange(len(w))
    return (mu[rows, k] + sigma[rows, k] * temperature * rng.standard_normal(mu.shape[-1])).astype(np.float32)
