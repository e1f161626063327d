"""Motion quality measures shared by the evaluation reports."""
from __future__ import annotations

import numpy as np

from .mocap.skeleton import Skeleton

TOES = ("LeftToeBase", "RightToeBase")


def planted_toe_speeds(positions: np.ndarray, contacts: np.ndarray, fps: float, skel: Skeleton) -> np.ndarray:
    """Horizontal toe speeds (m/s) over the frame pairs in which that foot is labelled as planted in both
    frames; the left toe's, then the right toe's."""
    speeds = []
    for side, name in enumerate(TOES):
        toe = positions[:, skel.index(name)][:, [0, 2]]
        v = np.linalg.norm(np.diff(toe, axis=0), axis=-1) * fps
        speeds.append(v[(contacts[1:, side] > 0) & (contacts[:-1, side] > 0)])
    return np.concatenate(speeds)


def foot_skating(positions: np.ndarray, contacts: np.ndarray, fps: float, skel: Skeleton) -> float:
    """Mean horizontal speed (m/s) of the toe of a foot while that foot is labelled as planted."""
    allv = planted_toe_speeds(positions, contacts, fps, skel)
    return float(allv.mean()) if len(allv) else float("nan")


def foot_skating_clips(clips: list[tuple[np.ndarray, np.ndarray]], fps: float, skel: Skeleton) -> float:
    """foot_skating pooled over separate clips (positions, contacts), each measured on its own: frame pairs
    never span two clips (joining clips end to end would count the jump between them as skating)."""
    allv = np.concatenate([planted_toe_speeds(p, c, fps, skel) for p, c in clips]) if clips else np.zeros(0)
    return float(allv.mean()) if len(allv) else float("nan")


def root_speed(features: np.ndarray, fps: float) -> np.ndarray:
    """Horizontal root speed per frame (m/s) from generator features."""
    return np.hypot(features[:, 0], features[:, 1]) * fps


def turning_rate(features: np.ndarray, fps: float) -> np.ndarray:
    """Signed heading change per frame as a rate (rad/s)."""
    return features[:, 2] * fps


def per_second_means(values: np.ndarray, fps: float) -> np.ndarray:
    """The mean of each whole second of a per-frame series (a last partial second is dropped)."""
    step = int(round(fps))
    return np.array([values[a:a + step].mean() for a in range(0, len(values) - step + 1, step)])


def pose_change_per_second(positions: np.ndarray, fps: float) -> np.ndarray:
    """Mean joint speed relative to the root (m/s), averaged over each whole second: low values mean a frozen pose."""
    local = positions - positions[:, :1]
    return per_second_means(np.linalg.norm(np.diff(local, axis=0), axis=-1).mean(axis=1) * fps, fps)


def power_spectra(windows: np.ndarray) -> np.ndarray:
    """Per-window, per-dimension power spectrum (windows, freq, dims) of mean-removed windows (windows, time, dims)."""
    w = windows - windows.mean(axis=1, keepdims=True)
    return np.abs(np.fft.rfft(w, axis=1)) ** 2


def npss(real: np.ndarray, generated: np.ndarray) -> float:
    """Normalized power spectrum similarity (Gopalakrishnan et al. 2019) between two sets of windows
    (n, time, dims): earth mover's distance between the mean normalised spectra of each dimension,
    weighted by the real power of that dimension. 0 means identical spectra."""
    pr, pg = power_spectra(real).mean(axis=0), power_spectra(generated).mean(axis=0)
    total_r, total_g = pr.sum(axis=0), pg.sum(axis=0)
    nr, ng = pr / np.maximum(total_r, 1e-12), pg / np.maximum(total_g, 1e-12)
    emd = np.abs(np.cumsum(nr, axis=0) - np.cumsum(ng, axis=0)).sum(axis=0)
    return float((emd * total_r).sum() / total_r.sum())


def windows_of(seqs: list[np.ndarray], length: int, stride: int) -> np.ndarray:
    out = [s[a:a + length] for s in seqs for a in range(0, len(s) - length + 1, stride)]
    return np.stack(out) if out else np.zeros((0, length, seqs[0].shape[1]))


def wasserstein_1d(a: np.ndarray, b: np.ndarray) -> float:
    """Earth mover's distance between two 1-D samples (same units as the samples)."""
    qs = np.linspace(0, 1, 201)
    return float(np.abs(np.quantile(a, qs) - np.quantile(b, qs)).mean())


def summary(values: np.ndarray) -> dict:
    return {"mean": float(np.mean(values)), "p10": float(np.percentile(values, 10)),
            "p50": float(np.percentile(values, 50)), "p90": float(np.percentile(values, 90))}


FOOT_GROUP = {"left": ("LeftFoot", "LeftToeBase", "LeftToeBase_end"), "right": ("RightFoot", "RightToeBase", "RightToeBase_end")}
NEAR_FLOOR = 0.04  # metres


def low_foot_speeds(positions: np.ndarray, fps: float, skel: Skeleton, near: float = NEAR_FLOOR) -> np.ndarray:
    """Horizontal speeds (m/s) of each foot's lowest point (ankle, toe or toe tip, chosen in the first frame of
    each pair) over the frame pairs in which that point is within `near` of the floor (y = 0) in both frames.
    Needs no contact labels, so it also counts feet near the floor whose contact bit is off."""
    speeds = []
    for names in FOOT_GROUP.values():
        idx = [skel.index(n) for n in names]
        pts = positions[:, idx]  # (frames, 3, 3)
        low = pts[..., 1].argmin(axis=1)
        rows = np.arange(len(positions) - 1)
        a, b = pts[rows, low[:-1]], pts[rows + 1, low[:-1]]
        near_both = (a[:, 1] < near) & (b[:, 1] < near)
        speeds.append(np.linalg.norm((b - a)[:, [0, 2]], axis=-1)[near_both] * fps)
    return np.concatenate(speeds)


def low_foot_sliding_clips(clips: list[np.ndarray], fps: float, skel: Skeleton) -> float:
    """low_foot_speeds pooled over separate clips (each measured on its own), mean m/s."""
    allv = np.concatenate([low_foot_speeds(p, fps, skel) for p in clips]) if clips else np.zeros(0)
    return float(allv.mean()) if len(allv) else float("nan")
