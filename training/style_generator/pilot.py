"""Measure a style-generator checkpoint against the shipped generator on raw output (issue 39's pilots), and write
the numbers to docs/models/style-generator-pilot.json.

    python -m training.style_generator.pilot --checkpoint runs/style-pilot/best.pt [--frames 1500] [--steps 1500]
    python -m training.style_generator.pilot --checkpoint runs/style-pilot/best.pt --refiner runs/style-refiner-joints/best.pt \
        --out docs/models/style-refiner-pilot-1250.json     # also the style model's motion locked, refined, refined + locked

What is measured, and how both models are sampled alike, is in training/style_generator/pilots.py: held-out NLL per
style, the refiner report's two-sample test cut down (one classifier seed, --frames per seed), the hip-bob spectrum,
root speed and the lowest pose change. The shipped generator has no style input, so its streams are measured on CMU.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import torch

from ..data.style_locomotion import STYLES
from ..paths import REPORTS_DIR
from ..refiner.pilots import CheckpointRefiner
from .pilots import PILOT_FRAMES, TEMPERATURE, measure, shipped_candidate, style_candidate


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--checkpoint", type=Path, default=None, help="a style-generator checkpoint (none: the shipped generator only)")
    parser.add_argument("--frames", type=int, default=PILOT_FRAMES, help="frames per seed and stream set")
    parser.add_argument("--steps", type=int, default=None, help="classifier training steps (default 1,500, the report's)")
    parser.add_argument("--classifier-seeds", type=int, default=1, help="classifiers per test (the report uses 3)")
    parser.add_argument("--temperature", type=float, default=TEMPERATURE, help="sampling temperature of both models (the page's 0.5)")
    parser.add_argument("--styles", default=",".join(STYLES), help="styles the style generator is sampled in")
    parser.add_argument("--refiner", type=Path, default=None,
                        help="a refiner training checkpoint (python -m training.refiner.train --style-generator ...): the style "
                             "model's streams are also measured with the foot lock, refined, and refined with the lock")
    parser.add_argument("--out", type=Path, default=REPORTS_DIR / "style-generator-pilot.json")
    parser.add_argument("--mocap", default=None)
    parser.add_argument("--threads", type=int, default=1, help="torch CPU threads (more than the free cores slows it badly)")
    args = parser.parse_args(argv)
    torch.set_num_threads(args.threads)
    cands = [shipped_candidate()]
    styles = {cands[0].name: ["cmu"]}
    if args.checkpoint is not None:
        if not args.checkpoint.exists():
            raise SystemExit(f"error: no checkpoint at {args.checkpoint}")
        cands.append(style_candidate(args.checkpoint))
        styles[cands[1].name] = [s for s in args.styles.split(",") if s]
    refiner = None
    if args.refiner is not None:
        if args.checkpoint is None or not args.refiner.exists():
            raise SystemExit(f"error: --refiner needs --checkpoint and an existing refiner checkpoint ({args.refiner})")
        refiner = CheckpointRefiner(args.refiner)
    result = measure(cands, styles, args.frames, steps=args.steps, mocap=args.mocap,
                     classifier_seeds=args.classifier_seeds, temperature=args.temperature, refiner=refiner)
    result["checkpoint"] = str(args.checkpoint) if args.checkpoint else None
    result["refiner"] = str(args.refiner) if args.refiner else None
    args.out.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {args.out} ({result['minutes']:.1f} min)")


if __name__ == "__main__":
    main()
