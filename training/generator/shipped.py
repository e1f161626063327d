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
from .sampling import draw_mixture, held_normals, snap_contacts


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


def seed_batch(info: dict, indices: list[int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The step inputs (x, h, c) of a batch that starts from generator.json's seed states `indices` (`info` is
    generator.json): x (batch, dim), h and c (layers, batch, hidden), float32."""
    layers, hidden = info["onnx"]["layers"], info["onnx"]["hidden"]
    chosen = [info["seeds"][i] for i in indices]
    x = np.array([s["x"] for s in chosen], np.float32)
    h = np.stack([np.array(s["h"], np.float32).reshape(layers, hidden) for s in chosen], axis=1)
    c = np.stack([np.array(s["c"], np.float32).reshape(layers, hidden) for s in chosen], axis=1)
    return x, h, c


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

    def seed_batch(self, indices: list[int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The step inputs (x, h, c) of a batch that starts from the seed states `indices` (seed_batch)."""
        return seed_batch(self.info, indices)

    @property
    def noise_correlation(self) -> float:
        """generator.json's sampling.noise_correlation: how much of each frame's normals carries to the next (0 if absent)."""
        return float(self.info.get("sampling", {}).get("noise_correlation", 0.0))

    def sample(self, seeds: list[int], frames: int, temperature: float = 1.0, rng: np.random.Generator | None = None,
               progress: bool = False, noise_correlation: float | None = None) -> np.ndarray:
        """Features (len(seeds), frames, dim) in physical units, one stream per seed, batched in one session call per
        step, drawn as the page draws them: per row one uniform, then dim fresh normals held over frames with
        `noise_correlation` (default: generator.json's)."""
        rng = rng or np.random.default_rng(0)
        corr = self.noise_correlation if noise_correlation is None else noise_correlation
        b = len(seeds)
        x, h, c = self.seed_batch(seeds)
        out = np.zeros((b, frames, len(self.mean)), np.float32)
        z = None
        for t in tqdm(range(frames), desc="sampling", unit="frame", disable=not progress):
            w, mu, sigma, h, c = self.session.run(None, {"x": x, "h": h, "c": c})
            if temperature <= 0:
                x = draw_mixture(w, mu, sigma, temperature)
            else:
                u = rng.random(b)
                z = held_normals(z, rng.standard_normal((b, mu.shape[-1])), corr)
                x = draw_mixture(w, mu, sigma, temperature, u, z)
            # Contacts are bits: feed back a clean 0 or 1, as in the training data.
            x = snap_contacts(x, self.mean, self.std)
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

