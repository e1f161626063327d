"""Measure a realism lever quickly and add it to docs/models/refiner-pilots.json (the refiner report's table of levers).

    python -m training.refiner.pilot NAME --checkpoint runs/refiner-joints/last.pt [--note "..."]
    python -m training.refiner.pilot NAME --shipped [--sigma-scale 3-6:0.3] [--rho 0.9]
    python -m training.refiner.pilot NAME --raw-only --sigma-scale 0-68:1.4

A pilot is a refiner (a training checkpoint, the shipped refiner.onnx, or none) behind the shipped generator sampled
at temperature 0.5, optionally with per-feature sigma factors (--sigma-scale FIRST-LAST:FACTOR,...) or another noise
correlation. Measured as training/refiner/pilots.py says: one classifier seed, 1,500 frames per generator seed.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from ..paths import REPORTS_DIR
from .pilots import measure_pilot

PILOTS = REPORTS_DIR / "refiner-pilots.json"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("name", help="the pilot's row name in the table")
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--checkpoint", type=Path, help="a refiner training checkpoint (best.pt, last.pt, checkpoint.pt)")
    source.add_argument("--shipped", action="store_true", help="the shipped public/models/refiner.onnx")
    source.add_argument("--raw-only", action="store_true", help="no refiner: the generator's motion and its foot lock only")
    parser.add_argument("--sigma-scale", default="", help="per-feature sigma factors, e.g. 3-6:0.3 (root height and tilt)")
    parser.add_argument("--rho", type=float, default=None, help="noise correlation instead of generator.json's")
    parser.add_argument("--frames", type=int, default=1500)
    parser.add_argument("--note", default="", help="what the pilot is (training settings, minutes)")
    parser.add_argument("--mocap", default=None)
    args = parser.parse_args(argv)
    if args.checkpoint is not None and not args.checkpoint.exists():
        raise SystemExit(f"error: no checkpoint at {args.checkpoint}")
    result = measure_pilot(args.checkpoint, args.shipped, args.sigma_scale, args.rho, args.frames, args.mocap)
    result["note"] = args.note
    saved = json.loads(PILOTS.read_text()) if PILOTS.exists() else {}
    saved[args.name] = result  # merged into the file as it is now, so pilots measured side by side lose nothing
    PILOTS.write_text(json.dumps(saved, indent=1) + "\n")
    for v, m in result["variants"].items():
        print(f"{args.name} {v}: windows {100 * m['window']:.1f}%, single frames {100 * m['frame']:.1f}%, "
              f"sliding {m['sliding']:.3f} m/s (real {result['real_sliding']:.3f})")
    print(f"wrote {PILOTS} ({result['minutes']:.1f} min)")


if __name__ == "__main__":
    main()
