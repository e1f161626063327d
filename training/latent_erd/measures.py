"""The measurements behind docs/models/latent-erd.md (python -m training.latent_erd.evaluate), all on the
shipped ONNX models unless a row says otherwise.

- Prediction (the VAE-LSTM paper's Tables 1 and 2): windows of the held-out clips long enough for
  16 seed frames + 210 predicted ones, starts every PREDICTION_STRIDE frames. Every model sees only the
  past: the seed's rows and latents are computed from the clip up to the seed's end, so no future leaks in
  through the smoothing or the encoder's receptive field. The latent and pose ERDs are then driven by the
  clip's own control; the generator (no control input) free-runs from the same 16 frames.
- Long runs: random control (training/control.py random_control) from 5 seeds, 10,000 frames each.
- Seams: the pose change across the boundary between two emitted 4-frame steps against the change inside a
  step and between real frames, for several look-aheads.
- Foot sliding: by contact bits and by the lowest foot point's height (metrics.py), before and after the
  foot lock (contacts labelled on the motion, then the lock: footlock.plant_feet, as the page does), with the
  held-out real clips measured the same way.
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from .. import metrics
from ..control import random_control
from ..data.features import heading_of
from ..data.windows import CONTACT_SLICE, CONTROL_SLICE, POSITION_DIM, WindowCorpus, ground_frame, motion_rows, smooth
from ..footlock import plant_feet
from ..generator.sampling import sample_mixture, snap_contacts
from ..generator.shipped import ShippedGenerator
from ..mocap.rotations import quat_to_matrix
from ..mocap.skeleton import canonical_skeleton
from ..models.autoencoder import POOLING
from ..models.erd import ControlERD
from .sequences import encode_clip, step_control
from .streaming import LatentStream, Normalisation, OnnxBackend, Root, StreamOutput, place_rows, run_stream

SEED_FRAMES = 16
HORIZONS = (70, 90, 120, 160, 210)
PREDICT_FRAMES = 212  # the stream emits 4 frames at a time
PREDICTION_STRIDE = 60
FREEZE_FRACTION = 0.2


@dataclass
class Shipped:
    """The exported latent ERD and autoencoder as the page runs them."""
    info: dict
    manifold: dict
    norm: Normalisation
    backend: OnnxBackend
    encoder_path: Path

    @classmethod
    def load(cls, models_dir: Path) -> "Shipped":
        info = json.loads((models_dir / "latent-erd.json").read_text())
        manifold = json.loads((models_dir / "manifold.json").read_text())
        norm = Normalisation(np.array(info["latent_normalisation"]["mean"]), np.array(info["latent_normalisation"]["std"]),
                             np.array(manifold["normalisation"]["mean"]), np.array(manifold["normalisation"]["std"]))
        backend = OnnxBackend(models_dir / info["file"], models_dir / manifold["files"]["decoder"])
        return cls(info, manifold, norm, backend, models_dir / manifold["files"]["encoder"])

    @property
    def control_sigma(self) -> float:
        """Frames of Gaussian smoothing the ERD's control input had in training (0: none)."""
        return float(self.info.get("control_smoothing_frames", 0.0))

    def stream(self, seed_latents, seed_controls, root: Root, lookahead: int | None = None) -> LatentStream:
        return LatentStream(self.backend, self.norm, seed_latents, seed_controls, (self.info["layers"], self.info["hidden"]),
                            self.info["fps"], self.info["lookahead"] if lookahead is None else lookahead, root)

    def seed_stream(self, index: int, lookahead: int | None = None) -> LatentStream:
        s = self.info["seeds"][index % len(self.info["seeds"])]
        return self.stream(np.array(s["latents"], np.float32), np.array(s["controls"], np.float32), Root(), lookahead)


class OnnxEncoder:
    def __init__(self, path: Path):
        from ..onnx.sessions import cpu_session
        self.session = cpu_session(path)

    def encode(self, rows: torch.Tensor) -> torch.Tensor:
        return torch.from_numpy(self.session.run(["latent"], {"rows": rows.numpy()})[0])


# ---- prediction -------------------------------------------------------------------------------

@dataclass
class Window:
    clip: int
    start: int  # first seed frame


def prediction_windows(corpus: WindowCorpus) -> list[Window]:
    need = SEED_FRAMES + PREDICT_FRAMES
    out = []
    for i, c in enumerate(corpus.valid_clips):
        for a in range(4, len(c.rows) - need + 1, PREDICTION_STRIDE):
            out.append(Window(i, a // POOLING * POOLING))
    return out


def past_rows(corpus: WindowCorpus, w: Window) -> tuple[np.ndarray, Root]:
    """Normalised rows of the clip up to the end of the seed (computed from that past alone) and the root of the
    first predicted frame."""
    c = corpus.valid_clips[w.clip]
    end = w.start + SEED_FRAMES
    pos, con = c.positions[:end + 1], c.rows[:end + 1, CONTACT_SLICE]
    rows = corpus.normalise(motion_rows(pos, con))
    xz, heading = ground_frame(pos)
    return rows[:end], Root(float(xz[end, 0]), float(xz[end, 1]), float(heading[end]))


def past_seed(shipped: Shipped, encoder: OnnxEncoder, corpus: WindowCorpus, w: Window):
    """The stream's seed for a window from the clip's past only: latents and controls of the 4 seed steps, and
    the root of the first predicted frame."""
    rows, root = past_rows(corpus, w)
    z = encode_clip(encoder, rows)
    steps = SEED_FRAMES // POOLING
    latents = ((z[-steps:] - shipped.norm.latent_mean) / shipped.norm.latent_std).astype(np.float32)
    return latents, step_control(rows, len(z), shipped.control_sigma)[-steps:], root


def driving_control(shipped: Shipped, corpus: WindowCorpus, w: Window, frames: int) -> np.ndarray:
    """The held-out clip's own control (physical) for the predicted frames, smoothed as the ERD reads it."""
    control = corpus.valid_clips[w.clip].rows[:, CONTROL_SLICE]
    if shipped.control_sigma > 0:
        control = smooth(control, shipped.control_sigma)
    return control[w.start + SEED_FRAMES: w.start + SEED_FRAMES + frames]


def latent_prediction(shipped: Shipped, encoder: OnnxEncoder, corpus: WindowCorpus, w: Window, frames: int,
                      constant: bool = False) -> StreamOutput:
    """The stream from the window's seed driven by the clip's own control, or with `constant` by that control's
    mean over the window (a stick held still: no stride in the signal)."""
    stream = shipped.stream(*past_seed(shipped, encoder, corpus, w))
    control = driving_control(shipped, corpus, w, frames)
    if constant:
        control = np.repeat(control.mean(axis=0, keepdims=True), len(control), axis=0)
    return run_stream(stream, control, known_future=True)


def pose_erd_prediction(model: ControlERD, corpus: WindowCorpus, w: Window, frames: int) -> np.ndarray:
    rows, root = past_rows(corpus, w)
    seed = torch.from_numpy(rows[-SEED_FRAMES:])[None]
    real = corpus.valid[w.clip]
    control = torch.from_numpy(real[w.start + 1: w.start + SEED_FRAMES + frames, CONTROL_SLICE])[None]
    out = []
    with torch.no_grad():
        pred, state = model(seed, control[:, :SEED_FRAMES])
        x = pred[:, -1:]
        out.append(x)
        for t in range(SEED_FRAMES, SEED_FRAMES + frames - 1):
            x, state = model(x, control[:, t:t + 1], state)
            out.append(x)
    rows_out = corpus.denormalise(torch.cat(out, 1)[0].numpy())
    return place_rows(rows_out, root, 30.0)[0]


def generator_prediction(gen: ShippedGenerator, corpus: WindowCorpus, clips_by_file: dict, w: Window, frames: int,
                         rng: np.random.Generator, temperature: float = 1.0) -> np.ndarray:
    """The generator teacher-forced through the 16 seed frames from a zero state, then sampling freely."""
    clip = clips_by_file[corpus.valid_clips[w.clip].file]
    end = w.start + SEED_FRAMES
    feats = gen.codec.encode(clip.root[w.start - 1:end], clip.rotations[w.start - 1:end], clip.contacts[w.start - 1:end])
    x_seed = ((feats - gen.mean) / gen.std).astype(np.float32)
    layers, hidden = gen.info["onnx"]["layers"], gen.hidden
    h = np.zeros((layers, 1, hidden), np.float32)
    c = np.zeros_like(h)
    for t in range(len(x_seed)):
        w_, mu, sigma, h, c = gen.session.run(None, {"x": x_seed[t:t + 1], "h": h, "c": c})
    out = []
    for _ in range(frames):
        x = snap_contacts(sample_mixture(w_, mu, sigma, temperature, rng), gen.mean, gen.std)
        out.append(x[0] * gen.std + gen.mean)
        w_, mu, sigma, h, c = gen.session.run(None, {"x": x, "h": h, "c": c})
    allf = np.concatenate([feats, np.array(out)]).astype(np.float64)
    start_heading = float(heading_of(quat_to_matrix(clip.rotations[w.start - 1, 0])))
    pos = gen.codec.positions(allf, start_xz=(clip.root[w.start - 1, 0], clip.root[w.start - 1, 2]), start_heading=start_heading)
    return pos[len(feats):]


def prediction_errors(predicted: list[np.ndarray], real: list[np.ndarray]) -> dict:
    """Mean joint position error (cm) at each horizon, with the root and relative to it."""
    out = {"with_root_cm": {}, "relative_cm": {}}
    for k in HORIZONS:
        p, r = np.stack([q[k - 1] for q in predicted]), np.stack([q[k - 1] for q in real])
        out["with_root_cm"][k] = round(float(np.linalg.norm(p - r, axis=-1).mean() * 100), 1)
        rel = lambda a: a - a[:, :1]
        out["relative_cm"][k] = round(float(np.linalg.norm(rel(p) - rel(r), axis=-1).mean() * 100), 1)
    return out


# ---- long runs, seams, sliding ------------------------------------------------------------------

def real_pose_change_median(corpus: WindowCorpus, fps: float) -> float:
    changes = [metrics.pose_change_per_second(c.positions, fps) for c in corpus.valid_clips + corpus.train_clips[::6]]
    return float(np.median(np.concatenate([c for c in changes if len(c)])))


SPEED_BANDS = ((0.4, 0.6), (0.6, 0.8), (0.8, 1.0), (1.0, 1.5), (1.5, 2.0))


def forward_speed_per_second(control: np.ndarray, fps: float) -> np.ndarray:
    """Each whole second's mean forward speed of a per-frame control (frames, 3), aligned with
    metrics.pose_change_per_second of the same frames (frame t's control is the motion from t to t + 1)."""
    return metrics.per_second_means(control[:-1, 0], fps)


def pose_change_by_speed(changes: list[np.ndarray], speeds: list[np.ndarray], median: float) -> list[dict]:
    """Per band of forward speed (m/s, each second's mean): how many seconds, and their pose change against the
    real median (mean and lowest)."""
    change, speed = np.concatenate(changes), np.concatenate(speeds)
    out = []
    for lo, hi in SPEED_BANDS:
        sel = (speed >= lo) & (speed < hi)
        out.append({"band": [lo, hi], "seconds": int(sel.sum()),
                    "mean_share_of_median": round(float(change[sel].mean() / median), 3) if sel.any() else None,
                    "lowest_share_of_median": round(float(change[sel].min() / median), 3) if sel.any() else None})
    return out


def real_pose_change_by_speed(corpus: WindowCorpus, fps: float, median: float) -> list[dict]:
    """pose_change_by_speed of the real clips (those real_pose_change_median measures), by their own speed."""
    clips = corpus.valid_clips + corpus.train_clips[::6]
    changes = [metrics.pose_change_per_second(c.positions, fps) for c in clips]
    speeds = [forward_speed_per_second(c.rows[:, CONTROL_SLICE], fps) for c in clips]
    return pose_change_by_speed(changes, speeds, median)


def real_share_below(corpus: WindowCorpus, fps: float, median: float) -> float:
    """Share of the held-out clips' seconds whose pose change is below FREEZE_FRACTION of `median`."""
    changes = np.concatenate([metrics.pose_change_per_second(c.positions, fps) for c in corpus.valid_clips])
    return round(float((changes < FREEZE_FRACTION * median).mean()), 4)


def seam_ratio(positions: np.ndarray, fps: float) -> dict:
    """Mean joint displacement relative to the hips between consecutive frames (cm/frame): across the boundary
    of two emitted 4-frame steps, and inside a step."""
    local = positions - positions[:, :1]
    d = np.linalg.norm(np.diff(local, axis=0), axis=-1).mean(axis=1) * 100
    boundary = (np.arange(1, len(positions)) % POOLING) == 0
    return {"boundary_cm": round(float(d[boundary].mean()), 3), "inside_cm": round(float(d[~boundary].mean()), 3),
            "ratio": round(float(d[boundary].mean() / d[~boundary].mean()), 3)}


def real_frame_change(corpus: WindowCorpus) -> float:
    d = [np.linalg.norm(np.diff(c.positions - c.positions[:, :1], axis=0), axis=-1).mean(axis=1) for c in corpus.valid_clips]
    return round(float(np.concatenate(d).mean() * 100), 3)


def random_run(shipped: Shipped, seed: int, frames: int, lookahead: int | None = None) -> tuple[StreamOutput, float, np.ndarray]:
    """The stream on random control from `seed`: its output, the seconds it took, and the control of its frames."""
    control = random_control(seed, frames, shipped.info["fps"])
    stream = shipped.seed_stream(seed, lookahead)
    t0 = time.perf_counter()
    out = run_stream(stream, control, known_future=True)
    return out, time.perf_counter() - t0, control[:len(out.positions)]


def sliding(runs: list[tuple[np.ndarray, np.ndarray]], fps: float) -> dict:
    skel = canonical_skeleton()
    locked = [plant_feet(p, c, fps, skel) for p, c in runs]  # what the page shows: labelled contacts, then the lock
    return {"contact_bits_before": round(metrics.foot_skating_clips(runs, fps, skel), 3),
            "contact_bits_after": round(metrics.foot_skating_clips(locked, fps, skel), 3),
            "low_foot_before": round(metrics.low_foot_sliding_clips([p for p, _ in runs], fps, skel), 3),
            "low_foot_after": round(metrics.low_foot_sliding_clips([p for p, _ in locked], fps, skel), 3)}


def real_sliding(corpus: WindowCorpus, fps: float) -> dict:
    skel = canonical_skeleton()
    clips = [(c.positions, c.rows[:, CONTACT_SLICE].astype(np.uint8)) for c in corpus.valid_clips]
    return {"contact_bits": round(metrics.foot_skating_clips(clips, fps, skel), 3),
            "low_foot": round(metrics.low_foot_sliding_clips([p for p, _ in clips], fps, skel), 3)}

