"""Export the trained generator to ONNX plus its JSON, with seed states and a parity check.

    python -m training.generator.export [--checkpoint runs/generator/best.pt] [--out public/models]

Writes public/models/generator.onnx (one step: x, h, c -> weights, mu, sigma, h_out, c_out; the batch
dimension is dynamic; the graph is built directly, see training/generator/graph.py) and
public/models/generator.json (skeleton, feature layout, normalisation, rotation references, seed states
estimated as in eq. 26, training and parity numbers).
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..paths import MODELS_DIR
from ..runs import RUNS_DIR
from .exporting import export_generator


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--checkpoint", type=Path, default=RUNS_DIR / "generator" / "best.pt")
    parser.add_argument("--out", type=Path, default=MODELS_DIR)
    parser.add_argument("--mocap", default=None)
    args = parser.parse_args(argv)
    if not args.checkpoint.exists():
        raise SystemExit(f"error: no checkpoint at {args.checkpoint}; train first with python -m training.generator.train")
    onnx_path = export_generator(args.checkpoint, args.out, args.mocap)
    print(f"wrote {onnx_path} ({onnx_path.stat().st_size / 1e6:.2f} MB) and generator.json")


if __name__ == "__main__":
    main()
