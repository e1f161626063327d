"""Evaluate the shipped generator against its held-out real clips and write docs/models/generator.{md,json,png}.

    python -m training.generator.evaluate [--frames 10000] [--seeds 5] [--temperature 0.5] [--sweep 1.0,0.5,0.25]
    python -m training.generator.evaluate --from-json    # generator.md again from generator.json, measuring nothing

Foot skating, root speed and turning-rate distributions, NPSS, a long stability run and a temperature
sweep (training/generator/report.py).
"""
from __future__ import annotations

import argparse

from ..paths import REPORTS_DIR
from ..runs import add_from_json_argument, add_report_arguments, rewrote_from_json
from .report import rewrite_generator_markdown, write_generator_report


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_report_arguments(parser, frames=10000, seeds=5)
    parser.add_argument("--temperature", type=float, default=0.5, help="the playground's default")
    parser.add_argument("--sweep", default="1.0,0.5,0.25", help="temperatures for the comparison table ('' to skip)")
    parser.add_argument("--sweep-frames", type=int, default=3000)
    add_from_json_argument(parser, "generator")
    args = parser.parse_args(argv)
    if rewrote_from_json(args, "generator", rewrite_generator_markdown):
        return
    sweep = [float(t) for t in args.sweep.split(",") if t.strip()]
    report = write_generator_report(args.frames, args.seeds, args.temperature, sweep, args.sweep_frames, args.mocap,
                                    args.models)
    print(f"wrote {REPORTS_DIR / 'generator.md'}; all stable: {report['all_stable']}")


if __name__ == "__main__":
    main()
