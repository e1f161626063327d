"""Train the adversarial refiner R against a discriminator D (Wang, Chai, Xia §4.2, §4.3).

    python -m training.refiner.train [--minutes 50] [--hidden 96] [--resume]

The recipe, its deviations from the paper and the runs tried are in training/refiner/training.py. Writes
runs/refiner/{train.log, checkpoint.pt, best.pt, last.pt}; export with python -m training.refiner.export.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..models.refiner import DISCRIMINATOR_INPUTS
from ..runs import RUNS_DIR, add_run_arguments
from .training import RefinerTraining


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_run_arguments(parser, run="refiner", minutes=50.0)
    parser.add_argument("--generator", type=Path, default=RUNS_DIR / "generator" / "best.pt")
    parser.add_argument("--style-generator", type=Path, default=None, metavar="CHECKPOINT",
                        help="train against a style generator's motion instead (issue 39, e.g. runs/style-pilot/best.pt): "
                             "streams in every style, an equal share each, against real windows of every style")
    parser.add_argument("--hidden", type=int, default=96, help="refiner width (FC1 and LSTM)")
    parser.add_argument("--d-hidden", type=int, default=64, help="discriminator width (FC1 and each LSTM direction)")
    parser.add_argument("--window", type=int, default=90, help="frames per refiner window (from a zero state)")
    parser.add_argument("--crop", type=int, default=30, help="frames per discriminator window")
    parser.add_argument("--batch", type=int, default=32, help="b: refiner windows per update, D windows per update")
    parser.add_argument("--buffer", type=int, default=320, help="B: history buffer of refined D windows")
    parser.add_argument("--lam", type=float, default=20.0, help="lambda of the root regularisation (eq. 13)")
    parser.add_argument("--pose-weight", type=float, default=1.0,
                        help="extra self-regularisation (eq. 13 has the root only): weight of the mean squared change of "
                             "the other features (tilt, joint rotation vectors, contacts; normalised units). 0 = the paper")
    parser.add_argument("--d-input", choices=DISCRIMINATOR_INPUTS, default="ends",
                        help="what D sees: ends = the end effectors and contacts of eq. 12 (the paper); pose = also the rest "
                             "of x (root motion, tilt, joint rotations); joints = every joint's root-frame position and "
                             "velocity and the contacts, as the report's two-sample classifiers see a frame")
    parser.add_argument("--d-arch", choices=("lstm", "conv"), default="lstm",
                        help="lstm: the paper's bidirectional LSTM D, a logit per frame (RMSProp); conv: a window classifier "
                             "shaped like the report's two-sample test, a logit per window (Adam)")
    parser.add_argument("--skate-weight", type=float, default=0.0,
                        help="weight of the mean planted-toe speed (m/s, planted by the generator's bits) in R's loss")
    parser.add_argument("--lr-r", type=float, default=0.002)
    parser.add_argument("--lr-d", type=float, default=0.005)
    parser.add_argument("--initial", type=int, default=75, help="initial updates of each network")
    parser.add_argument("--ratio", type=int, default=5, help="refiner updates per discriminator update (start)")
    parser.add_argument("--iterations", type=int, default=20000, help="refiner updates in all")
    parser.add_argument("--streams", type=int, default=2048, help="short generated streams for training")
    parser.add_argument("--long-streams", type=int, default=96, help="long (1200-frame) generated streams")
    parser.add_argument("--warmup", type=int, default=10, help="teacher-forced real frames before sampling")
    parser.add_argument("--eval-every", type=int, default=250, help="refiner updates between validation checks")
    args = parser.parse_args(argv)

    state = RefinerTraining(args).train()
    print(f"done: {state['r_updates']} refiner updates, best validation skating {state['best']:.3f} m/s; {RUNS_DIR / args.run}")


if __name__ == "__main__":
    main()
