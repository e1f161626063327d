"""The acLSTM dance set as joint positions, and the acLSTM feature layout (Zhou et al., "Data Representation").
The cache (cache/aclstm_positions.npz) is built by python -m training.data.build_dance, or on first use.
With extra=True, the set plus the two CMU trials it lacks (indian 01, martial 02: dance_extra.py brings them onto the
standard skeleton), always training clips, in their own cache (cache/aclstm_positions_extra.npz, --extra).

Every file in ../shared/mocap/aclstm/{salsa,indian,martial} is on one standard 57-point skeleton
(43 joints + 14 end sites). The BVH headers all say 120 fps, but the set's readme gives salsa at 60 fps
(28 files, 15 minutes, which only adds up at 60), so the readme's rate is used.

Features of frame t (model rate 30 fps, metres, y up):
    [r_x(t) - r_x(t-1), r_y(t), r_z(t) - r_z(t-1), p_j(t) - r(t) for the 56 other points]
The paper uses the root displacement in all three axes; here the root height is absolute, because an
integrated height drifts without bound over a 20,000-frame run. Joint offsets are in world axes (not the
body's heading frame), as in the paper, so training rotates every window about the vertical axis.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from .. import metrics
from ..mocap.bvh import global_transforms, load_bvh
from ..paths import DEFAULT_CACHE, resolve_mocap_dir
from .dance_extra import EXTRA_FILES, read_source, to_standard

STYLES = ("salsa", "indian", "martial")
SOURCE_FPS = {"salsa": 60.0, "indian": 120.0, "martial": 120.0}  # from aclstm/readme.txt
# 30 fps, not the paper's 60: at 60 fps the 5 self-fed frames of a u = v = 5 cycle span only 83 ms and a
# 100-frame window 1.7 s; at 30 fps they span 167 ms and 3.3 s for the same cost per iteration. The 60 fps
# model (2026-12-01, 7,181 iterations) froze in all 15 long runs.
MODEL_FPS = 30.0
CM = 0.01  # the set's BVH units are centimetres
CACHE = DEFAULT_CACHE / "aclstm_positions.npz"
EXTRA_CACHE = DEFAULT_CACHE / "aclstm_positions_extra.npz"  # the set and the two converted trials (extra=True)
EXTRA_DIR = "aclstm-extra/"  # the converted trials' files start so; they are never held out
# Every file of the acLSTM set starts with a T-pose frame and 2-5 frames blending out of it (joint speeds of
# 37-189 m/s; the first ordinary frame is at most 0.083 s in, measured 2026-12-05). load_clips drops this lead-in,
# so training windows, the real references (pose change and jitter: the lead-in had raised real jitter by 4-12%) and
# the jitter filter's spectrum see only the dance. The converted extra trials lose the same 0.1 s.
LEAD_IN_S = 0.1
# Held out per style for validation, the evaluation report and the browser's seed motions.
HELD_OUT = {"salsa": ("10", "20", "30"), "indian": ("15",), "martial": ("10",)}


@dataclass
class DanceSkeleton:
    names: list[str]
    parents: list[int]
    offsets: np.ndarray  # (points, 3) metres, from each point's parent in the rest pose

    def bone_lengths(self) -> np.ndarray:
        return np.linalg.norm(self.offsets, axis=1)

    def to_json(self) -> dict:
        return {"joints": self.names, "parents": self.parents,
                "offsets": [round(float(v), 6) for v in self.offsets.ravel()]}


@dataclass
class DanceClip:
    style: str
    file: str  # relative to the corpus root
    fps: float  # the source rate (SOURCE_FPS of its style)
    positions: np.ndarray  # (frames, 57, 3) world metres, feet on the floor
    held_out: bool
    lead_in_s: float = 0.0  # seconds dropped from the file's start (LEAD_IN_S): positions[0] is the file's time lead_in_s

    @property
    def seconds(self) -> float:
        return len(self.positions) / self.fps


def point_names(clip) -> list[str]:
    """Joint names, with end sites named after their parent (e.g. 'rThumb2_end')."""
    return [f"{clip.joints[j.parent].name}_end" if j.end_site else j.name for j in clip.joints]


def load_skeleton(mocap: Path) -> DanceSkeleton:
    clip = load_bvh(mocap / "aclstm" / "standard.bvh.gz")
    return DanceSkeleton(point_names(clip), [j.parent for j in clip.joints],
                         np.array([j.offset for j in clip.joints], dtype=np.float64) * CM)


def dance_files(mocap: Path) -> list[tuple[str, Path]]:
    files = [(s, p) for s in STYLES for p in sorted((mocap / "aclstm" / s).glob("*.bvh*"))]
    if not files:
        raise SystemExit(f"error: no acLSTM dance files under {mocap / 'aclstm'}")
    return files


def is_held_out(style: str, path: Path | str) -> bool:
    return Path(path).name.split(".")[0] in HELD_OUT[style]


def on_floor(pos: np.ndarray) -> np.ndarray:
    """The clip moved vertically so that the floor is at 0: the 10th percentile of the lowest point over the clip.
    Lower percentiles follow glitches: in indian/07 the feet dip 14 cm below their usual level in 3% of the frames."""
    pos = pos.copy()
    pos[..., 1] -= np.percentile(pos[..., 1].min(axis=1), 10)
    return pos


def extra_positions(mocap: Path, skel: DanceSkeleton) -> list[tuple[str, str, np.ndarray]]:
    """(style, file, positions) of the two converted CMU trials (dance_extra.py): world metres on the standard
    skeleton at the source rate (120 fps), feet on the floor."""
    return [(style, motion, on_floor(to_standard(read_source(mocap, motion, skeleton), skel.names, skel.parents,
                                                 skel.offsets)))
            for style, motion, skeleton in EXTRA_FILES]


def build_cache(mocap: Path, out: Path | None = None, extra: bool = False) -> Path:
    """World positions (metres) of every point of every clip at its source rate, feet on the floor; with `extra`,
    the two converted trials too (in EXTRA_CACHE unless `out` says otherwise)."""
    out = out or (EXTRA_CACHE if extra else CACHE)
    positions, table = [], []
    skel = load_skeleton(mocap)
    for style, path in tqdm(dance_files(mocap), desc="acLSTM dance files", unit="file"):
        clip = load_bvh(path)
        if point_names(clip) != skel.names:
            raise SystemExit(f"error: {path} is not on the standard acLSTM skeleton")
        _, pos = global_transforms(clip)
        pos = on_floor(pos * CM)
        table.append((style, f"aclstm/{style}/{path.name}", sum(len(p) for p in positions), len(pos)))
        positions.append(pos.astype(np.float32))
    for style, file, pos in (extra_positions(mocap, skel) if extra else []):
        table.append((style, file, sum(len(p) for p in positions), len(pos)))
        positions.append(pos.astype(np.float32))
    out.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(out, positions=np.concatenate(positions), style=[t[0] for t in table],
                        files=[t[1] for t in table], start=[t[2] for t in table], frames=[t[3] for t in table],
                        names=skel.names, parents=skel.parents, offsets=skel.offsets)
    return out


def load_clips(mocap_flag: str | None = None, extra: bool = False) -> tuple[DanceSkeleton, list[DanceClip]]:
    """The skeleton and every clip without its lead-in (LEAD_IN_S), from the cache (built first when missing); with
    `extra`, the two converted CMU trials too (training clips), from EXTRA_CACHE."""
    cache = EXTRA_CACHE if extra else CACHE
    if not cache.exists():
        build_cache(resolve_mocap_dir(mocap_flag), extra=extra)
    d = np.load(cache)
    skel = DanceSkeleton([str(n) for n in d["names"]], [int(p) for p in d["parents"]], d["offsets"])
    clips = []
    for style, file, start, frames in zip(d["style"], d["files"], d["start"], d["frames"]):
        style = str(style)
        fps = SOURCE_FPS[style]
        lead_in = int(round(LEAD_IN_S * fps))
        clips.append(DanceClip(style, str(file), fps, d["positions"][start + lead_in:start + frames].astype(np.float64),
                               not str(file).startswith(EXTRA_DIR) and is_held_out(style, str(file)), lead_in / fps))
    return skel, clips


def resample_positions(pos: np.ndarray, src_fps: float, start: float, count: int, speed: float = 1.0,
                       fps: float = MODEL_FPS) -> np.ndarray:
    """`count` frames at `fps` from source time `start` (s), played `speed` times as fast (linear interpolation)."""
    t = (start + np.arange(count) * speed / fps) * src_fps
    i = np.clip(np.floor(t).astype(int), 0, len(pos) - 2)
    w = np.clip(t - i, 0.0, 1.0)[:, None, None]
    return pos[i] * (1 - w) + pos[i + 1] * w


def rotate_y(pos: np.ndarray, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    out = pos.copy()
    out[..., 0] = c * pos[..., 0] + s * pos[..., 2]
    out[..., 2] = -s * pos[..., 0] + c * pos[..., 2]
    return out


def mirror_pairs(names: list[str]) -> np.ndarray:
    """Index of each point's left/right counterpart (itself on the midline): rShin <-> lShin, rightEye <-> leftEye,
    LeftUpLeg <-> RightUpLeg (the canonical skeleton's names)."""
    def other(n: str) -> str:
        for a, b in (("Left", "Right"), ("Right", "Left")):
            if n.startswith(a):
                return b + n[len(a):]
        if n.startswith("left"):
            return "right" + n[4:]
        if n.startswith("right"):
            return "left" + n[5:]
        if len(n) > 1 and n[0] in "lr" and n[1].isupper():
            return ("l" if n[0] == "r" else "r") + n[1:]
        return n
    return np.array([names.index(other(n)) for n in names])


def mirror(pos: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """The mirror image across the y-z plane: x negated and left and right points swapped."""
    out = pos[..., pairs, :].copy()
    out[..., 0] *= -1
    return out


def encode(pos: np.ndarray) -> np.ndarray:
    """Positions (frames, points, 3) -> features (frames - 1, 3 * points); frame k of the output is frame k + 1."""
    root = pos[:, 0]
    step = root[1:] - root[:-1]
    first = np.stack([step[:, 0], root[1:, 1], step[:, 2]], axis=1)
    rel = (pos[1:, 1:] - root[1:, None]).reshape(len(pos) - 1, -1)
    return np.concatenate([first, rel], axis=1)


def decode(feats: np.ndarray, start_xz=(0.0, 0.0)) -> np.ndarray:
    """Features (frames, 3 * points) -> world positions (frames, points, 3); the root starts at start_xz."""
    n = len(feats)
    root = np.zeros((n, 3))
    root[:, 0] = start_xz[0] + np.cumsum(feats[:, 0])
    root[:, 1] = feats[:, 1]
    root[:, 2] = start_xz[1] + np.cumsum(feats[:, 2])
    rel = feats[:, 3:].reshape(n, -1, 3)
    return np.concatenate([root[:, None], root[:, None] + rel], axis=1)


LIMB_MIN_LENGTH = 0.15  # bones at least this long: spine, neck, collars, upper and lower arms and legs (11 bones)


def bone_length_error(pos: np.ndarray, skel: DanceSkeleton, min_length: float = 0.02) -> np.ndarray:
    """Per frame: mean |predicted bone length / true length - 1| over bones longer than `min_length`."""
    lengths = skel.bone_lengths()
    bones = [j for j in range(1, len(skel.parents)) if lengths[j] > min_length]
    parents = [skel.parents[j] for j in bones]
    got = np.linalg.norm(pos[:, bones] - pos[:, parents], axis=-1)
    return np.abs(got / lengths[bones] - 1).mean(axis=1)


def held_out_pose_change(clips: list[DanceClip], style: str) -> list[np.ndarray]:
    """Per-second pose change (m/s, joints relative to the root) of each real held-out clip of `style`, at the
    model's rate, one curve per clip (clips are measured one by one, never joined)."""
    curves = []
    for c in clips:
        if c.style == style and c.held_out:
            pos = resample_positions(c.positions, c.fps, 0.0, int(len(c.positions) / c.fps * MODEL_FPS) - 1)
            curves.append(metrics.pose_change_per_second(pos, MODEL_FPS))
    return curves


def real_pose_change(clips: list[DanceClip], styles: tuple[str, ...] | list[str] = STYLES) -> dict:
    """Median per-second pose change (m/s) of the real held-out clips, per style."""
    return {style: round(float(np.median(np.concatenate(held_out_pose_change(clips, style)))), 4) for style in styles}
