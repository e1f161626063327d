"""The check of dance_extra.py's conversion against the acLSTM set (docs/data.md, "The two extra dance trials").

The CMU originals of the acLSTM clips are not in the corpus, so a converted clip cannot be compared frame by frame
with an acLSTM conversion of the same trial. What can be checked: per-clip statistics of each converted trial against
the acLSTM clips of the same subject (indian 04-15 for 94_01, martial 03-10 for 135_02), and the T-pose that every
acLSTM file begins with (the standard's rest pose) against CMU's own rest pose (135.asf, a T-pose) converted.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .. import metrics
from ..mocap import asf_amc
from .dance import MODEL_FPS, DanceClip, DanceSkeleton, load_clips, resample_positions
from .dance_extra import EXTRA_FILES, SourceMotion, correspondence, read_source, rest_positions, to_standard

FEET = ("lFoot", "rFoot", "lFoot_end", "rFoot_end")


def _angle(pos: np.ndarray, a: int, b: int, c: int) -> np.ndarray:
    u, v = pos[:, a] - pos[:, b], pos[:, c] - pos[:, b]
    cos = (u * v).sum(-1) / np.linalg.norm(u, axis=-1) / np.linalg.norm(v, axis=-1)
    return np.degrees(np.arccos(np.clip(cos, -1, 1)))


def clip_measures(pos: np.ndarray, fps: float, skel: DanceSkeleton) -> dict[str, float]:
    """One clip (frames, 57, 3), world metres, feet on the floor, at `fps`."""
    n = skel.names.index
    bones = np.linalg.norm(pos[:, 1:] - pos[:, skel.parents[1:]], axis=-1)
    speed = np.linalg.norm(np.diff(pos, axis=0), axis=-1) * fps
    lowest = pos[..., 1].min(axis=1)
    knee = np.concatenate([_angle(pos, n(f"{s}Thigh"), n(f"{s}Shin"), n(f"{s}Foot")) for s in "lr"])
    elbow = np.concatenate([_angle(pos, n(f"{s}Shldr"), n(f"{s}ForeArm"), n(f"{s}Hand")) for s in "lr"])
    p30 = resample_positions(pos, fps, 0.0, int(len(pos) / fps * MODEL_FPS) - 1)
    return {
        "frames": len(pos),
        "bone_mm": float(np.abs(bones - skel.bone_lengths()[1:]).max() * 1000),
        "hip_p5": float(np.percentile(pos[:, 0, 1], 5)), "hip_p50": float(np.median(pos[:, 0, 1])),
        "hip_p95": float(np.percentile(pos[:, 0, 1], 95)),
        "speed_p50": float(np.median(speed)), "speed_p95": float(np.percentile(speed, 95)),
        "lowest_cm": float(np.median(lowest) * 100),
        "foot_lowest": float(np.isin(pos[..., 1].argmin(axis=1), [n(f) for f in FEET]).mean() * 100),
        "knee_p50": float(np.median(knee)), "knee_p99": float(np.percentile(knee, 99)),
        "elbow_p50": float(np.median(elbow)), "elbow_p99": float(np.percentile(elbow, 99)),
        "pose_change": float(np.median(metrics.pose_change_per_second(p30, MODEL_FPS))),
    }


def rest_source(mocap: Path, motion: str, skeleton: str) -> tuple[SourceMotion, SourceMotion]:
    """The clip and its skeleton's rest pose (all AMC values zero: CMU's T-pose) as one frame."""
    src = read_source(mocap, motion, skeleton)
    skel = asf_amc.load_asf(mocap / skeleton)
    zero = asf_amc.AmcMotion(1, {b: np.zeros((1, v.shape[1])) for b, v in asf_amc.load_amc(mocap / motion, skel).values.items()})
    _, rots = asf_amc.global_rotations(skel, zero)
    names, pos = asf_amc.positions(skel, zero)
    rest = SourceMotion("rest", src.fps, names, src.parents, pos, np.stack([rots[b] for b in names], axis=1), src.rest)
    return src, rest


def extra_check(mocap: Path, mocap_flag: str | None = None) -> dict:
    """The numbers of docs/data.md's section: per style, the converted trial's measures and the same subject's
    acLSTM clips' (their T-pose frame 0 left out), and the T-pose comparisons."""
    skel, clips = load_clips(mocap_flag, extra=True)
    rest = rest_positions(skel.parents, skel.offsets)
    out: dict = {"styles": {}}
    for style, motion, _ in EXTRA_FILES:
        mine = [c for c in clips if c.file == motion]
        theirs = [c for c in clips if c.style == style and c.file.startswith("aclstm/")]
        out["styles"][style] = {
            "file": motion, "converted": clip_measures(mine[0].positions, mine[0].fps, skel),
            "acLSTM": [clip_measures(c.positions[1:], c.fps, skel) for c in theirs],
            "acLSTM_files": [Path(c.file).name.split(".")[0] for c in theirs]}
    set_clips: list[DanceClip] = [c for c in clips if c.file.startswith("aclstm/")]
    first = np.array([np.linalg.norm((c.positions[0] - c.positions[0, :1]) - (rest - rest[:1]), axis=-1).max()
                      for c in set_clips])
    jump = np.array([np.linalg.norm(c.positions[1] - c.positions[0], axis=-1).max() for c in set_clips])
    out["tpose"] = {"clips": len(set_clips), "frame0_vs_rest_cm_max": float(first.max() * 100),
                    "frame0_vs_rest_cm_median": float(np.median(first) * 100),
                    "jump_cm_median": float(np.median(jump) * 100), "jump_cm_max": float(jump.max() * 100)}
    style, motion, skeleton = next(f for f in EXTRA_FILES if f[2])
    src, zero = rest_source(mocap, motion, skeleton)
    pairs = correspondence(src, skel.names, skel.parents, skel.offsets)
    got = to_standard(zero, skel.names, skel.parents, skel.offsets, pairs)[0]
    d = np.linalg.norm((got - got[:1]) - (rest - rest[:1]), axis=-1)
    legs = np.array([any(k in n for k in ("Thigh", "Shin", "Foot")) for n in skel.names])
    out["cmu_tpose"] = {"upper_cm_max": float(d[~legs].max() * 100), "upper_cm_mean": float(d[~legs].mean() * 100),
                        "legs_cm_max": float(d[legs].max() * 100)}
    return out


COLUMNS = (("frames", "frames", "{:.0f}"), ("bone_mm", "bone error mm", "{:.1g}"),
           ("hip_p5", "hips p5 m", "{:.2f}"), ("hip_p50", "hips p50 m", "{:.2f}"), ("hip_p95", "hips p95 m", "{:.2f}"),
           ("speed_p50", "speed p50 m/s", "{:.2f}"), ("speed_p95", "speed p95 m/s", "{:.2f}"),
           ("lowest_cm", "lowest point p50 cm", "{:.1f}"), ("foot_lowest", "lowest is a foot %", "{:.0f}"),
           ("knee_p50", "knee p50°", "{:.0f}"), ("knee_p99", "knee p99°", "{:.0f}"),
           ("elbow_p50", "elbow p50°", "{:.0f}"), ("elbow_p99", "elbow p99°", "{:.0f}"),
           ("pose_change", "pose change m/s", "{:.2f}"))


def extra_report(check: dict) -> str:
    """docs/data.md's section on the two extra trials, from extra_check."""
    lines = [
        "## The two extra dance trials (../shared/mocap/aclstm-extra/)",
        "",
        "The acLSTM set lacks twelve of its CMU trials; two come as other conversions: indian 01 (CMU 94_01, the 3ds "
        "Max-friendly BVH) and martial 02 (CMU 135_02, ASF/AMC). `training/data/dance_extra.py` brings them onto the "
        "set's standard skeleton, at 120 fps, one frame per source frame (no T-pose frame): the humanoid mapper pairs "
        "the points; limb bones turn with their source bone from the rest pose with one rest correction per limb (the "
        "thigh and upper arm point exactly where the source's do, and the standard's rest bends stay: its elbow is "
        "bent 17° at rest, and no acLSTM elbow straightens past 157°); spine, chest and neck bones lie along the "
        "source's; collars, buttocks, eyes and fingers ride on the pelvis, chest, head and forearm frames; the root is "
        "the source's hip-socket midpoint scaled by the leg-length ratio. `load_clips(extra=True)` (and "
        "`build_dance --extra`) adds them as training clips, never held out, in `cache/aclstm_positions_extra.npz`; "
        "the default stays the set alone.",
        "",
        "The CMU originals of the acLSTM clips are not in the corpus, so the check is statistical: each converted "
        "trial against the acLSTM clips of the same subject (min–max over those clips; their T-pose frame 0 left "
        "out). Positions in metres, feet on the floor by the set's rule, speeds over all 57 points at 120 fps, pose "
        "change per second at 30 fps (the freeze rule's measure).",
        "",
    ]
    heads = [h for _, h, _ in COLUMNS]
    lines += ["| clip | " + " | ".join(heads) + " |", "|---" * (len(heads) + 1) + "|"]
    for style, s in check["styles"].items():
        conv = s["converted"]
        lines.append(f"| {style} {Path(s['file']).name.split('.')[0]} (converted) | "
                     + " | ".join(f.format(conv[k]) for k, _, f in COLUMNS) + " |")
        files = s["acLSTM_files"]
        cells = []
        for k, _, f in COLUMNS:
            vals = [m[k] for m in s["acLSTM"]]
            cells.append(f"{f.format(min(vals))}–{f.format(max(vals))}")
        lines.append(f"| {style} {files[0]}–{files[-1]} acLSTM ({len(files)} clips) | " + " | ".join(cells) + " |")
    t, c = check["tpose"], check["cmu_tpose"]
    lines += [
        "",
        f"Every acLSTM file begins with a T-pose, the standard's rest pose to within {t['frame0_vs_rest_cm_max']:.1f} cm "
        f"(median {t['frame0_vs_rest_cm_median']:.1f} cm over the {t['clips']} clips), and jumps from it into the dance "
        f"on frame 1 (some point moves {t['jump_cm_median']:.0f} cm in the median clip, up to {t['jump_cm_max']:.0f} cm); "
        "the set's cache keeps that frame. CMU's own T-pose (135.asf's rest pose) converted lands on the standard's "
        f"T-pose to within {c['upper_cm_max']:.1f} cm above the hips (mean {c['upper_cm_mean']:.1f} cm); the legs differ "
        f"by up to {c['legs_cm_max']:.0f} cm because CMU's rest pose spreads the thighs 20° apart, where the standard's "
        "hang straight (in motion the converted thighs follow the source's).",
        "",
    ]
    return "\n".join(lines)
