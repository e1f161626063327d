"""The corpus measured on the canonical skeleton (docs/data.md, written by python -m training.data.report).

Per category: clips, minutes, how well the feet meet the floor after retargeting, and how often each foot
is labelled as planted. Every CMU clip is loaded at its native 120 fps. The Bandai Namco set is measured on its
cache (training/data/bandai.py, 30 fps), per content and style, with the combined locomotion corpus's split.
"""
from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..mocap.rotations import matrix_to_rotvec, quat_to_matrix
from ..mocap.skeleton import GROUND_POINTS, canonical_skeleton
from .bandai import CONTENTS, LICENCE, STYLES, BandaiClip, is_held_out
from .cmu import CATEGORIES, clip_contacts, load_clip, read_index
from .features import mean_rotation
from .locomotion import LocomotionClip, is_validation


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


def _floor_windows(positions: np.ndarray, fps: float, ground: list[int]) -> np.ndarray:
    low = positions[:, ground, 1].min(axis=1)
    step = int(round(fps))
    return np.array([low[a:a + step].min() for a in range(0, len(low), step)])


SPREAD_JOINTS = ("Head", "Head_end", "LeftToeBase_end", "Neck1", "Neck", "LeftToeBase", "LeftForeArm")


def _rotation_spread(rotations: np.ndarray, skel) -> dict[str, float]:
    """Per joint of SPREAD_JOINTS: the root mean square angle (degrees) of its local rotations (frames, joints, 4)
    from their chordal mean."""
    mats = quat_to_matrix(rotations)
    out = {}
    for name in SPREAD_JOINTS:
        m = mats[:, skel.index(name)]
        v = matrix_to_rotvec(np.swapaxes(mean_rotation(m), -1, -2) @ m)
        out[name] = float(np.degrees(np.sqrt((v ** 2).sum(axis=-1).mean())))
    return out


def locomotion_report(cmu: list[LocomotionClip], bandai: list[BandaiClip], fps: float = 30.0) -> str:
    """The combined locomotion corpus (CMU walk and run from cache/cmu_walk-run_30fps.npz, the Bandai Namco set from
    cache/bandai_30fps.npz): minutes and held-out clips per corpus, content and style, the Bandai clips' floor and
    contacts, what the Bandai skeleton lacks and the licence."""
    skel = canonical_skeleton()
    ground = [skel.index(n) for n in GROUND_POINTS]
    minutes = lambda clips: sum(c.frames for c in clips) / fps / 60
    lines = [
        "## The locomotion corpus: CMU and Bandai Namco",
        "",
        "What the locomotion models can train on (issue 39), at 30 fps on the canonical skeleton: CMU walking and",
        "running (`python -m training.data.build_locomotion`, `cache/cmu_walk-run_30fps.npz`) and the Bandai Namco",
        "stylised locomotion set (`python -m training.data.build_bandai`, `cache/bandai_30fps.npz`,",
        "`training/data/bandai.py`). Held out: every 8th clip by file name, per CMU category and per Bandai content and",
        "style (rank % 8 == 3); `bandai.as_locomotion_clip` hands Bandai clips to `data/locomotion.py`'s `Corpus` with",
        "that rank, so its own rule holds out the same clips. The `Corpus` adds a mirrored copy (`features.mirror_clip`:",
        "left and right swapped, x → −x) of every training clip it is given, CMU's today and Bandai's through",
        "`as_locomotion_clip`, so a left turn also trains a right turn (`tests/python/test_bandai.py`).",
        "",
        "| corpus | content | clips | minutes | held-out clips | held-out minutes |",
        "|---|---|---|---|---|---|",
    ]
    for cat in ("walk", "run"):
        group = [c for c in cmu if c.category == cat]
        held = [c for c in group if is_validation(c)]
        lines.append(f"| CMU | {cat} | {len(group)} | {minutes(group):.1f} | {len(held)} | {minutes(held):.1f} |")
    for content in CONTENTS:
        group = [c for c in bandai if c.content == content]
        held = [c for c in group if is_held_out(c.rank)]
        lines.append(f"| Bandai Namco | {content} | {len(group)} | {minutes(group):.1f} | {len(held)} | {minutes(held):.1f} |")
    held_cmu = [c for c in cmu if is_validation(c)]
    held_b = [c for c in bandai if is_held_out(c.rank)]
    lines += [
        f"| **all** | | {len(cmu) + len(bandai)} | {minutes(cmu) + minutes(bandai):.1f} | {len(held_cmu) + len(held_b)} "
        f"| {minutes(held_cmu) + minutes(held_b):.1f} |",
        "",
        f"Running: {minutes([c for c in cmu if c.category == 'run']):.1f} min of CMU, "
        f"{minutes([c for c in bandai if c.content == 'run']):.1f} min of Bandai Namco.",
        "",
        "### Bandai Namco per style (minutes; held-out clips in brackets)",
        "",
        "| style | " + " | ".join(CONTENTS) + " | all | 1-s windows: lowest foot point within ±3 cm | foot planted, walk / run (mean share per foot) |",
        "|---|" + "---|" * (len(CONTENTS) + 3),
    ]
    for style in STYLES:
        cells = []
        for content in CONTENTS:
            group = [c for c in bandai if c.style == style and c.content == content]
            cells.append(f"{minutes(group):.1f} ({sum(is_held_out(c.rank) for c in group)})")
        group = [c for c in bandai if c.style == style]
        windows = np.concatenate([_floor_windows(c.positions, fps, ground) for c in group])
        walk = np.mean([c.contacts.mean(axis=0) for c in group if c.category == "walk"])
        run = np.mean([c.contacts.mean(axis=0) for c in group if c.category == "run"])
        cells += [f"{minutes(group):.1f} ({sum(is_held_out(c.rank) for c in group)})",
                  f"{np.mean(np.abs(windows) < 0.03):.1%}", f"{walk:.0%} / {run:.0%}"]
        lines.append(f"| {style} | " + " | ".join(cells) + " |")
    lines += [
        "",
        "### What the Bandai Namco skeleton lacks",
        "",
        "Its 22 joints (`joint_Root` on the floor, `Hips`, `Spine`, `Chest`, `Neck`, `Head`, `Shoulder`, `UpperArm`,",
        "`LowerArm`, `Hand`, `UpperLeg`, `LowerLeg`, `Foot`, `Toes` per side) go onto the canonical 25 points by the",
        "humanoid mapper (scheme \"Bandai Namco\", `mocap/canonical_points.py`, as a user's files do). 19 points are",
        "mapped: Hips; LeftUpLeg, LeftLeg, LeftFoot, LeftToeBase ← UpperLeg_L, LowerLeg_L, Foot_L, Toes_L (and the",
        "right side); Spine ← Spine, Spine1 ← Chest, Neck ← Neck, Head ← Head (its End Site, at a zero offset); LeftArm,",
        "LeftForeArm, LeftHand ← UpperArm_L, LowerArm_L, Hand_L (and the right side). 6 are derived, as the page derives",
        "them (`web/motion/skeletonMap.ts`):",
        "",
        "- the toe tips `LeftToeBase_end`, `RightToeBase_end` (no toe End Site offset): 1.5 × ankle → toe base, so",
        "  the toe segment continues the foot's toe line and has no bend of its own;",
        "- the hand tips `LeftHand_end`, `RightHand_end` (no fingers): 1.3 × elbow → wrist. These are fixed joints for",
        "  every corpus (`FIXED_JOINTS`: held at their reference, no features);",
        "- `Neck1` (no upper-neck bone): halfway from Neck to Head, and `Head_end` (no head top): 1.5 × Neck → Head, so",
        "  the upper neck and the head lie on the neck's line: no nod of the head against the neck.",
        "",
        "Not lacking, though the bones differ from CMU's: there is no separate lower back (CMU's LowerBack, Spine,",
        "Spine1 are three; the canonical skeleton keeps two spine points, which Spine and Chest fill) and no hip-joint",
        "bones (the canonical hip points are the leg roots, UpperLeg_L/R; the pelvis → hip segments are fixed joints",
        "in every corpus). The clavicles (`Shoulder_L/R`) have no canonical point and are dropped (the canonical arms",
        "hang from the Neck point).",
        "",
        "How the features deal with it: the feature row keeps every non-fixed joint's rotation for both corpora. On",
        "Bandai clips the derived segments' directions follow from the mapped points (toe tip along the toe, upper",
        "neck and head along the neck) and their twist is the IK prior's most likely one (`mocap/canonical_ik.py`), so",
        "the rotations of the segments ending at Head, Head_end and the toe tips stay at one value in every Bandai frame while CMU clips move",
        "them (the neck's bend goes to `Neck1`'s rotation, whose segment carries the Neck → Head line). Spread of each",
        "joint's local rotation about its mean (root mean square angle, degrees; `Neck`, `LeftToeBase` and",
        "`LeftForeArm`, mapped in both, for comparison):",
        "",
        "| joint | CMU | Bandai Namco |",
        "|---|---|---|",
    ]
    cmu_spread = _rotation_spread(np.concatenate([c.rotations for c in cmu]), skel)
    bandai_spread = _rotation_spread(np.concatenate([c.rotations for c in bandai]), skel)
    lines += [f"| `{name}` | {cmu_spread[name]:.1f} | {bandai_spread[name]:.1f} |" for name in SPREAD_JOINTS]
    lines += [
        "",
        "A corpus or style input lets a model tell the two apart instead of averaging a moving head and toe tip",
        "(CMU) with a still one (Bandai). Nothing else is filled in.",
        "",
        "### Licence",
        "",
        f"The Bandai Namco set is **{LICENCE}** (Bandai-Namco-Research-Motiondataset © 2022 Bandai Namco Research",
        "Inc., https://github.com/BandaiNamcoResearchInc/Bandai-Namco-Research-Motiondataset; Kobayashi et al.,",
        "arXiv:2306.08861, 2023). **Any model trained on it is non-commercial**, and must say so where it is offered;",
        "the CMU-only models stay available. The CMU data is free for commercial use. The files stay in",
        "`../shared/mocap/bandai` and are never copied into the repository; the cache in `cache/` is not in git.",
        "",
    ]
    return "\n".join(lines)
