"""Time the page's peers for npm run bench -- peers: a PyTorch eager loop of each shipped network and native
onnxruntime on its ONNX step, one stream, one thread (training/bench/peer_loops.py says what each loop runs).
With --ceiling, first writes the generator's matrix-products-only graph there (training/bench/ceiling.py) for
the page to time, and times it and the shipped generator natively at batch 64, one thread. Prints one JSON line.

    python -m training.bench.peers [--frames 2000] [--ceiling tmp/bench/generator-ceiling.onnx]
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from ..paths import MODELS_DIR
from .ceiling import native_batch_rate, write_ceiling
from .peer_loops import measure_peers

BATCH = 64


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", type=int, default=2000, help="timed frames per loop (after 100 untimed)")
    parser.add_argument("--models", type=Path, default=MODELS_DIR)
    parser.add_argument("--ceiling", type=Path, default=None,
                        help="write the generator's products-only graph here and time it natively at batch 64")
    parser.add_argument("--batch-calls", type=int, default=300, help="timed batch-64 calls per graph (after 30 untimed)")
    args = parser.parse_args(argv)
    out = {}
    if args.ceiling:
        out["ceiling"] = write_ceiling(args.models, args.ceiling)
        rate = lambda path: native_batch_rate(path, BATCH, args.batch_calls, 30, threads=1)
        native = {"generator": rate(args.models / "generator.onnx"), "ceiling": rate(args.ceiling)}
        native["generator_over_ceiling"] = native["generator"]["particle_steps_per_s"] / native["ceiling"]["particle_steps_per_s"]
        out["batch64_native"] = {"batch": BATCH, "threads": 1, "calls": args.batch_calls, **native}
    out.update(measure_peers(args.models, args.frames))
    print(json.dumps(out))


if __name__ == "__main__":
    main()
