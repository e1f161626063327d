"""Train the motion autoencoder (the manifold) as a denoising autoencoder on 4 s CMU locomotion windows.

    python -m training.autoencoder.train [--minutes 40] [--resume]

The recipe is in training/autoencoder/training.py. Writes runs/autoencoder/{train.log, checkpoint.pt,
best.pt}; export with python -m training.autoencoder.export.
"""
from __future__ import annotations

import argparse

from ..runs import add_run_arguments
from .training import CONTROL_WEIGHT, SPARSITY, train_autoencoder


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_run_arguments(parser, run="autoencoder", minutes=40.0, iterations=12000)
    parser.add_argument("--hidden", type=int, default=96, help="channels of the first convolution")
    parser.add_argument("--latent", type=int, default=256, help="channels of the latent")
    parser.add_argument("--control-weight", type=float, default=CONTROL_WEIGHT, help="loss weight of the control channels")
    parser.add_argument("--sparsity", type=float, default=SPARSITY, help="L1 weight on the latent (Holden's Lasso term)")
    parser.add_argument("--batch", type=int, default=32)
    parser.add_argument("--lr", type=float, default=1e-3)
    parser.add_argument("--mask", type=float, default=0.3, help="masked-noise probability (thesis: 0.3)")
    args = parser.parse_args(argv)
    best, run_dir = train_autoencoder(args)
    print(f"done: best held-out reconstruction {best:.2f} cm per joint; checkpoints in {run_dir}")


if __name__ == "__main__":
    main()
