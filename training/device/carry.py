"""Pack files for a lent GPU machine and unpack what comes back (training/device/carried.py says how and why).

    python -m training.device.carry pack-cache .carry/aclstm_positions.xz       # here: the dance cache (built first if missing)
    python -m training.device.carry unpack-cache .carry/aclstm_positions.xz     # there: writes cache/aclstm_positions.npz
    python -m training.device.carry pack-checkpoint runs/R/last.pt $OUT/R-last [--int8]    # there: R-last.part0, part1 …
    python -m training.device.carry unpack-checkpoint DIR/R-last runs/R last.pt            # here: runs/R/last.pt
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..data.dance import CACHE, load_clips
from .carried import pack_checkpoint, pack_positions, unpack_checkpoint, unpack_positions


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("action", choices=["pack-cache", "unpack-cache", "pack-checkpoint", "unpack-checkpoint"])
    parser.add_argument("paths", nargs="+", type=Path)
    parser.add_argument("--int8", action="store_true", help="pack-checkpoint: int8 weights with a scale per row (else float16)")
    args = parser.parse_args(argv)
    if args.action == "pack-cache":
        if not CACHE.exists():
            load_clips()
        pack_positions(CACHE, args.paths[0])
        print(f"wrote {args.paths[0]} ({args.paths[0].stat().st_size / 1e6:.1f} MB)")
    elif args.action == "unpack-cache":
        if CACHE.exists():  # built from ../shared here: keep it exact
            raise SystemExit(f"error: {CACHE} exists; unpack-cache is for a machine without ../shared, and would replace "
                             "it with positions rounded to 10 µm")
        unpack_positions(args.paths[0], CACHE)
        print(f"wrote {CACHE}")
    elif args.action == "pack-checkpoint":
        checkpoint, stem = args.paths
        latest = checkpoint.parent / "checkpoint.pt"
        parts = pack_checkpoint(checkpoint, stem, args.int8, latest if latest.exists() else None)
        print(f"wrote {', '.join(p.name for p in parts)} ({sum(p.stat().st_size for p in parts) / 1e6:.1f} MB)")
    else:
        stem, run_dir, name = args.paths[0], args.paths[1], str(args.paths[2])
        print(f"wrote {unpack_checkpoint(stem, run_dir, name)}")


if __name__ == "__main__":
    main()
