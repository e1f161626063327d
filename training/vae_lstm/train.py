"""Train the VAE-LSTM (Habibie et al.) on 4 s windows of CMU walking and running.

    python -m training.vae_lstm.train [--minutes 60] [--resume]        # runs/vae-lstm/: train.log, checkpoints

The recipe is in training/vae_lstm/training.py.
"""
from __future__ import annotations

import argparse

from ..runs import add_run_arguments
from .training import L1_PAPER, train_vae_lstm


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_run_arguments(parser, run="vae-lstm", minutes=60.0, iterations=20000)
    parser.add_argument("--latent", type=int, default=128, help="latent and cell size (the paper's 128)")
    parser.add_argument("--control-features", type=int, default=128)
    parser.add_argument("--inference-features", type=int, default=256)
    parser.add_argument("--decoder-hidden", type=int, default=128)
    parser.add_argument("--dropout", type=float, default=0.1, help="dropout on the positions and the control")
    parser.add_argument("--beta", type=float, default=0.02, help="KL weight against the mean squared error (2 sigma^2)")
    parser.add_argument("--free", type=float, default=1.0, help="weight of the free-mode reconstruction (0: the paper's recipe)")
    parser.add_argument("--free-z1", choices=["seed", "window", "both"], default="seed",
                        help="the free mode's z_1: from the first 4 frames held (seed), from the window's own first step (window), or half each")
    parser.add_argument("--free-mix", type=float, default=0.0, help="free mode: z_1's share of every step's content (0: Algorithm 1, z_1 only the first state)")
    parser.add_argument("--energy", type=float, default=5.0, help="weight of the free mode's motion-energy term (models/losses.py energy_loss)")
    parser.add_argument("--l1", type=float, default=L1_PAPER, help="l1 on the weights, against the summed loss")
    parser.add_argument("--control-sigma", type=float, default=10.0, help="frames of smoothing on the control the cell reads")
    parser.add_argument("--batch", type=int, default=32)
    parser.add_argument("--lr", type=float, default=5e-4)
    args = parser.parse_args(argv)
    best, run_dir = train_vae_lstm(args)
    print(f"done: best held-out error from 4 frames {best:.2f} cm; checkpoints in {run_dir}")


if __name__ == "__main__":
    main()
