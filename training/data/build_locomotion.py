"""Build cached arrays of the CMU corpus on the canonical skeleton (training/data/cmu.py).

    python -m training.data.build_locomotion [--fps 30] [--categories walk,run] [--mocap DIR] [--out cache/]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..paths import DEFAULT_CACHE, add_mocap_argument, resolve_mocap_dir
from .cmu import CATEGORIES, build_cache


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_mocap_argument(parser)
    parser.add_argument("--fps", type=float, default=30.0, help="output frame rate (default 30)")
    parser.add_argument("--categories", default="walk,run", help=f"comma-separated, from {','.join(CATEGORIES)}")
    parser.add_argument("--out", type=Path, default=DEFAULT_CACHE, help=f"cache directory (default {DEFAULT_CACHE})")
    args = parser.parse_args(argv)
    categories = [c.strip() for c in args.categories.split(",") if c.strip()]
    unknown = [c for c in categories if c not in CATEGORIES]
    if unknown:
        parser.error(f"unknown category {unknown[0]!r}; choose from {', '.join(CATEGORIES)}")
    if args.fps <= 0 or args.fps > 120:
        parser.error("--fps must be in (0, 120]")
    build_cache(resolve_mocap_dir(args.mocap), args.fps, categories, args.out)


if __name__ == "__main__":
    main(sys.argv[1:])
