"""Measure a trained style generator per style (issue 39's report), and write docs/models/style-generator-full.{json,md}.

    python -m training.style_generator.evaluate --checkpoint runs/style-generator-c/best.pt [--frames 10000]

Raw output against the shipped generator (pilots.measure: held-out NLL, two-sample test, hip bob, speed), the style
check (style_check.py), and long runs with stability and sliding per style (evaluation.py).
"""
from __future__ import annotations

import argparse
import datetime
import json
from pathlib import Path

import torch

from ..data.style_locomotion import STYLES, load_styled_clips
from ..paths import REPORTS_DIR
from .evaluation import long_runs, report_markdown
from .pilots import measure, shipped_candidate, style_candidate
from .style_check import style_check


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--checkpoint", type=Path, required=True)
    parser.add_argument("--frames", type=int, default=10_000, help="frames per long run")
    parser.add_argument("--pilot-frames", type=int, default=3000, help="frames per seed and stream set of the two-sample test")
    parser.add_argument("--classifier-seeds", type=int, default=3)
    parser.add_argument("--steps", type=int, default=None, help="two-sample classifier training steps (default the report's 1,500)")
    parser.add_argument("--styles", default=",".join(STYLES), help="styles of the two-sample test (all by default)")
    parser.add_argument("--out", type=Path, default=REPORTS_DIR / "style-generator-full.json")
    parser.add_argument("--mocap", default=None)
    parser.add_argument("--threads", type=int, default=1)
    args = parser.parse_args(argv)
    if not args.checkpoint.exists():
        raise SystemExit(f"error: no checkpoint at {args.checkpoint}")
    torch.set_num_threads(args.threads)
    shipped, style = shipped_candidate(), style_candidate(args.checkpoint)
    clips = load_styled_clips(args.mocap)
    result = {"checkpoint": str(args.checkpoint), "date": datetime.date.today().isoformat()}
    save = lambda: args.out.write_text(json.dumps(result, indent=1) + "\n")  # after each part: nothing measured is lost
    result["long_runs"] = long_runs(style, clips, list(STYLES), args.frames)
    save()
    result["style_check"] = style_check(style, clips)
    save()
    styles = [s for s in args.styles.split(",") if s]
    result["pilot"] = measure([shipped, style], {shipped.name: ["cmu"], style.name: styles}, args.pilot_frames,
                              steps=args.steps, mocap=args.mocap, classifier_seeds=args.classifier_seeds)
    save()
    args.out.with_suffix(".md").write_text(report_markdown(result))
    print(f"wrote {args.out} and {args.out.with_suffix('.md')}")


if __name__ == "__main__":
    main()
