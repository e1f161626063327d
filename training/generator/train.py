"""Train the locomotion generator (LSTM + Gaussian mixture) on CMU walking and running.

    python -m training.generator.train [--epochs 150] [--hidden 192] [--minutes 85] [--resume]

The recipe is in training/generator/training.py. Writes runs/generator/{train.log, checkpoint.pt, best.pt};
export with python -m training.generator.export.
"""
from __future__ import annotations

import argparse

from ..paths import add_mocap_argument
from .training import train_generator


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_mocap_argument(parser)
    parser.add_argument("--epochs", type=int, default=150)
    parser.add_argument("--hidden", type=int, default=192)
    parser.add_argument("--batch", type=int, default=20)
    parser.add_argument("--window", type=int, default=50)
    parser.add_argument("--lr", type=float, default=1e-3)
    parser.add_argument("--dropout", type=float, default=0.25)
    parser.add_argument("--minutes", type=float, default=85.0, help="stop cleanly after this much training time")
    parser.add_argument("--checkpoint-minutes", type=float, default=3.0)
    parser.add_argument("--run", default="generator", help="run name under runs/")
    parser.add_argument("--resume", action="store_true", help="continue from runs/<run>/checkpoint.pt")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--threads", type=int, default=1, help="torch CPU threads (1 is steadiest when the machine is shared)")
    parser.add_argument("--iters-per-epoch", type=int, default=200,
                        help="iterations between learning-rate decays; 150 x 200 matches the paper's ~30k iterations")
    args = parser.parse_args(argv)
    best, run_dir = train_generator(args)
    print(f"done: best validation NLL {best:.3f} per frame; checkpoints in {run_dir}")


if __name__ == "__main__":
    main()
