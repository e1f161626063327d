"""Quick measures of realism levers (issue 20's pilots), on the refiner report's two-sample protocol cut down: one
classifier seed, 1,500 frames from each of the generator's 8 seeds, streams A (measured, the classifiers' test) and B
(the classifiers' training) as in report.py. Each pilot is a refiner (a training checkpoint, run in torch over the
whole stream from a zero state, which is what the causal R streamed frame by frame computes, or the shipped ONNX) and a
way of sampling the generator (a temperature factor on some features' sigmas, the noise correlation). Results go to
docs/models/refiner-pilots.json by python -m training.refiner.pilot; the report prints them as a table.
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import torch

from .. import metrics
from ..data.locomotion import load_clips
from ..generator.shipped import DecodedMotion, ShippedGenerator
from ..paths import MODELS_DIR
from .measures import motion_windows, two_sample_accuracy, windows
from .report import TEMPERATURE, decode_variants, real_training_frames
from .shipped import ShippedRefiner
from .training import load_refiner

FRAMES = 1500
STREAM_SEEDS = (2024, 7)  # streams A and B, as in report.evaluate_refiner


class CheckpointRefiner:
    """A training checkpoint's R over whole streams in torch (physical frames in and out, as ShippedRefiner.refine)."""

    def __init__(self, checkpoint: Path):
        self.model, self.meta, _ = load_refiner(checkpoint)

    def refine(self, physical: np.ndarray, seed_physical: np.ndarray) -> np.ndarray:
        m = self.model
        mean, std = m.mean.numpy(), m.std.numpy()
        with torch.no_grad():
            y, _ = m(torch.from_numpy(((physical - mean) / std).astype(np.float32)),
                     torch.from_numpy(((seed_physical - mean) / std).astype(np.float32)))
        return y.numpy() * std + mean


class ScaledSigmas:
    """The generator's session with each feature's mixture sigmas multiplied by a factor: a per-feature temperature."""

    def __init__(self, session, scale: np.ndarray):
        self.session, self.scale = session, scale.astype(np.float32)

    def run(self, names, feed):
        w, mu, sigma, h, c = self.session.run(names, feed)
        return w, mu, sigma * self.scale, h, c


def sigma_scale(spec: str, dim: int) -> np.ndarray:
    """'3-6:0.3,0-2:0.5' -> per-feature factors (features 3..6 times 0.3, 0..2 times 0.5, the rest 1)."""
    scale = np.ones(dim)
    for part in filter(None, spec.split(",")):
        span, factor = part.split(":")
        a, b = (int(v) for v in span.split("-"))
        scale[a:b + 1] = float(factor)
    return scale


def variant_streams(gen: ShippedGenerator, refiner, stream_seed: int, frames: int) -> dict[str, list[DecodedMotion]]:
    """'raw', 'raw + foot lock', 'refined', 'refined + foot lock' (the refined ones only with a refiner), as the page
    shows them (report.decode_variants: plant_feet on the decoded frames)."""
    seeds = list(range(len(gen.info["seeds"])))
    seed_x = np.array([gen.info["seeds"][s]["x"] for s in seeds]) * gen.std + gen.mean
    raw = gen.sample(seeds, frames, TEMPERATURE, np.random.default_rng(stream_seed))
    return decode_variants(gen, refiner, raw, seed_x)[0]


def measure_pilot(checkpoint: Path | None, shipped_refiner: bool, scale_spec: str = "", rho: float | None = None,
                  frames: int = FRAMES, mocap: str | None = None, classifier_seed: int = 0) -> dict:
    """Two-sample accuracies (windows, single frames) and lowest-point sliding of every variant of one pilot."""
    t0 = time.perf_counter()
    gen = ShippedGenerator(MODELS_DIR)
    if scale_spec:
        gen.session = ScaledSigmas(gen.session, sigma_scale(scale_spec, len(gen.mean)))
    if rho is not None:
        gen.info["sampling"]["noise_correlation"] = rho
    refiner = CheckpointRefiner(checkpoint) if checkpoint else ShippedRefiner(MODELS_DIR, gen.codec) if shipped_refiner else None
    fps = gen.info["fps"]
    var_a, var_b = (variant_streams(gen, refiner, s, frames) for s in STREAM_SEEDS)
    clips = load_clips(mocap)
    real = gen.held_out(clips)
    real_train, real_test = windows(real_training_frames(gen, clips)), motion_windows(real, fps)
    out = {"frames_per_seed": frames, "classifier_seed": classifier_seed, "sigma_scale": scale_spec,
           "noise_correlation": gen.noise_correlation, "checkpoint": str(checkpoint) if checkpoint else None,
           "refiner": "checkpoint" if checkpoint else "shipped" if shipped_refiner else None,
           "real_sliding": float(np.concatenate([metrics.low_foot_speeds(s.positions, fps, gen.skel) for s in real]).mean()),
           "variants": {}}
    if checkpoint:
        out["updates"] = int(torch.load(checkpoint, weights_only=False)["state"]["r_updates"])
    for v in var_a:
        train_w, test_w = motion_windows(var_b[v], fps), motion_windows(var_a[v], fps)
        out["variants"][v] = {
            "window": two_sample_accuracy(real_train, train_w, real_test, test_w, classifier_seed)["balanced_accuracy"],
            "frame": two_sample_accuracy(real_train, train_w, real_test, test_w, classifier_seed, kind="frame")["balanced_accuracy"],
            "sliding": float(np.concatenate([metrics.low_foot_speeds(s.positions, fps, gen.skel) for s in var_a[v]]).mean()),
            "contact_share": np.concatenate([s.contacts for s in var_a[v]]).mean(0).round(3).tolist()}
    out["minutes"] = (time.perf_counter() - t0) / 60
    return out
