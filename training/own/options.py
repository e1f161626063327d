"""The options of python -m training.own and what follows from them: the pack's id, the run folder, the training
window's minimum clip length."""
from __future__ import annotations

import argparse
import re
from pathlib import Path

from ..runs import RUNS_DIR

KINDS = ("locomotion", "dance")


def add_own_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--data", type=Path, required=True, help="folder of BVH or ASF/AMC files (any depth, .gz too)")
    parser.add_argument("--kind", choices=KINDS, required=True, help="locomotion: the LSTM-GMM generator; dance: the acLSTM")
    parser.add_argument("--out", type=Path, required=True, help="folder the pack is written to")
    parser.add_argument("--id", default=None, help="the pack's model id (default: the --out folder's name)")
    parser.add_argument("--minutes", type=float, default=20.0, help="training time budget (minutes)")
    parser.add_argument("--iterations", type=int, default=None, help="stop after this many iterations in all (default: the time budget decides)")
    parser.add_argument("--run", default=None, help="run folder for the log and checkpoints (default runs/own-<id>)")
    parser.add_argument("--resume", action="store_true", help="continue the run from its last checkpoint")
    parser.add_argument("--checkpoint-minutes", type=float, default=3.0, help="minutes between checkpoints")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--threads", type=int, default=1,
                        help="torch CPU threads for training (1 is steadiest on a shared machine; the export runs on 1)")
    parser.add_argument("--hidden", type=int, default=192, help="LSTM units per layer")
    parser.add_argument("--dropout", type=float, default=0.25)
    parser.add_argument("--lr", type=float, default=1e-3)
    parser.add_argument("--batch", type=int, default=20)
    parser.add_argument("--window", type=int, default=50, help="training window (frames at 30 fps)")
    parser.add_argument("--epochs", type=int, default=150, help="epochs at most (the time budget usually ends the run first)")
    parser.add_argument("--iters-per-epoch", type=int, default=200, help="iterations between learning-rate decays")
    parser.add_argument("--weights", choices=("float32", "float16", "int8"), default="int8", help="how the ONNX stores its weights")
    parser.add_argument("--stability-frames", type=int, default=10_000, help="frames of the card's stability run")


def pack_id(args: argparse.Namespace) -> str:
    """--id, else the --out folder's name, as a model id: lower case letters, digits and dashes."""
    raw = args.id or args.out.resolve().name
    slug = re.sub(r"[^a-z0-9]+", "-", raw.lower()).strip("-")
    if not slug:
        raise SystemExit(f"error: cannot make a model id of {raw!r}; give one with --id")
    return slug


def run_folder(args: argparse.Namespace, model_id: str) -> str:
    """The run folder TrainingLoop uses (runs.Run takes a name under runs/, or an absolute path)."""
    return str(Path(args.run).resolve()) if args.run else str(RUNS_DIR / f"own-{model_id}")


def min_clip_frames(args: argparse.Namespace) -> int:
    """A clip must fill one training window plus its next-frame target, and the first frame has no feature row."""
    return args.window + 2
