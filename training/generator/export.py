"""Export the trained generator to ONNX plus its JSON, with seed states and a parity check.

    python -m training.generator.export [--checkpoint runs/generator/best.pt] [--out public/models] [--weights int8]
    python -m training.generator.export --from-shipped [DIR] [--weights int8]   # no checkpoint: rewrite the shipped file

Writes public/models/generator.onnx (one step: x, h, c -> weights, mu, sigma, h_out, c_out; the batch
dimension is dynamic; the graph is built directly, see training/generator/graph.py) and
public/models/generator.json (skeleton, feature layout, normalisation, rotation references, seed states
estimated as in eq. 26, training and parity numbers). Weights are stored as int8 with the mixture head float16
(training/onnx/compact.py), turned back into float32 when the session is created.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..runs import add_export_arguments
from ..onnx.compact import FORMATS
from .exporting import export_generator, rewrite_generator


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mocap", default=None)
    add_export_arguments(parser, FORMATS, run="generator",
                         weights_help="how the file stores its weights (int8: the mixture head float16, training/generator/graph.py)",
                         shipped_help="no checkpoint: read the network back from DIR/generator.onnx (default the shipped one) and keep its JSON")
    args = parser.parse_args(argv)
    if args.from_shipped is not None:
        onnx_path = rewrite_generator(args.from_shipped, args.out, args.weights)
        print(f"wrote {onnx_path} ({onnx_path.stat().st_size / 1e6:.2f} MB) and generator.json")
        return
    if not args.checkpoint.exists():
        raise SystemExit(f"error: no checkpoint at {args.checkpoint}; train first with python -m training.generator.train")
    onnx_path = export_generator(args.checkpoint, args.out, args.mocap, args.weights)
    print(f"wrote {onnx_path} ({onnx_path.stat().st_size / 1e6:.2f} MB) and generator.json")


if __name__ == "__main__":
    main()
