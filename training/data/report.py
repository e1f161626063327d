"""Measure the corpus on the canonical skeleton and write docs/data.md (training/data/statistics.py).

    python -m training.data.report [--mocap DIR]
"""
from __future__ import annotations

import argparse

from ..paths import REPO_ROOT, add_mocap_argument, resolve_mocap_dir
from .statistics import corpus_statistics, data_report

OUT = REPO_ROOT / "docs" / "data.md"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_mocap_argument(parser)
    mocap = resolve_mocap_dir(parser.parse_args(argv).mocap)
    OUT.write_text(data_report(corpus_statistics(mocap)))
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
