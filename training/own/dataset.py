"""A user's folder as a training set: every clip read, mapped onto the canonical skeleton and checked before any
training starts (refusals with short messages), split into training and held-out clips by clip, and the generator's
normalised feature sequences with window sampling (as training/data/locomotion.py Corpus does for CMU)."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from ..data.features import FeatureCodec, mirror_clip
from ..data.locomotion import SPEED_FACTORS, Corpus, LocomotionClip, change_speed
from ..mocap.canonical_points import MappedClip, canonical_clip, make_ik, map_skeleton
from ..mocap.humanoid import SkeletonMapError
from ..mocap.skeleton import canonical_skeleton
from .reading import read_folder

FPS = 30.0  # the generator's rate
# Every 8th clip by name is held out (CMU's rule in data/locomotion.py), and at least one.
HELD_OUT_EVERY, HELD_OUT_AT = 8, 3


class RefusedFolder(ValueError):
    """A folder that cannot be trained on; the message says why, before any training starts."""


@dataclass
class OwnData:
    """The user's clips on the canonical skeleton, and what was found reading them."""
    folder: Path
    clips: list[MappedClip]
    held_out: list[str]  # clip names
    skeletons: list[dict]  # per distinct skeleton: scheme, joints, files
    skipped: list[str] = field(default_factory=list)  # files that could not be read, each with why (file:line)
    too_short: list[str] = field(default_factory=list)  # clips shorter than the training window
    min_seconds: float = 0.0  # the shortest clip the training window takes

    @property
    def minutes(self) -> float:
        return sum(c.frames for c in self.clips) / FPS / 60

    def train_clips(self) -> list[MappedClip]:
        return [c for c in self.clips if c.name not in self.held_out]

    def held_out_clips(self) -> list[MappedClip]:
        return [c for c in self.clips if c.name in self.held_out]


def held_out_names(names: list[str]) -> list[str]:
    ordered = sorted(names)
    chosen = [n for rank, n in enumerate(ordered) if rank % HELD_OUT_EVERY == HELD_OUT_AT]
    return chosen or [ordered[len(ordered) // 2]]


def load_folder(folder: Path, min_frames: int, log=print, source_fps: float | None = None) -> OwnData:
    """Reads and maps every clip under `folder`; raises RefusedFolder for a folder with no motion, a skeleton the mapper
    cannot map (naming the file), or fewer than two clips of at least `min_frames` frames at FPS. `source_fps`: the
    files' true frame rate, instead of their headers'."""
    if not folder.is_dir():
        raise RefusedFolder(f"{folder} is not a folder")
    raws, skipped = read_folder(folder)
    if source_fps is not None:
        for raw in raws:
            raw.fps = source_fps
    for problem in skipped:
        log(f"skipped: {problem}")
    if not raws:
        found = f" ({len(skipped)} could not be read: {skipped[0]})" if skipped else ""
        raise RefusedFolder(f"no motion in {folder}: no .bvh or .amc file (plain or .gz) was found or could be read{found}")
    skel = canonical_skeleton()
    mappings, skeletons = [], {}
    for raw in raws:
        try:
            mapping = map_skeleton(raw, skel.leg_length)
        except (SkeletonMapError, ValueError) as err:
            raise RefusedFolder(f"{raw.name}: not a humanoid skeleton the mapper can read: {err}") from None
        mappings.append(mapping)
        key = (tuple(raw.joints), tuple(raw.parents))
        entry = skeletons.setdefault(key, {"scheme": mapping.scheme, "joints": len(raw.joints), "files": 0})
        entry["files"] += 1
    ik = make_ik(skel)
    clips, too_short = [], []
    for raw, mapping in zip(raws, mappings):
        clip = canonical_clip(raw, mapping, FPS, ik, skel)
        if clip.frames < min_frames:
            too_short.append(raw.name)
            log(f"skipped: {raw.name}: {raw.seconds:.2f} s, shorter than the {min_frames / FPS:.2f} s the training window needs")
            continue
        clips.append(clip)
        log(f"read {raw.name}: {raw.seconds:.1f} s at {raw.fps:.4g} fps, skeleton {mapping.scheme}")
    if len(clips) < 2:
        longest = max(r.seconds for r in raws)
        raise RefusedFolder(f"clips too short: training needs at least 2 clips of {min_frames / FPS:.2f} s or more "
                            f"(the window is {min_frames} frames at {FPS:g} fps); {len(clips)} here, the longest "
                            f"{longest:.2f} s")
    return OwnData(folder, clips, held_out_names([c.name for c in clips]), list(skeletons.values()), skipped, too_short,
                   min_frames / FPS)


class OwnCorpus(Corpus):
    """Normalised feature sequences of the training clips (mirrored, and played 10% slower and faster, as for CMU) and
    of the held-out clips, with window sampling: data/locomotion.py Corpus (its normalise and batch) on the user's clips."""

    # Corpus.__init__ splits CMU's clips by its own rule; this builds the same fields from the user's split.
    def __init__(self, data: OwnData):
        train = data.train_clips()
        self.codec = FeatureCodec()
        self.codec.fit_references(np.concatenate([c.rotations for c in train]))
        seqs = []
        for c in train:
            as_clip = LocomotionClip(c.name, "", "own", "", 0, c.root, c.rotations, c.contacts)
            for factor in SPEED_FACTORS:
                root, rot, con = change_speed(as_clip, factor)
                for variant in [(root, rot, con), mirror_clip(root, rot, con)]:
                    seqs.append(self.codec.encode(*variant))
        allx = np.concatenate(seqs)
        self.mean = allx.mean(axis=0)
        self.std = np.maximum(allx.std(axis=0), 1e-2)
        self.train = [self.normalise(s) for s in seqs]
        lengths = np.array([len(s) for s in seqs], np.float64)
        self.weights = lengths / lengths.sum()
        held = data.held_out_clips()
        self.valid = [self.normalise(self.codec.encode(c.root, c.rotations, c.contacts)) for c in held]
        self.train_frames = len(allx)
        self.valid_files = [c.name for c in held]
