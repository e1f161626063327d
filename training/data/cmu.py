"""Build cached arrays of the CMU corpus on the canonical skeleton.

    python -m training.dataset [--fps 30] [--categories walk,run] [--mocap DIR] [--out cache/]

Writes one .npz with every clip concatenated (root, local rotations, positions, contacts) plus a
clip table, so training scripts never parse mocap files. Caches live in cache/ (not in git).
"""
from __future__ import annotations

import argparse
import csv
import json
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..mocap.contacts import contacts_for
from ..mocap.files import MotionFormatError
from ..paths import DEFAULT_CACHE, add_mocap_argument, resolve_mocap_dir
from ..mocap.resample import resample
from ..mocap.retarget import CanonicalClip, retarget, source_from_amc, source_from_cmu_bvh
from ..mocap.skeleton import FOOT_POINTS, canonical_skeleton

CATEGORIES = ("walk", "run", "jump", "dance", "other")


@dataclass
class ClipInfo:
    file: str  # relative to the corpus root
    subject: str
    trial: str
    fps: float
    category: str
    description: str


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


def build(mocap: Path, fps: float, categories: list[str], out: Path) -> Path:
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
        table.append({"file": info.file, "subject": info.subject, "category": info.category,
                      "description": info.description, "start": start, "frames": clip.frames})
        start += clip.frames
    out.mkdir(parents=True, exist_ok=True)
    name = f"cmu_{'-'.join(categories)}_{fps:g}fps.npz"
    path = out / name
    np.savez_compressed(path, fps=np.float32(fps), clips=json.dumps(table), joints=json.dumps(canonical_skeleton().joints),
                        **{k: np.concatenate(v) for k, v in arrays.items()})
    seconds = start / fps
    print(f"wrote {path} ({len(table)} clips, {start} frames, {seconds / 60:.1f} min)")
    return path


def load_cache(path: Path) -> dict:
    """The arrays of a built cache plus its clip table as a list of dicts."""
    with np.load(path) as data:
        out = {k: data[k] for k in data.files}
    out["clips"] = json.loads(str(out["clips"]))
    out["joints"] = json.loads(str(out["joints"]))
    return out


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_mocap_argument(parser)
    parser.add_argument("--fps", type=float, default=30.0, help="output frame rate (default 30)")
    parser.add_argument("--categories", default="walk,run", help=f"comma-separated, from {','.join(CATEGORIES)}")
    parser.add_argument("--out", type=Path, default=DEFAULT_CACHE, help=f"cache directory (default {DEFAULT_CACHE})")
    args = parser.parse_args(argv)
    categories = [c.strip() for c in args.categories.split(",") if c.strip()]
    unknown = [c for c in categories if c not in CATEGORIES]
    if unknown:
        parser.error(f"unknown category {unknown[0]!r}; choose from {', '.join(CATEGORIES)}")
    if args.fps <= 0 or args.fps > 120:
        parser.error("--fps must be in (0, 120]")
    build(resolve_mocap_dir(args.mocap), args.fps, categories, args.out)


if __name__ == "__main__":
    main(sys.argv[1:])
