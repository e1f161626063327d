"""Rebuild the generator's torch checkpoint from the shipped ONNX model and its JSON (training/generator/recovery.py).

    python -m training.generator.recover [--onnx public/models/generator.onnx] [--out runs/generator/best.pt]

For when runs/generator/best.pt is gone (runs/ is not in git) but the model still has to be re-exported.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..paths import MODELS_DIR
from ..runs import RUNS_DIR
from .recovery import recover_checkpoint


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--onnx", type=Path, default=MODELS_DIR / "generator.onnx")
    parser.add_argument("--info", type=Path, default=None, help="generator.json (default: next to --onnx)")
    parser.add_argument("--out", type=Path, default=RUNS_DIR / "generator" / "best.pt")
    parser.add_argument("--force", action="store_true", help="overwrite an existing checkpoint")
    args = parser.parse_args(argv)
    info_path = args.info or args.onnx.with_name("generator.json")
    if args.out.exists() and not args.force:
        raise SystemExit(f"error: {args.out} exists; pass --force to overwrite it")
    state, worst = recover_checkpoint(args.onnx, info_path, args.out)
    print(f"rebuilt {args.out} from {args.onnx} and {info_path.name}: epoch {state['epoch']}, "
          f"max scaled |torch - onnxruntime| = {worst:.2e} at batches 1 and 7")


if __name__ == "__main__":
    main()
