"""Train the dance model: acLSTM (auto-conditioned) or the vanilla teacher-forced baseline of the same size.

    python -m training.aclstm.train [--minutes 75] [--resume]                 # runs/aclstm/
    python -m training.aclstm.train --condition 0 --run aclstm-vanilla        # the baseline

The recipe is in training/aclstm/training.py.
"""
from __future__ import annotations

import argparse

from ..runs import add_run_arguments
from .training import train_dance_model


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_run_arguments(parser, run="aclstm", minutes=75.0, iterations=20000)
    parser.add_argument("--condition", type=int, default=5, help="v: self-fed frames per cycle (0: vanilla teacher forcing)")
    parser.add_argument("--ground-truth", type=int, default=5, help="u: real frames per cycle")
    parser.add_argument("--condition-max", type=int, default=0,
                        help="grow v linearly from --condition to this over the time budget (0: v stays fixed)")
    parser.add_argument("--input-noise", type=float, nargs=2, default=(0.0, 0.0), metavar=("START", "END"),
                        help="Gaussian noise on the real input frames (normalised units), growing from START to END over the time budget")
    parser.add_argument("--energy", type=float, default=0.0,
                        help="weight of the motion-energy term (each channel's RMS frame-to-frame change against the real window's)")
    parser.add_argument("--feedback-noise", type=float, default=0.0,
                        help="Gaussian noise (normalised units) on each self-fed frame in training, as the inference-time lever adds it")
    parser.add_argument("--head", choices=["mean", "gauss", "mdn"], default="mean",
                        help="output: the next frame (squared error), a Gaussian over it (likelihood; draws are fed back) or "
                             "a mixture of --components Gaussians (likelihood; a component held over each self-fed stretch, its draws fed back)")
    parser.add_argument("--components", type=int, default=10, help="K, the mdn head's mixture components")
    parser.add_argument("--draw-temperature", type=float, default=1.0,
                        help="the mdn head's fed-back draws in training: the held component's sigma times this")
    parser.add_argument("--hidden", type=int, default=256)
    parser.add_argument("--layers", type=int, default=3)
    parser.add_argument("--batch", type=int, default=32)
    parser.add_argument("--window", type=int, default=100)
    parser.add_argument("--lr", type=float, default=1e-3)
    parser.add_argument("--decay", type=float, default=0.95, help="learning-rate factor per epoch")
    parser.add_argument("--iters-per-epoch", type=int, default=250)
    parser.add_argument("--device", default="cpu", help="where to train: cpu, or cuda on a machine with a GPU "
                                                        "(checkpoints are saved for the CPU either way)")
    parser.add_argument("--no-mirror", action="store_true", help="no left/right mirroring of training windows")
    parser.add_argument("--extra", action="store_true",
                        help="also train on ../shared/mocap/aclstm-extra (Indian 01, martial 02 on the standard skeleton: "
                             "training/data/dance_extra.py)")
    args = parser.parse_args(argv)
    result = train_dance_model(args)
    print(f"done: {result.stopped}; best validation loss {result.best:.4f}; checkpoints in {result.run_dir}")


if __name__ == "__main__":
    main()
