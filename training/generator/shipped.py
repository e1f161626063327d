"""Sampling motion from the exported generator with onnxruntime (the same artefact the browser runs)."""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..data.features import FeatureCodec
from ..data.locomotion import LocomotionClip
from ..mocap.rotations import quat_to_matrix
from ..mocap.skeleton import canonical_skeleton
from ..onnx.sessions import cpu_session


@dataclass
class DecodedMotion:
    """Generator features of one stream or clip and the world motion they decode to."""
    features: np.ndarray   # (frames, dim) physical units
    positions: np.ndarray  # (frames, joints, 3) world metres
    contacts: np.ndarray   # (frames, 2) 0/1

    @property
    def yaw(self) -> np.ndarray:
        """Heading per frame (rad), integrated from the features' heading changes."""
        return np.cumsum(self.features[:, 2])


class ShippedGenerator:
    def __init__(self, models_dir: Path):
        self.info = json.loads((models_dir / "generator.json").read_text())
        self.session = cpu_session(models_dir / self.info["file"], threads=1)
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

    def held_out(self, clips: list[LocomotionClip]) -> list[DecodedMotion]:
        """The generator's held-out validation clips among `clips`, encoded with its codec and decoded again
        (each clip on its own, root starting at the origin)."""
        held_out = set(self.info["training"]["valid_files"])
        out = []
        for c in clips:
            if c.file in held_out:
                features = self.codec.encode(c.root, c.rotations, c.contacts)
                out.append(DecodedMotion(features, self.codec.positions(features), c.contacts[1:]))
        return out


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
