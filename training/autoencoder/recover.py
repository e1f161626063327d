"""Rebuild the motion autoencoder's torch checkpoint from the shipped ONNX graphs and manifold.json
(training/autoencoder/recovery.py).

    python -m training.autoencoder.recover [--info public/models/manifold.json] [--out runs/autoencoder/best.pt]

For when runs/autoencoder/best.pt is gone (runs/ is not in git) but the latent ERD has to be trained or
exported again.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..paths import MODELS_DIR
from ..runs import RUNS_DIR
from .recovery import recover_checkpoint


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--info", type=Path, default=MODELS_DIR / "manifold.json")
    parser.add_argument("--out", type=Path, default=RUNS_DIR / "autoencoder" / "best.pt")
    parser.add_argument("--force", action="store_true", help="overwrite an existing checkpoint")
    args = parser.parse_args(argv)
    if args.out.exists() and not args.force:
        raise SystemExit(f"error: {args.out} exists; pass --force to overwrite it")
    try:
        _, worst = recover_checkpoint(args.info, args.out)
    except (OSError, ValueError, KeyError) as error:
        raise SystemExit(f"error: cannot rebuild the autoencoder from {args.info}: {error}")
    print(f"rebuilt {args.out} from {args.info} and its ONNX graphs: max |torch - onnxruntime| = {worst:.2e}")


if __name__ == "__main__":
    main()
