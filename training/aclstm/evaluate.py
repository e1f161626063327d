"""Evaluate the shipped dance models (and the vanilla baseline, when its files are there) and write
docs/models/aclstm.{md,json,png}.

    python -m training.aclstm.evaluate [--frames 20000] [--seeds 5] [--also LABEL=path/to/model.json]
    python -m training.aclstm.evaluate --from-json    # aclstm.md again from aclstm.json, measuring nothing
    python -m training.aclstm.evaluate --add "acLSTM mdn=public/models/aclstm-mdn.json"   # measure one model, keep the other rows

The models of report.MODELS whose files are in public/models (acLSTM and the mdn model `aclstm-mdn`; the vanilla
baseline left the page on 2026-12-05) are measured on every run, and such a run writes only their rows: to keep the
vanilla baseline's row, restore its files first (report.py says how) or measure it with --add; --also adds a model
that is not shipped. --add measures only the models it names and adds
them to the stored aclstm.json beside its other rows (same --frames and --seeds; aclstm.png is not redrawn, and each
added model gets its own figure, aclstm-<id>.png: its runs against the real held-out seconds' band).

What is measured: training/aclstm/report.py.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..paths import REPORTS_DIR
from ..runs import add_from_json_argument, add_report_arguments, rewrote_from_json
from .report import add_to_dance_report, fair_rule_passes, rewrite_aclstm_markdown, write_dance_report


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_report_arguments(parser, frames=20000, seeds=5, seeds_help="seeds per style")
    parser.add_argument("--also", action="append", default=[], metavar="LABEL=JSON",
                        help="another exported dance model to compare (not shipped), e.g. 'acLSTM v=20=/tmp/x/aclstm.json'")
    parser.add_argument("--add", action="append", default=[], metavar="LABEL=JSON",
                        help="measure only this exported model and add it to the stored report, keeping its other rows")
    add_from_json_argument(parser, "aclstm")
    args = parser.parse_args(argv)
    if rewrote_from_json(args, "aclstm", rewrite_aclstm_markdown):
        return

    def labelled(items: list[str], flag: str) -> list[tuple[str, Path]]:
        out = []
        for item in items:
            label, sep, path = item.rpartition("=")
            if not sep:
                parser.error(f"{flag} wants LABEL=path/to/model.json, got {item!r}")
            out.append((label, Path(path)))
        return out

    if args.add:
        report = add_to_dance_report(args.frames, args.seeds, args.mocap, args.models, labelled(args.add, "--add"))
        print(f"wrote {REPORTS_DIR / 'aclstm.md'} with " + ", ".join(f"{label}: {fair_rule_passes(report['models'][label])} of "
                                                                    f"{len(report['models'][label]['runs'])} pass the fairer rule"
                                                                    for label, _ in labelled(args.add, "--add")))
        return
    extra = labelled(args.also, "--also")
    report = write_dance_report(args.frames, args.seeds, args.mocap, args.models, extra)
    print(f"wrote {REPORTS_DIR / 'aclstm.md'}; " + ", ".join(f"{k}: all stable {m['all_stable']}" for k, m in report["models"].items()))


if __name__ == "__main__":
    main()
