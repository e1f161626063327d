"""The Bandai Namco stylised locomotion set (../shared/mocap/bandai, CC BY-NC 4.0: any model trained on it is
non-commercial) on the canonical skeleton: the clip index, one clip mapped, the cache of all clips (built by
python -m training.data.build_bandai) and the split by clip.

Each file goes through training/mocap/canonical_points.py as a user's file does: the humanoid mapper's points (the
Bandai names are one of its schemes), the six points the skeleton lacks derived (toe and hand tips, the upper neck
point and the head top; docs/data.md), scaled by leg length onto the canonical skeleton, rotations by the canonical IK,
put on the floor, foot contacts. The files are 30 fps already.

Held out: within each content and style, every 8th clip by file name (rank % 8 == 3, CMU's rule in
data/locomotion.py), so every style keeps clips of every content it has for validation.

A cache is one .npz with every clip concatenated (root, local rotations, positions, contacts) plus a clip table
(file, content, style, start, frames), as data/cmu.py's; caches live in cache/ (not in git).
"""
from __future__ import annotations

import csv
import json
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..mocap.canonical_ik import CanonicalIK
from ..mocap.canonical_points import MappedClip, canonical_clip, make_ik, map_skeleton, read_bvh
from ..mocap.skeleton import Skeleton, canonical_skeleton
from ..paths import DEFAULT_CACHE, resolve_mocap_dir
from .locomotion import LocomotionClip

FPS = 30.0
CONTENTS = ("walk", "walk-turn-left", "walk-turn-right", "run")
STYLES = ("active", "elderly", "exhausted", "feminine", "masculine", "normal", "youthful")
HELD_OUT_EVERY, HELD_OUT_AT = 8, 3
LICENCE = "CC BY-NC 4.0"
CACHE_NAME = f"bandai_{FPS:g}fps.npz"


@dataclass
class BandaiInfo:
    """One row of bandai/index.tsv."""
    file: str  # relative to bandai/bvh
    content: str
    style: str
    frames: int
    fps: float


@dataclass
class BandaiCachedClip:
    """One row of a cache's clip table."""
    file: str
    content: str
    style: str
    start: int
    frames: int


@dataclass
class BandaiClip:
    """One clip on the canonical skeleton at 30 fps, with its labels and its rank within its content and style."""
    file: str
    content: str
    style: str
    rank: int
    root: np.ndarray       # (frames, 3) metres
    rotations: np.ndarray  # (frames, joints, 4) local quaternions
    positions: np.ndarray  # (frames, joints, 3) metres, feet on the floor
    contacts: np.ndarray   # (frames, 2) left, right

    @property
    def frames(self) -> int:
        return len(self.root)

    @property
    def category(self) -> str:
        """CMU's category names: run, or walk (straight walks and walking turns)."""
        return "run" if self.content == "run" else "walk"


def read_index(mocap: Path) -> list[BandaiInfo]:
    with open(mocap / "bandai" / "index.tsv", newline="") as f:
        rows = list(csv.DictReader(f, delimiter="\t"))
    infos = [BandaiInfo(r["file"], r["content"], r["style"], int(r["frames"]), float(r["fps"])) for r in rows]
    for i in infos:
        if i.content not in CONTENTS or i.style not in STYLES:
            raise ValueError(f"bandai/index.tsv: {i.file}: unknown content {i.content!r} or style {i.style!r}")
    return infos


def is_held_out(rank: int) -> bool:
    """Whether the clip of this rank (by file name, within its content and style) is held out."""
    return rank % HELD_OUT_EVERY == HELD_OUT_AT


def ranks(rows: list[BandaiInfo] | list[BandaiCachedClip]) -> dict[str, int]:
    """Each file's rank by name within its content and style."""
    out: dict[str, int] = {}
    for content in CONTENTS:
        for style in STYLES:
            group = sorted(r.file for r in rows if r.content == content and r.style == style)
            out.update({f: k for k, f in enumerate(group)})
    return out


class BandaiReader:
    """Maps Bandai files onto the canonical skeleton with one IK (its prior read once)."""

    def __init__(self, mocap: Path, skel: Skeleton | None = None, ik: CanonicalIK | None = None):
        self.mocap = mocap
        self.skel = skel or canonical_skeleton()
        self.ik = ik or make_ik(self.skel)

    def load(self, info: BandaiInfo, fps: float = FPS) -> MappedClip:
        raw = read_bvh(self.mocap / "bandai" / "bvh" / info.file, info.file)
        mapping = map_skeleton(raw, self.skel.leg_length)
        if mapping.humanoid.scheme != "Bandai Namco":
            raise ValueError(f"{info.file}: mapped as {mapping.scheme}, not as the Bandai Namco skeleton")
        return canonical_clip(raw, mapping, fps, self.ik, self.skel)


def build_cache(mocap: Path, out: Path, fps: float = FPS, limit: int | None = None) -> Path:
    """Every clip of the index (the first `limit` per content and style when given) at `fps`, written to
    out/CACHE_NAME (or a name marking the limit); returns the path."""
    infos = read_index(mocap)
    if limit is not None:
        rank = ranks(infos)
        infos = [i for i in infos if rank[i.file] < limit]
    reader = BandaiReader(mocap)
    arrays: dict[str, list[np.ndarray]] = {"root": [], "rotations": [], "positions": [], "contacts": []}
    table, start, t0 = [], 0, time.time()
    for info in tqdm(infos, desc=f"bandai -> {fps:g} fps", unit="clip"):
        clip = reader.load(info, fps)
        arrays["root"].append(clip.root.astype(np.float32))
        arrays["rotations"].append(clip.rotations.astype(np.float32))
        arrays["positions"].append(clip.positions.astype(np.float32))
        arrays["contacts"].append(clip.contacts.astype(np.uint8))
        table.append(BandaiCachedClip(info.file, info.content, info.style, start, clip.frames))
        start += clip.frames
    out.mkdir(parents=True, exist_ok=True)
    name = CACHE_NAME if limit is None and fps == FPS else f"bandai_{fps:g}fps" + (f"_first{limit}" if limit else "") + ".npz"
    path = out / name
    np.savez_compressed(path, fps=np.float32(fps), clips=json.dumps([asdict(c) for c in table]), licence=LICENCE,
                        joints=json.dumps(canonical_skeleton().joints), **{k: np.concatenate(v) for k, v in arrays.items()})
    print(f"wrote {path} ({len(table)} clips, {start} frames, {start / fps / 60:.1f} min) in {time.time() - t0:.0f} s")
    return path


def clips_from_cache(path: Path) -> list[BandaiClip]:
    """The clips of a built cache, with their ranks."""
    with np.load(path) as data:
        table = [BandaiCachedClip(**c) for c in json.loads(str(data["clips"]))]
        root, rot, pos, con = data["root"], data["rotations"], data["positions"], data["contacts"]
    rank = ranks(table)
    return [BandaiClip(c.file, c.content, c.style, rank[c.file],
                       root=root[c.start:c.start + c.frames].astype(np.float64),
                       rotations=rot[c.start:c.start + c.frames].astype(np.float64),
                       positions=pos[c.start:c.start + c.frames].astype(np.float64),
                       contacts=con[c.start:c.start + c.frames]) for c in table]


def as_locomotion_clip(clip: BandaiClip) -> LocomotionClip:
    """The clip as data/locomotion.py's Corpus takes it (mirrored and speed-changed copies for training): category walk
    or run, the style as its subject, the content as its description, and its rank within content and style, so the
    Corpus's held-out rule (rank % 8 == 3) is this module's."""
    return LocomotionClip(clip.file, clip.style, clip.category, clip.content, clip.rank,
                          root=clip.root, rotations=clip.rotations, contacts=clip.contacts)


def load_clips(mocap_flag: str | None = None) -> list[BandaiClip]:
    """Every Bandai clip at 30 fps, from the cache (built first when missing: about 10 minutes on one core)."""
    path = DEFAULT_CACHE / CACHE_NAME
    if not path.exists():
        build_cache(resolve_mocap_dir(mocap_flag), DEFAULT_CACHE)
    return clips_from_cache(path)
