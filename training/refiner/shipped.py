"""Running the shipped refiner with onnxruntime behind the generator, frame by frame from a zero state, as the
browser does."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import torch

from ..data.features import FeatureCodec
from ..models.refiner import FeatureGeometry
from ..onnx.sessions import cpu_session


class ShippedRefiner:
    def __init__(self, models_dir: Path, codec: FeatureCodec):
        self.info = json.loads((models_dir / "refiner.json").read_text())
        self.session = cpu_session(models_dir / self.info["file"], threads=1)
        self.hidden = self.info["onnx"]["hidden"]
        self.mean = np.array(self.info["normalisation"]["mean"], np.float32)
        self.std = np.array(self.info["normalisation"]["std"], np.float32)
        self.geometry = FeatureGeometry(codec.references, fps=self.info["fps"],
                                        end_effectors=tuple(self.info["end_effectors"]["names"])).double()

    def ends(self, physical: np.ndarray) -> np.ndarray:
        """Root-frame end-effector positions (..., 3E) of physical frames (..., D): what the browser computes."""
        with torch.no_grad():
            return self.geometry.end_positions(torch.from_numpy(physical.astype(np.float64))).flatten(-2).numpy().astype(np.float32)

    def refine(self, physical: np.ndarray, seed_physical: np.ndarray) -> np.ndarray:
        """Stream (B, T, D) physical generator frames through R after the seed frames (B, D); physical out."""
        b, t, _ = physical.shape
        x = ((physical - self.mean) / self.std).astype(np.float32)
        q = self.ends(physical)
        q_prev = self.ends(seed_physical)
        h = np.zeros((1, b, self.hidden), np.float32)
        c = h.copy()
        out = np.zeros_like(x)
        for k in range(t):  # one frame per call: the graph takes (B, frames, .) chunks
            y, h, c = self.session.run(None, {"x": x[:, k:k + 1], "ends": q[:, k:k + 1], "ends_prev": q_prev, "h": h, "c": c})
            out[:, k] = y[:, 0]
            q_prev = q[:, k]
        return out * self.std + self.mean
