"""Measure the shipped latent ERD and write docs/models/latent-erd.{md,json}.

    python -m training.latent_erd.evaluate [--frames 10000] [--seeds 5]
    python -m training.latent_erd.evaluate --from-json    # latent-erd.md again from latent-erd.json, measuring nothing

Run npm run evaluate:latent-erd first for the page's numbers (paths, live control); the measures are
described in training/latent_erd/measures.py.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from ..paths import REPO_ROOT, REPORTS_DIR, add_mocap_argument
from ..runs import add_from_json_argument, rewrote_from_json
from .report import rewrite_latent_erd_markdown, write_report

NOTES = REPORTS_DIR / "latent-erd-notes.json"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_mocap_argument(parser)
    parser.add_argument("--frames", type=int, default=10000)
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--pose-checkpoint", default=str(REPO_ROOT / "runs" / "pose-erd" / "last.pt"),
                        help="the pose-space baseline: its last checkpoint, after the input-noise ramp (its best next-step loss came before the noise)")
    add_from_json_argument(parser, "latent-erd")
    args = parser.parse_args(argv)
    if rewrote_from_json(args, "latent-erd", rewrite_latent_erd_markdown):
        return
    notes = json.loads(NOTES.read_text()) if NOTES.exists() else {}
    report = write_report(args.mocap, args.frames, args.seeds, Path(args.pose_checkpoint), notes)
    print(f"wrote {REPORTS_DIR / 'latent-erd.md'}: {report['long_runs']['collapsed']} of {args.seeds} long runs collapsed")


if __name__ == "__main__":
    main()
