"""The CMU corpus on the canonical skeleton: the clip index, one clip loaded and retargeted, and the cached
arrays of many clips (built by python -m training.data.build_locomotion).

A cache is one .npz with every clip concatenated (root, local rotations, positions, contacts) plus a clip
table, so training scripts never parse mocap files. Caches live in cache/ (not in git).
"""
from __future__ import annotations

import csv
import json
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..mocap.contacts import contacts_for
from ..mocap.files import MotionFormatError
from ..mocap.resample import resample
from ..mocap.retarget import CanonicalClip, retarget, source_from_amc, source_from_cmu_bvh
from ..mocap.skeleton import FOOT_POINTS, canonical_skeleton

CATEGORIES = ("walk", "run", "jump", "dance", "other")


@dataclass
class ClipInfo:
    """One row of cmu/index.tsv."""
    file: str  # relative to the corpus root
    subject: str
    trial: str
    fps: float
    category: str
    description: str


@dataclass
class CachedClip:
    """One row of a cache's clip table: which frames of the concatenated arrays belong to which clip."""
    file: str
    subject: str
    category: str
    description: str
    start: int
    frames: int


@dataclass
class LocomotionCache:
    """A built cache: the clip table and the concatenated per-frame arrays."""
    fps: float
    joints: list[str]
    clips: list[CachedClip]
    root: np.ndarray       # (frames, 3) metres
    rotations: np.ndarray  # (frames, joints, 4) local quaternions
    positions: np.ndarray  # (frames, joints, 3) metres
    contacts: np.ndarray   # (frames, 2) left, right


def read_index(mocap: Path) -> list[ClipInfo]:
    with open(mocap / "cmu" / "index.tsv", newline="") as f:
        rows = list(csv.DictReader(f, delimiter="\t"))
    return [ClipInfo(r["file"], r["subject"], r["trial"], float(r["fps"]), r["category"], r["description"]) for r in rows]


def load_clip(mocap: Path, info: ClipInfo, fps: float | None = None) -> CanonicalClip:
    """One corpus clip on the canonical skeleton, resampled to `fps` when given."""
    path = mocap / info.file
    if info.file.endswith((".amc", ".amc.gz")):
        src = source_from_amc(mocap / "cmu" / "asf" / f"{info.subject}.asf", path, info.fps)
    else:
        src = source_from_cmu_bvh(path)
    clip = retarget(src)
    return resample(clip, fps) if fps else clip


def clip_contacts(clip: CanonicalClip) -> np.ndarray:
    return contacts_for(clip.positions, canonical_skeleton().joints, clip.fps, FOOT_POINTS)


def cache_name(fps: float, categories: list[str]) -> str:
    return f"cmu_{'-'.join(categories)}_{fps:g}fps.npz"


def build_cache(mocap: Path, fps: float, categories: list[str], out: Path) -> Path:
    """Load every clip of `categories` at `fps` and write them to out/cache_name(...); returns the path."""
    infos = [i for i in read_index(mocap) if i.category in categories]
    if not infos:
        raise SystemExit(f"error: no clips in categories {categories} under {mocap}")
    arrays: dict[str, list[np.ndarray]] = {"root": [], "rotations": [], "positions": [], "contacts": []}
    table = []
    start = 0
    for info in tqdm(infos, desc=f"clips -> {fps:g} fps", unit="clip"):
        try:
            clip = load_clip(mocap, info, fps)
        except MotionFormatError as err:
            tqdm.write(f"skipped {info.file}: {err}")
            continue
        arrays["root"].append(clip.root.astype(np.float32))
        arrays["rotations"].append(clip.rotations.astype(np.float32))
        arrays["positions"].append(clip.positions.astype(np.float32))
        arrays["contacts"].append(clip_contacts(clip))
        table.append(CachedClip(info.file, info.subject, info.category, info.description, start, clip.frames))
        start += clip.frames
    out.mkdir(parents=True, exist_ok=True)
    path = out / cache_name(fps, categories)
    np.savez_compressed(path, fps=np.float32(fps), clips=json.dumps([asdict(c) for c in table]),
                        joints=json.dumps(canonical_skeleton().joints), **{k: np.concatenate(v) for k, v in arrays.items()})
    seconds = start / fps
    print(f"wrote {path} ({len(table)} clips, {start} frames, {seconds / 60:.1f} min)")
    return path


def load_cache(path: Path) -> LocomotionCache:
    with np.load(path) as data:
        return LocomotionCache(fps=float(data["fps"]), joints=json.loads(str(data["joints"])),
                               clips=[CachedClip(**c) for c in json.loads(str(data["clips"]))],
                               root=data["root"], rotations=data["rotations"], positions=data["positions"],
                               contacts=data["contacts"])
