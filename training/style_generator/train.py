"""Train the style-conditioned locomotion generator (issue 39) on CMU walking and running plus the Bandai Namco set
(CC BY-NC 4.0: the model is non-commercial).

    python -m training.style_generator.train [--minutes 150] [--run style-generator] [--resume]

The recipe is in training/style_generator/training.py, the corpus and its style sampling in
training/data/style_locomotion.py. Writes runs/<run>/{train.log, checkpoint.pt, best.pt, last.pt, summary.json}.
"""
from __future__ import annotations

import argparse

from ..runs import add_run_arguments
from .training import train_style_generator


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_run_arguments(parser, run="style-generator", minutes=150.0)
    parser.add_argument("--epochs", type=int, default=300)
    parser.add_argument("--iters-per-epoch", type=int, default=200, help="iterations between learning-rate decays")
    parser.add_argument("--hidden", type=int, default=192)
    parser.add_argument("--style-dim", type=int, default=8, help="values in each style's embedding")
    parser.add_argument("--batch", type=int, default=20)
    parser.add_argument("--window", type=int, default=50)
    parser.add_argument("--lr", type=float, default=1e-3)
    parser.add_argument("--dropout", type=float, default=0.25)
    parser.add_argument("--cmu-share", type=float, default=None,
                        help="CMU's share of the windows (default: every style equally often, 1/8)")
    parser.add_argument("--init-from-shipped", action="store_true",
                        help="start from the shipped CMU generator's weights (public/models/generator.onnx), every style as CMU")
    parser.add_argument("--cmu-guard", type=float, default=None,
                        help="best.pt only from epochs whose CMU held-out NLL is at most this above the first validation's")
    parser.add_argument("--fit-references", action="store_true",
                        help="fit the rotation references to the training clips instead of the shipped generator's")
    args = parser.parse_args(argv)
    best, run_dir = train_style_generator(args)
    print(f"done: best validation NLL {best:.3f} per frame (mean over styles); checkpoints in {run_dir}")


if __name__ == "__main__":
    main()
