"""Train the locomotion generator (LSTM + Gaussian mixture) on CMU walking and running.

    python -m training.generator.train [--epochs 150] [--hidden 192] [--minutes 85] [--resume]

The recipe is in training/generator/training.py. Writes runs/generator/{train.log, checkpoint.pt, best.pt};
export with python -m training.generator.export.
"""
from __future__ import annotations

import argparse

from ..runs import add_run_arguments
from .training import train_generator


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_run_arguments(parser, run="generator", minutes=85.0)
    parser.add_argument("--epochs", type=int, default=150)
    parser.add_argument("--iters-per-epoch", type=int, default=200,
                        help="iterations between learning-rate decays; 150 x 200 matches the paper's ~30k iterations")
    parser.add_argument("--hidden", type=int, default=192)
    parser.add_argument("--batch", type=int, default=20)
    parser.add_argument("--window", type=int, default=50)
    parser.add_argument("--lr", type=float, default=1e-3)
    parser.add_argument("--dropout", type=float, default=0.25)
    args = parser.parse_args(argv)
    best, run_dir = train_generator(args)
    print(f"done: best validation NLL {best:.3f} per frame; checkpoints in {run_dir}")


if __name__ == "__main__":
    main()
