"""Train the latent ERD on the motion autoencoder's latents, or the pose-space ERD baseline of the same size.

    python -m training.latent_erd.train [--minutes 60] [--resume]                              # runs/latent-erd/
    python -m training.latent_erd.train --space pose --run pose-erd --noise 0.3                # the baseline

The latent ERD needs a trained autoencoder (python -m training.autoencoder.train). The recipe is in
training/latent_erd/training.py.
"""
from __future__ import annotations

import argparse

from ..paths import REPO_ROOT
from ..runs import add_run_arguments
from .training import train_erd


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_run_arguments(parser, run="latent-erd", minutes=60.0, iterations=12000)
    parser.add_argument("--space", choices=["latent", "pose"], default="latent")
    parser.add_argument("--autoencoder", default=str(REPO_ROOT / "runs" / "autoencoder" / "best.pt"))
    parser.add_argument("--hidden", type=int, default=224, help="LSTM units (the thesis's 256 does not fit 8 MB)")
    parser.add_argument("--layers", type=int, default=3)
    parser.add_argument("--dropout", type=float, default=0.2)
    parser.add_argument("--batch", type=int, default=32)
    parser.add_argument("--steps", type=int, default=48, help="steps per training stretch (latent: 4 frames each)")
    parser.add_argument("--lr", type=float, default=1e-3)
    parser.add_argument("--noise", type=float, default=0.05, help="final input-noise sigma (normalised units)")
    parser.add_argument("--self-fed", type=float, default=1.0,
                        help="share of each stretch (after the 4 seed steps) fed the model's own predictions by the end of the ramp")
    parser.add_argument("--energy", type=float, default=0.0,
                        help="weight of the motion-energy term (training.py energy_loss); 0 is mean squared error alone")
    parser.add_argument("--control-sigma", type=float, default=0.0,
                        help="latent ERD: read the control smoothed over this many frames (sequences.py); 0 reads it as it is")
    args = parser.parse_args(argv)
    best, run_dir = train_erd(args)
    print(f"done: best held-out free-running loss {best:.4f}; checkpoints in {run_dir}")


if __name__ == "__main__":
    main()
