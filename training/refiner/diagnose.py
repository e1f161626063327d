"""Which features give generated walking away in the refiner report's two-sample test: the window and single-frame
classifiers trained on one feature group at a time (pose in the root frame, joint velocities, contact bits), for
every variant (raw, raw + foot lock, refined, refined + foot lock), one classifier seed, 1,500 frames per seed.
Writes docs/models/refiner-feature-groups.json.

    python -m training.refiner.diagnose [--frames 1500]
"""
from __future__ import annotations

import argparse
import json

import numpy as np

from ..paths import REPORTS_DIR
from .report import feature_group_report


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", type=int, default=1500)
    parser.add_argument("--mocap", default=None)
    args = parser.parse_args(argv)
    out = feature_group_report(args.frames, args.mocap)
    path = REPORTS_DIR / "refiner-feature-groups.json"
    path.write_text(json.dumps(out, indent=1) + "\n")
    for v, groups in out["variants"].items():
        print(v, " | ".join(f"{g}: windows {a['window']:.3f}, frames {a['frame']:.3f}" for g, a in groups.items()))
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
