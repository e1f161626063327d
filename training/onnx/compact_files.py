"""Store the large weights of float32 ONNX exports as float16 or int8 (training/onnx/compact.py), in place, and bring
the `bytes` and `weights` fields of the model JSONs and public/models/index.json up to date.

    python -m training.onnx.compact_files --weights int8 public/models/latent-erd.onnx [...]
    python -m training.onnx.compact_files --refresh          # only the bytes and weights fields

Each model's export stores its weights this way itself; this command is for exports made before that.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..paths import MODELS_DIR
from .compact import FORMATS, compact_file, refresh_bytes


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("files", type=Path, nargs="*")
    parser.add_argument("--weights", choices=FORMATS[1:], default="int8")
    parser.add_argument("--refresh", action="store_true", help="only update the bytes and weights fields")
    parser.add_argument("--models", type=Path, default=MODELS_DIR, help="the folder whose JSONs and index.json to update")
    args = parser.parse_args(argv)
    if not args.refresh and not args.files:
        parser.error("name the ONNX files to compact, or pass --refresh")
    for path in args.files if not args.refresh else []:
        try:
            before, after = compact_file(path, args.weights)
        except (ValueError, FileNotFoundError) as e:
            raise SystemExit(f"error: {e}")
        print(f"{path}: {before / 1e6:.2f} -> {after / 1e6:.2f} MB ({args.weights})")
    refresh_bytes(args.models)
    print(f"updated bytes and weights in {args.models}/*.json and index.json")


if __name__ == "__main__":
    main()
