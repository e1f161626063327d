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
    parser.add_argument("--source-fps", type=positive_rate, default=None,
                        help="the files' true frame rate, for files whose header is wrong (the acLSTM salsa files say 120, "
                             "were captured at 60); default each file's own (AMC: 120)")
    parser.add_argument("--licence", default=None,
                        help="the terms of your data, shown with the model (default: \"your data's own terms\")")
    parser.add_argument("--non-commercial", action="store_true",
                        help="the data may not be used commercially (e.g. the Bandai Namco set, CC BY-NC 4.0): the page "
                             "labels the model \"(non-commercial)\"")
    parser.add_argument("--minutes", type=float, default=20.0, help="training time budget (minutes)")
    parser.add_argument("--iterations", type=int, default=None, help="stop after this many iterations in all (default: the time budget decides)")
    parser.add_argument("--run", default=None, help="run folder for the log and checkpoints (default runs/own-<id>)")
    parser.add_argument("--resume", action="store_true", help="continue the run from its last checkpoint")
    parser.add_argument("--checkpoint-minutes", type=float, default=3.0, help="minutes between checkpoints")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--threads", type=int, default=1,
                        help="torch CPU threads for training (1 is steadiest on a shared machine; the export runs on 1)")
    parser.add_argument("--hidden", type=int, default=None, help="LSTM units per layer (locomotion 192, dance 256)")
    parser.add_argument("--layers", type=int, default=None, help="LSTM layers of the dance model (3; the generator has 2)")
    parser.add_argument("--dropout", type=float, default=0.25, help="the generator's dropout")
    parser.add_argument("--lr", type=float, default=1e-3)
    parser.add_argument("--batch", type=int, default=None, help="windows per step (locomotion 20, dance 32)")
    parser.add_argument("--window", type=int, default=None, help="training window, frames at 30 fps (locomotion 50, dance 100)")
    parser.add_argument("--epochs", type=int, default=150, help="the generator's epochs at most (the time budget usually ends the run first)")
    parser.add_argument("--iters-per-epoch", type=int, default=None,
                        help="iterations between learning-rate decays (locomotion 200, dance 250)")
    parser.add_argument("--weights", choices=("float32", "float16", "int8"), default="int8", help="how the ONNX stores its weights")
    parser.add_argument("--stability-frames", type=int, default=10_000, help="frames of the card's stability run")


def positive_rate(text: str) -> float:
    """--source-fps: a positive frame rate, refused before anything is read."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a frame rate, got {text!r}") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be a positive frame rate, got {text}")
    return value


def pack_terms(args: argparse.Namespace) -> dict:
    """The pack's licence fields (its JSON's `pack`): what the page shows with the model."""
    return {"licence": args.licence or "your data's own terms", "commercial": not args.non_commercial}


# Each kind's recipe: the shipped generator's (training/generator) and the shipped acLSTM's (training/aclstm).
KIND_DEFAULTS = {
    "locomotion": {"hidden": 192, "batch": 20, "window": 50, "iters_per_epoch": 200},
    "dance": {"hidden": 256, "layers": 3, "batch": 32, "window": 100, "iters_per_epoch": 250},
}


def apply_kind_defaults(args: argparse.Namespace) -> None:
    """Fills the options left out with the --kind's recipe; --layers is the dance model's only."""
    if args.kind == "locomotion" and args.layers is not None:
        raise SystemExit("error: --layers is for --kind dance; the generator has 2 layers")
    for name, value in KIND_DEFAULTS[args.kind].items():
        if getattr(args, name, None) is None:
            setattr(args, name, value)


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
