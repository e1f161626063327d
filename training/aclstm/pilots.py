"""Quick measure of a dance-model training run (issue 18's pilots): self-fed rollouts of its checkpoint in torch,
judged by the fairer freeze rule (freeze_rule.py) against each style's real clips, with its validation losses.

Rollouts start from the export's seed motions (exporting.pick_seeds: 10 real frames of held-out clips) and run
`frames` steps per seed for each style; a rollout that leaves the believable range (NaN, a root outside
0.2-1.6 m, or a second whose limb-length error exceeds 25%) counts as diverged, as in the report.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import torch

from .. import metrics
from ..data.dance import LIMB_MIN_LENGTH, MODEL_FPS, STYLES, bone_length_error, decode, load_clips
from .exporting import load_dance_model, pick_seeds
from .freeze_rule import judge, real_reference
from .report import BONE_ERROR_LIMIT, HEIGHT_BAND, per_second


def rollout(model, meta: dict, seed_frames: np.ndarray, styles: list[str], frames: int) -> np.ndarray:
    """Warm up on the seeds (batch, seed, dim; physical units), then feed outputs back: (batch, frames, dim)."""
    mean, std = np.array(meta["mean"], np.float32), np.array(meta["std"], np.float32)
    style = torch.eye(len(meta["styles"]))[[meta["styles"].index(s) for s in styles]]
    x = torch.from_numpy(((seed_frames - mean) / std).astype(np.float32))
    out = np.zeros((len(x), frames, x.shape[-1]), np.float32)
    with torch.no_grad():
        y, state = model(x, style)
        y = y[:, -1:]
        for t in range(frames):
            out[:, t] = y[:, 0].numpy()
            y, state = model(y, style, state)
    return out * std + mean


def measure_run(checkpoint: Path, frames: int = 3000, seeds_per_style: int = 3, mocap: str | None = None) -> dict:
    """The pilot measure of one checkpoint: per style and seed the freeze-rule numbers; validation from the run."""
    skel, clips = load_clips(mocap)
    model, meta, state = load_dance_model(checkpoint)
    ref = real_reference(clips)
    chosen = [s for style in STYLES for s in [x for x in pick_seeds(clips) if x["style"] == style][:seeds_per_style]]
    feats = rollout(model, meta, np.array([s["frames"] for s in chosen], np.float32), [s["style"] for s in chosen], frames)
    runs = []
    for seed, f in zip(chosen, feats):
        finite = bool(np.isfinite(f).all())
        pos = decode(np.nan_to_num(f.astype(np.float64)))
        curve = metrics.pose_change_per_second(pos, MODEL_FPS)
        limb = per_second(bone_length_error(pos, skel, LIMB_MIN_LENGTH), MODEL_FPS)
        height = pos[:, 0, 1]
        diverged = (not finite or float(limb.max()) > BONE_ERROR_LIMIT
                    or not (HEIGHT_BAND[0] <= height.min() and height.max() <= HEIGHT_BAND[1]))
        runs.append({"style": seed["style"], "seed": seed["name"], "diverged": diverged, **judge(curve, ref[seed["style"]])})
    per_style = {}
    for style in STYLES:
        mine = [r for r in runs if r["style"] == style]
        per_style[style] = {"passes": sum(r["passes"] and not r["diverged"] for r in mine), "runs": len(mine),
                            "low_share_worst": max(r["low_share"] for r in mine),
                            "longest_low_s_worst": max(r["longest_low_s"] for r in mine),
                            "median_ratio_worst": min(r["median_ratio"] for r in mine),
                            "diverged": sum(r["diverged"] for r in mine)}
    valid = state.get("valid") or (state.get("history") or [{}])[-1].get("valid") or {}  # best.pt, else the last epoch
    return {"checkpoint": str(checkpoint), "iteration": state.get("iteration"), "frames": frames, "args": meta.get("args", {}),
            "valid": {s: valid.get(s) for s in STYLES} if valid else None, "real": ref, "per_style": per_style,
            "passes": sum(p["passes"] for p in per_style.values()), "runs": len(runs), "details": runs}


def summary_line(name: str, m: dict) -> str:
    cells = []
    for style in STYLES:
        p = m["per_style"][style]
        cells.append(f"{style} {p['passes']}/{p['runs']} low {p['low_share_worst']:.0%} "
                     f"longest {p['longest_low_s_worst']} s median {p['median_ratio_worst']:.0%}"
                     + (f" diverged {p['diverged']}" if p["diverged"] else ""))
    ac = "/".join(f"{m['valid'][s]['auto_conditioned']:.3f}" for s in STYLES) if m["valid"] else "-"
    return f"{name} (it {m['iteration']}): {m['passes']}/{m['runs']} pass; " + "; ".join(cells) + f"; valid ac {ac}"


def recipe(args: dict) -> str:
    """A training run's recipe in a few words, from its arguments."""
    parts = [f"{args.get('layers', 3)}x{args.get('hidden', 256)}",
             f"u={args.get('ground_truth', 5)} v={args.get('condition', 5)}"
             + (f"->{args['condition_max']}" if args.get("condition_max") else ""),
             f"lr {args.get('lr', 1e-3):g} x{args.get('decay', 0.95):g}/epoch"]
    if args.get("energy"):
        parts.append(f"energy {args['energy']:g}")
    noise = args.get("input_noise") or (0, 0)
    if any(noise):
        parts.append(f"input noise {noise[0]:g}->{noise[1]:g}")
    return ", ".join(parts)


def pilot_markdown(table: dict) -> str:
    """docs/models/aclstm-pilots.md: the real clips' reference, then one row per measured run."""
    if not table:
        return "# acLSTM pilots (issue 18)\n\nNo pilot measured yet.\n"
    first = next(iter(table.values()))
    lines = ["# acLSTM pilots (issue 18)", "",
             "Written by `python -m training.aclstm.pilot`. Each pilot is a short training run; its checkpoint rolls out "
             f"{first['frames']} self-fed frames in torch from 3 real seed motions per style (held-out clips), judged by the "
             "fairer freeze rule (`training/aclstm/freeze_rule.py`): a *low* second is below 20% of the style's real median "
             "pose change; a run passes when (a) its share of low seconds is at most twice the real clips' share, (b) no low "
             "stretch lasts 5 s or more, and (c) its median is at least 50% of the real median. Each style's cell gives the "
             "passes and, over its seeds, the worst low share, the longest low stretch and the lowest median (share of real).",
             "",
             "Real held-out clips, measured the same way (each clip alone): "
             + "; ".join(f"{s} median {r['median']:.3f} m/s, low share {r['low_share']:.1%}, longest low stretch "
                         f"{r['longest_low_s']} s, over {r['seconds']} s" for s, r in first["real"].items()) + ".", "",
             "| run | recipe | iterations | minutes | " + " | ".join(STYLES) + " | held-out loss, self-fed (" + "/".join(STYLES) + ") |",
             "|---|---|---|---|" + "---|" * len(STYLES) + "---|"]
    for name, m in table.items():
        cells = []
        for style in STYLES:
            p = m["per_style"][style]
            cells.append(f"{p['passes']}/{p['runs']}: {p['low_share_worst']:.0%} low, {p['longest_low_s_worst']} s, "
                         f"median {p['median_ratio_worst']:.0%}" + (f", {p['diverged']} diverged" if p["diverged"] else ""))
        valid = "/".join(f"{m['valid'][s]['auto_conditioned']:.3f}" for s in STYLES) if m.get("valid") else "—"
        minutes = m.get("summary", {}).get("minutes")
        lines.append(f"| {name} | {recipe(m.get('args', {}))} | {m['iteration']} | "
                     f"{'—' if minutes is None else f'{minutes:.0f}'} | " + " | ".join(cells) + f" | {valid} |")
    return "\n".join(lines) + "\n"
