"""Report on the shipped refiner: raw generator output, refined, refined + foot lock, and real held-out clips.

    python -m training.refiner.evaluate [--frames 3000] [--seeds 8]
    python -m training.refiner.evaluate --from-json    # refiner.md again from refiner.json, measuring nothing

Writes docs/models/refiner.{md,json,png}; what is measured and how is in training/refiner/report.py.
"""
from __future__ import annotations

import argparse

from ..paths import REPORTS_DIR
from ..runs import add_from_json_argument, add_report_arguments, rewrote_from_json
from .report import rewrite_refiner_markdown, write_refiner_report


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_report_arguments(parser, frames=3000, seeds=8, seeds_help="seeds (8: all of the generator's)")
    add_from_json_argument(parser, "refiner")
    args = parser.parse_args(argv)
    if rewrote_from_json(args, "refiner", rewrite_refiner_markdown):
        return
    write_refiner_report(args.frames, args.seeds, args.mocap, args.models)
    print(f"wrote {REPORTS_DIR / 'refiner.md'}")


if __name__ == "__main__":
    main()
