"""Export the trained refiner R as a causal streaming model (ONNX) plus its JSON, parity-checked.

    python -m training.refiner.export [--checkpoint runs/refiner/shipped.pt] [--out public/models]
    python -m training.refiner.export --checkpoint runs/refiner/checkpoint.pt --recover runs/refiner/shipped.pt
        (rebuild the torch checkpoint of the shipped export; see training/refiner/graph.py refiner_from_onnx)

The graph and its inputs are described in training/refiner/graph.py; the JSON, fixture and manifest entry in
training/refiner/exporting.py.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..paths import MODELS_DIR
from ..runs import RUNS_DIR
from .exporting import export_refiner, recover_checkpoint


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--checkpoint", type=Path, default=RUNS_DIR / "refiner" / "shipped.pt",
                        help="the shipped model's checkpoint (a run's best.pt or last.pt to try another)")
    parser.add_argument("--out", type=Path, default=MODELS_DIR)
    parser.add_argument("--recover", type=Path, default=None, metavar="OUT.pt",
                        help="instead of exporting: rebuild a torch checkpoint for the shipped refiner.onnx into OUT.pt "
                             "(meta from --checkpoint, a checkpoint of the same run)")
    args = parser.parse_args(argv)
    if args.recover is not None:
        diff = recover_checkpoint(MODELS_DIR / "refiner.onnx", args.checkpoint, MODELS_DIR / "refiner.json", args.recover)
        print(f"wrote {args.recover}; its re-export differs from the shipped export by {diff:.2e}")
        return
    if not args.checkpoint.exists():
        raise SystemExit(f"error: no checkpoint at {args.checkpoint}; train first with python -m training.refiner.train")
    onnx_path = export_refiner(args.checkpoint, args.out)
    print(f"wrote {onnx_path} ({onnx_path.stat().st_size / 1e6:.2f} MB) and refiner.json")


if __name__ == "__main__":
    main()
