"""Build the cached arrays of the Bandai Namco set on the canonical skeleton (training/data/bandai.py).

    python -m training.data.build_bandai [--mocap DIR] [--out cache/] [--limit N]

Every clip of bandai/index.tsv at 30 fps (about 10 minutes on one core) to cache/bandai_30fps.npz; --limit N maps only
the first N clips of each content and style (a quick look, written under another name). The set is CC BY-NC 4.0: a
model trained on it is non-commercial.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..paths import DEFAULT_CACHE, add_mocap_argument, resolve_mocap_dir
from .bandai import build_cache


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_mocap_argument(parser)
    parser.add_argument("--out", type=Path, default=DEFAULT_CACHE, help=f"cache directory (default {DEFAULT_CACHE})")
    parser.add_argument("--limit", type=int, default=None, help="only the first N clips of each content and style")
    args = parser.parse_args(argv)
    if args.limit is not None and args.limit < 1:
        parser.error("--limit must be at least 1")
    mocap = resolve_mocap_dir(args.mocap)
    if not (mocap / "bandai" / "index.tsv").is_file():
        parser.error(f"no bandai/index.tsv under {mocap}")
    build_cache(mocap, args.out, limit=args.limit)


if __name__ == "__main__":
    main(sys.argv[1:])
