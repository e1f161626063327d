"""The fairer freeze rule (issue 18): each style judged against its own real held-out clips, measured the same way.

A second is *low* when its pose change (mean joint speed relative to the root, metrics.pose_change_per_second)
is below 20% of the real median for the style. A run passes when
  (a) its share of low seconds is at most twice the real clips' share,
  (b) no stretch of 5 s or more is low, and
  (c) its median per-second pose change is at least 50% of the real median (a low-energy collapse fails).
Real dancers pause too, so the real clips' own share and longest low stretch are given beside every verdict.
A dancer that shakes also passes, so the reports give each run's jitter against the real clips' beside the verdict.
"""
from __future__ import annotations

import numpy as np

from ..data.dance import MODEL_FPS, STYLES, DanceClip, held_out_pose_change, resample_positions

LOW_FRACTION = 0.2      # of the real median: a "low" second
SHARE_FACTOR = 2.0      # (a) at most this many times the real share of low seconds
LONGEST_LOW_S = 5       # (b) no low stretch this long or longer
MEDIAN_FRACTION = 0.5   # (c) the run's median at least this share of the real median


def longest_run(mask: np.ndarray) -> int:
    """Length of the longest stretch of True values."""
    best = run = 0
    for m in mask:
        run = run + 1 if m else 0
        best = max(best, run)
    return best


def real_reference(clips: list[DanceClip], styles: tuple[str, ...] | list[str] = STYLES) -> dict:
    """Per style, over the held-out clips at the model's rate: the median per-second pose change (m/s), the share
    of low seconds and the longest low stretch (s) of any clip (clips are measured one by one, never joined)."""
    out = {}
    for style in styles:
        curves = held_out_pose_change(clips, style)
        median = float(np.median(np.concatenate(curves)))
        low = [curve < LOW_FRACTION * median for curve in curves]
        out[style] = {"median": median, "low_share": float(np.concatenate(low).mean()),
                      "longest_low_s": max(longest_run(m) for m in low), "seconds": int(sum(len(c) for c in curves))}
    return out


def judge(curve: np.ndarray, ref: dict) -> dict:
    """One run's per-second pose change against its style's real reference: the three measures and the verdicts."""
    low = curve < LOW_FRACTION * ref["median"]
    share, longest, ratio = float(low.mean()), longest_run(low), float(np.median(curve) / ref["median"])
    verdict = {"a": share <= SHARE_FACTOR * ref["low_share"], "b": longest < LONGEST_LOW_S, "c": ratio >= MEDIAN_FRACTION}
    return {"low_share": share, "longest_low_s": longest, "median_ratio": ratio, **{f"pass_{k}": v for k, v in verdict.items()},
            "passes": all(verdict.values())}


def real_jitter_cm(clips, styles: tuple[str, ...] | list[str] = STYLES) -> dict:
    """Each style's mean jitter_cm over its held-out clips, each clip alone, at the model's rate."""
    return {s: float(np.mean([jitter_cm(resample_positions(c.positions, c.fps, 0.0, int(c.seconds * MODEL_FPS) - 1))
                              for c in clips if c.style == s and c.held_out])) for s in styles}


def jitter_cm(pos: np.ndarray) -> float:
    """Mean |second difference| of the joints relative to the root (cm per frame²): frame-to-frame shake."""
    local = pos - pos[:, :1]
    return float(np.linalg.norm(np.diff(local, 2, axis=0), axis=-1).mean() * 100)
