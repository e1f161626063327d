"""Time the page's peers for npm run bench -- peers: a PyTorch eager loop of each shipped network and native
onnxruntime on its ONNX step, one stream, one thread (training/bench/peer_loops.py says what each loop runs). Prints
one JSON line.

    python -m training.bench.peers [--frames 2000]
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from ..paths import MODELS_DIR
from .peer_loops import measure_peers


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", type=int, default=2000, help="timed frames per loop (after 100 untimed)")
    parser.add_argument("--models", type=Path, default=MODELS_DIR)
    args = parser.parse_args(argv)
    print(json.dumps(measure_peers(args.models, args.frames)))


if __name__ == "__main__":
    main()
