"""--kind dance: the acLSTM (Zhou et al.; training/aclstm) trained on a user's folder as one style.

The user's clips are read and mapped as for locomotion (dataset.py load_folder: the humanoid mapper, the canonical
skeleton's 25 points at 30 fps, feet on the floor), and the dance model learns those points as the shipped acLSTM
learns its 57 (data/dance.py's features: root dx, height and dz, then every point relative to the root). Training is
training/aclstm/training.py's recipe, u = v = 5, with rotation, speed and mirror augmentation, on one process (a
dance model is small enough; torchrun is for --kind locomotion)."""
from __future__ import annotations

import argparse
import re

from ..aclstm.training import DanceRun, train_dance_model
from ..data.dance import DanceClip, DanceSkeleton
from ..mocap.skeleton import canonical_skeleton
from .dataset import FPS, OwnData


DANCE_ITERATIONS = 20_000  # the shipped acLSTM's cap; the time budget usually ends the run first


def style_name(data: OwnData) -> str:
    """The pack's one style: the data folder's name in lower case letters, digits and dashes ("dance" if none)."""
    return re.sub(r"[^a-z0-9]+", "-", data.folder.resolve().name.lower()).strip("-") or "dance"


def dance_data(data: OwnData) -> tuple[DanceSkeleton, list[DanceClip], tuple[str, ...]]:
    """The user's clips as the dance recipe takes them: the canonical skeleton's points, one style."""
    skel = canonical_skeleton()
    style = style_name(data)
    clips = [DanceClip(style, c.name, FPS, c.positions, c.name in data.held_out) for c in data.clips]
    return DanceSkeleton(list(skel.joints), list(skel.parents), skel.offsets.copy()), clips, (style,)


def dance_config(args: argparse.Namespace) -> argparse.Namespace:
    """The flags train_dance_model reads (python -m training.aclstm.train's), from python -m training.own's."""
    return argparse.Namespace(
        mocap=None, run=args.run, minutes=args.minutes, checkpoint_minutes=args.checkpoint_minutes, resume=args.resume,
        seed=args.seed, threads=args.threads, iterations=args.iterations or DANCE_ITERATIONS,
        condition=5, ground_truth=5, condition_max=0, input_noise=(0.0, 0.0), energy=0.0, feedback_noise=0.0,
        head="mean", hidden=args.hidden, layers=args.layers, batch=args.batch, window=args.window, lr=args.lr,
        decay=0.95, iters_per_epoch=args.iters_per_epoch, no_mirror=False)


def train_dance(data: OwnData, args: argparse.Namespace) -> DanceRun:
    return train_dance_model(dance_config(args), dance_data(data))
