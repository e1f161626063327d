"""Export a style-generator checkpoint to ONNX plus its JSON (issue 39), with seed states per style and a parity check.

    python -m training.style_generator.export --checkpoint runs/style-generator/best.pt --out DIR [--id style-generator] [--weights int8]

Writes DIR/<id>.onnx (one step: x, h, c, style -> weights, mu, sigma, h_out, c_out; style is float32 (batch, styles),
a one-hot or a blend of styles; the batch dimension is dynamic; training/style_generator/graph.py) and DIR/<id>.json
(the generator's fields plus styles, licence, data, seeds per style from held-out clips, training and parity numbers;
training/style_generator/exporting.py). With --out public/models it also adds the model to public/models/index.json
(data and licence: CC BY-NC 4.0, non-commercial); elsewhere it writes only the two files (docs/models/style-generator.md,
"Export").
"""
from __future__ import annotations

import argparse
from pathlib import Path

import torch

from ..data.style_locomotion import load_styled_clips
from ..generator.training import load_generator
from ..onnx.compact import FORMATS
from .exporting import export_style_generator


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--checkpoint", type=Path, required=True, help="a style-generator checkpoint (best.pt)")
    parser.add_argument("--out", type=Path, required=True, help="folder for <id>.onnx and <id>.json")
    parser.add_argument("--id", default="style-generator", help="the model's id and file names")
    parser.add_argument("--weights", choices=FORMATS, default="int8",
                        help="how the file stores its weights (int8: the mixture head float16, training/generator/graph.py)")
    parser.add_argument("--mocap", default=None)
    parser.add_argument("--threads", type=int, default=1, help="torch CPU threads")
    args = parser.parse_args(argv)
    torch.set_num_threads(args.threads)
    if not args.checkpoint.exists():
        raise SystemExit(f"error: no checkpoint at {args.checkpoint}; train first with python -m training.style_generator.train")
    model, meta, state = load_generator(args.checkpoint)
    onnx_path, info = export_style_generator(model, meta, state, load_styled_clips(args.mocap), args.out, args.id, args.weights)
    print(f"wrote {onnx_path} ({onnx_path.stat().st_size / 1e6:.2f} MB) and {args.id}.json: styles {', '.join(info['styles'])}, "
          f"{len(info['seeds'])} seeds")


if __name__ == "__main__":
    main()
