"""Evaluate the shipped dance models, acLSTM against its vanilla baseline, and write docs/models/aclstm.{md,json,png}.

    python -m training.aclstm.evaluate [--frames 20000] [--seeds 5] [--also LABEL=path/to/model.json]
    python -m training.aclstm.evaluate --from-json    # aclstm.md again from aclstm.json, measuring nothing

What is measured: training/aclstm/report.py.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..paths import REPORTS_DIR
from ..runs import add_from_json_argument, add_report_arguments, rewrote_from_json
from .report import rewrite_aclstm_markdown, write_dance_report


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_report_arguments(parser, frames=20000, seeds=5, seeds_help="seeds per style")
    parser.add_argument("--also", action="append", default=[], metavar="LABEL=JSON",
                        help="another exported dance model to compare (not shipped), e.g. 'acLSTM v=20=/tmp/x/aclstm.json'")
    add_from_json_argument(parser, "aclstm")
    args = parser.parse_args(argv)
    if rewrote_from_json(args, "aclstm", rewrite_aclstm_markdown):
        return
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
