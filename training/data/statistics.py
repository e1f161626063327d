"""The corpus measured on the canonical skeleton (docs/data.md, written by python -m training.data.report).

Per category: clips, minutes, how well the feet meet the floor after retargeting, and how often each foot
is labelled as planted. Every clip is loaded at its native 120 fps.
"""
from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..mocap.skeleton import GROUND_POINTS, canonical_skeleton
from .cmu import CATEGORIES, clip_contacts, load_clip, read_index


def corpus_statistics(mocap: Path) -> dict[str, dict[str, list]]:
    """Per category and for "all": per-clip counts and durations, the lowest foot point of each one-second
    window, per-clip percentiles of the lowest foot point, per-foot contact shares and airborne shares."""
    skel = canonical_skeleton()
    ground = [skel.index(n) for n in GROUND_POINTS]
    rows = defaultdict(lambda: defaultdict(list))
    for info in tqdm(read_index(mocap), desc="clips", unit="clip"):
        clip = load_clip(mocap, info)
        low = clip.positions[:, ground, 1].min(axis=1)
        step = int(round(clip.fps))
        windows = np.array([low[a:a + step].min() for a in range(0, len(low), step)])
        contacts = clip_contacts(clip)
        for key in (info.category, "all"):
            r = rows[key]
            r["clips"].append(1)
            r["seconds"].append(clip.frames / clip.fps)
            r["windows"].extend(windows.tolist())
            r["p1"].append(float(np.percentile(low, 1)))
            r["min"].append(float(low.min()))
            r["contact"].extend(contacts.mean(axis=0).tolist())
            r["airborne"].append(float((contacts.max(axis=1) == 0).mean()))
    return rows


def data_report(rows: dict[str, dict[str, list]]) -> str:
    """docs/data.md from corpus_statistics."""
    lines = [
        "# Corpus on the canonical skeleton",
        "",
        "Made by `python -m training.data.report` from `../shared/mocap` (CMU clips at their native 120 fps,",
        "retargeted to the canonical skeleton in `training/mocap/canonical_skeleton.json`).",
        "",
        "Floor: the lowest foot point (ankle, toe base, toe tip) in each one-second window; in locomotion some foot",
        "touches the floor every second, so a well-placed clip has these near 0. The loader fits a floor plane per",
        "clip (CMU capture floors are tilted by up to about a degree) and rests the clip on it.",
        "",
        "| category | clips | minutes | 1-s windows within ±3 cm | within ±5 cm | clip 1st percentile of lowest foot point (worst) | deepest single frame | foot planted (mean share per foot) | frames with both feet up |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for key in [*CATEGORIES, "all"]:
        r = rows[key]
        w = np.abs(np.array(r["windows"]))
        lines.append(
            f"| {key} | {len(r['clips'])} | {sum(r['seconds']) / 60:.1f} | {np.mean(w < 0.03):.1%} | {np.mean(w < 0.05):.1%} "
            f"| {min(r['p1']) * 100:+.1f} cm | {min(r['min']) * 100:+.1f} cm | {np.mean(r['contact']):.0%} | {np.mean(r['airborne']):.0%} |")
    lines += [
        "",
        "Known limits, measured above: a few clips (dance, and some long takes of subject 105) have isolated",
        "frames where a foot point dips several centimetres below the fitted floor (marker glitches or a floor that",
        "is not flat); the loader does not edit poses to hide them.",
        "",
    ]
    return "\n".join(lines)
