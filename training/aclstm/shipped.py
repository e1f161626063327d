"""Running an exported dance model (acLSTM or its vanilla baseline) with onnxruntime: the artefact the browser runs."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..onnx.sessions import cpu_session


class ShippedDance:
    STEPS_PER_CALL = 32  # as the page's DanceCore

    def __init__(self, models_dir: Path, model_id: str = "aclstm"):
        self.info = json.loads((models_dir / f"{model_id}.json").read_text())
        self.session = cpu_session(models_dir / self.info["file"], threads=1)
        self.mean = np.array(self.info["normalisation"]["mean"], np.float32)
        self.std = np.array(self.info["normalisation"]["std"], np.float32)
        self.styles = self.info["styles"]
        self.layers, self.hidden = self.info["onnx"]["layers"], self.info["onnx"]["hidden"]
        # A Gaussian head draws each frame from normals the caller passes (graph.py); its default temperature is the JSON's.
        self.gauss = "noise" in self.info["onnx"]["inputs"]
        self.temperature = float(self.info.get("temperature", 0.0))

    def seeds_of(self, style: str) -> list[dict]:
        return [s for s in self.info["seeds"] if s["style"] == style]

    def generate(self, seed_frames: np.ndarray, styles: list[str], frames: int, progress: bool = False,
                 feedback_noise: float = 0.0, rho: float = 0.0, pose_only: bool = False, seed: int = 0,
                 temperature: float | None = None) -> np.ndarray:
        """Warm up on seed_frames (batch, seed, dim; physical units), then feed outputs back for `frames` steps.
        Returns the generated features (batch, frames, dim) in physical units. `feedback_noise`: Gaussian noise
        (normalised units, AR(1) with coefficient `rho`, seeded by `seed`) added to what the network reads back,
        on every channel or, with `pose_only`, not the root's three; the outputs stay its own predictions.
        A Gaussian head draws its frames at `temperature` (default the JSON's; 0 gives the mean), from normals
        seeded by `seed`."""
        sampling = {"draws": np.random.default_rng(seed), "temperature": self.temperature if temperature is None else temperature}
        b = len(seed_frames)
        style = np.eye(len(self.styles), dtype=np.float32)[[self.styles.index(s) for s in styles]]
        h = np.zeros((self.layers, b, self.hidden), np.float32)
        c = np.zeros_like(h)
        warm = ((np.asarray(seed_frames) - self.mean) / self.std).astype(np.float32)
        for t in range(warm.shape[1]):
            y, h, c = self.run_steps(warm[:, t], style, h, c, 1, **sampling)
        y = y[-1]
        out = np.zeros((b, frames, len(self.mean)), np.float32)
        if not feedback_noise:  # the page's way: many steps per call, each output fed back inside the graph
            for t in tqdm(range(0, frames, self.STEPS_PER_CALL), desc="dance", unit="call", disable=not progress):
                n = min(self.STEPS_PER_CALL, frames - t)
                out[:, t] = y
                ys, h, c = self.run_steps(y, style, h, c, n, **sampling)
                out[:, t + 1:t + n] = np.swapaxes(ys[:n - 1], 0, 1)
                y = ys[-1]
            return out * self.std + self.mean
        rng = np.random.default_rng(seed)
        mask = np.ones(len(self.mean), np.float32)
        if pose_only:
            mask[:3] = 0.0
        noise = np.zeros(y.shape, np.float32)
        for t in tqdm(range(frames), desc="dance", unit="frame", disable=not progress):
            out[:, t] = y
            x = y
            if feedback_noise:
                noise = rho * noise + np.sqrt(1 - rho * rho) * feedback_noise * rng.standard_normal(y.shape).astype(np.float32)
                x = (y + noise * mask).astype(np.float32)
            ys, h, c = self.run_steps(x, style, h, c, 1, **sampling)
            y = ys[-1]
        return out * self.std + self.mean

    def run_steps(self, x, style, h, c, steps: int, draws: np.random.Generator | None = None,
                  temperature: float | None = None):
        """One session call: `steps` steps from x; returns ys (steps, batch, dim), h, c. A Gaussian head takes its
        normals from `draws` (required) at `temperature` (default the JSON's)."""
        feeds = {"x": x, "style": style, "h": h, "c": c, "steps": np.array([steps], np.int64)}
        if self.gauss:
            if draws is None:
                raise ValueError("a model with a Gaussian head needs `draws` (a numpy Generator) for its normals")
            feeds["noise"] = draws.standard_normal((steps, *x.shape)).astype(np.float32)
            feeds["temperature"] = np.array([self.temperature if temperature is None else temperature], np.float32)
        return self.session.run(None, feeds)
