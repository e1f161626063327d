"""Evaluate the shipped dance models, acLSTM against its vanilla baseline, and write docs/models/aclstm.{md,json,png}.

    python -m training.aclstm.evaluate [--frames 20000] [--seeds 5] [--also LABEL=path/to/model.json]

What is measured: training/aclstm/report.py.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..paths import MODELS_DIR, REPORTS_DIR
from .report import write_dance_report


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", type=int, default=20000, help="frames per seed")
    parser.add_argument("--seeds", type=int, default=5, help="seeds per style")
    parser.add_argument("--mocap", default=None)
    parser.add_argument("--models", type=Path, default=MODELS_DIR, help="directory with the exported models")
    parser.add_argument("--also", action="append", default=[], metavar="LABEL=JSON",
                        help="another exported dance model to compare (not shipped), e.g. 'acLSTM v=20=/tmp/x/aclstm.json'")
    args = parser.parse_args(argv)
    extra = []
    for item in args.also:
        label, sep, path = item.rpartition("=")
        if not sep:
            parser.error(f"--also wants LABEL=path/to/model.json, got {item!r}")
        extra.append((label, Path(path)))
    report = write_dance_report(args.frames, args.seeds, args.mocap, args.models, extra)
    print(f"wrote {REPORTS_DIR / 'aclstm.md'}; " + ", ".join(f"{k}: all stable {m['all_stable']}" for k, m in report["models"].items()))


if __name__ == "__main__":
    main()
