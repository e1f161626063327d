"""The locomotion dataset the generator and the refiner train on: CMU walking and running at 30 fps, split
into training and validation by clip, as normalised feature sequences with window sampling.

Mirrored copies and copies played 10% slower and faster are added to the training clips; running clips
(1 minute of 20) are drawn 4x as often.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from ..mocap.resample import resample
from ..mocap.retarget import CanonicalClip
from ..paths import DEFAULT_CACHE, resolve_mocap_dir
from .cmu import build_cache, cache_name, load_cache
from .features import FeatureCodec, mirror_clip

FPS = 30
CATEGORIES = ["walk", "run"]
RUN_WEIGHT = 4.0
SPEED_FACTORS = (0.9, 1.0, 1.1)


@dataclass
class LocomotionClip:
    """One cached clip: its table entry, its rank within its category (by file name) and its frames."""
    file: str
    subject: str
    category: str
    description: str
    rank: int
    root: np.ndarray       # (frames, 3) metres
    rotations: np.ndarray  # (frames, joints, 4) local quaternions
    contacts: np.ndarray   # (frames, 2)

    @property
    def frames(self) -> int:
        return len(self.root)


def is_validation(clip: LocomotionClip) -> bool:
    """Every 8th clip of each category (by file name) is held out."""
    return clip.rank % 8 == 3


def load_clips(mocap_flag: str | None) -> list[LocomotionClip]:
    """The walking and running clips at 30 fps, from the cache (built first when missing)."""
    cache = DEFAULT_CACHE / cache_name(FPS, CATEGORIES)
    if not cache.exists():
        build_cache(resolve_mocap_dir(mocap_flag), FPS, CATEGORIES, DEFAULT_CACHE)
    data = load_cache(cache)
    clips = []
    for cat in CATEGORIES:
        for rank, c in enumerate(sorted((c for c in data.clips if c.category == cat), key=lambda c: c.file)):
            s, e = c.start, c.start + c.frames
            clips.append(LocomotionClip(c.file, c.subject, c.category, c.description, rank,
                                        root=data.root[s:e].astype(np.float64),
                                        rotations=data.rotations[s:e].astype(np.float64), contacts=data.contacts[s:e]))
    return clips


def change_speed(clip: LocomotionClip, factor: float):
    """The clip played `factor` times as fast, still at 30 fps (slerped poses, nearest contacts)."""
    if factor == 1.0:
        return clip.root, clip.rotations, clip.contacts
    src = CanonicalClip(clip.file, FPS * factor, clip.root, clip.rotations, np.zeros((len(clip.root), 1, 3)))
    out = resample(src, FPS)
    idx = np.minimum(np.round(np.arange(out.frames) * factor).astype(int), len(clip.contacts) - 1)
    return out.root, out.rotations, clip.contacts[idx]


class Corpus:
    """Normalised feature sequences, split by clip, with window sampling."""

    def __init__(self, clips: list[LocomotionClip]):
        train = [c for c in clips if not is_validation(c)]
        self.codec = FeatureCodec()
        self.codec.fit_references(np.concatenate([c.rotations for c in train]))
        seqs, weights = [], []
        for c in train:
            for factor in SPEED_FACTORS:
                root, rot, con = change_speed(c, factor)
                for variant in [(root, rot, con), mirror_clip(root, rot, con)]:
                    seqs.append(self.codec.encode(*variant))
                    weights.append(len(seqs[-1]) * (RUN_WEIGHT if c.category == "run" else 1.0))
        allx = np.concatenate(seqs)
        self.mean = allx.mean(axis=0)
        self.std = np.maximum(allx.std(axis=0), 1e-2)
        self.train = [self.normalise(s) for s in seqs]
        self.weights = np.array(weights) / sum(weights)
        self.valid = [self.normalise(self.codec.encode(c.root, c.rotations, c.contacts))
                      for c in clips if is_validation(c)]
        self.train_frames = len(allx)
        self.valid_files = [c.file for c in clips if is_validation(c)]

    def normalise(self, x: np.ndarray) -> np.ndarray:
        return ((x - self.mean) / self.std).astype(np.float32)

    def batch(self, rng: np.random.Generator, size: int, length: int):
        """Windows of length+1 frames (inputs and next-frame targets), padded, with a mask of real targets."""
        x = np.zeros((size, length + 1, self.mean.shape[0]), np.float32)
        mask = np.zeros((size, length), np.float32)
        for i, k in enumerate(rng.choice(len(self.train), size=size, p=self.weights)):
            seq = self.train[k]
            start = rng.integers(0, max(1, len(seq) - length))
            w = seq[start:start + length + 1]
            x[i, :len(w)] = w
            mask[i, :len(w) - 1] = 1
        return torch.from_numpy(x), torch.from_numpy(mask)
