"""Report on the shipped refiner: raw generator output, refined, refined + foot lock, and real held-out clips.

    python -m training.refiner.evaluate [--frames 3000] [--seeds 8]

Writes docs/models/refiner.{md,json,png}; what is measured and how is in training/refiner/report.py.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..paths import MODELS_DIR, REPORTS_DIR
from .report import write_refiner_report


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", type=int, default=3000, help="frames per seed")
    parser.add_argument("--seeds", type=int, default=8, help="seeds (8: all of the generator's)")
    parser.add_argument("--mocap", default=None)
    parser.add_argument("--models", type=Path, default=MODELS_DIR, help="directory with the exported models")
    args = parser.parse_args(argv)
    write_refiner_report(args.frames, args.seeds, args.mocap, args.models)
    print(f"wrote {REPORTS_DIR / 'refiner.md'}")


if __name__ == "__main__":
    main()
