"""Export the dance models (acLSTM and its vanilla baseline) to ONNX plus JSON, parity checked.

    python -m training.aclstm.export [--run aclstm] [--id aclstm]
    python -m training.aclstm.export --run aclstm-vanilla --id aclstm-vanilla --out /tmp/vanilla   # the baseline, not shipped since 2026-12-05
    python -m training.aclstm.export --id aclstm --from-shipped [--weights int8]   # no checkpoint: rewrite the shipped file
    python -m training.aclstm.export --checkpoint runs/aclstm-mdn-dt35-s1/last.pt --id aclstm-mdn [--out DIR] [--tune-frames 3000]

An mdn head (issue 42) also gets its sampling block (phrase parameters tuned per style on held-out windows, the
output filter per style) and its parity fixture (tests/fixtures/aclstm_mdn_reference.json when written into
public/models, else beside the files).

What the files hold: training/aclstm/exporting.py.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..runs import RUNS_DIR, add_export_arguments
from ..onnx.compact import ALL_FORMATS
from .exporting import export_dance_model, rewrite_dance_model


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--run", default="aclstm", help="run under runs/")
    parser.add_argument("--checkpoint", default="best.pt",
                        help="file in the run directory (best.pt or last.pt), or a path to a checkpoint")
    parser.add_argument("--id", default=None, help="model id and file name (default: the run name)")
    parser.add_argument("--mocap", default=None)
    parser.add_argument("--temperature", type=float, default=0.2, help="a Gaussian head's sampling temperature (kept in the JSON)")
    parser.add_argument("--tune-frames", type=int, default=1200,
                        help="an mdn head: frames of each tuning rollout choosing its phrase parameters per style")
    add_export_arguments(parser, ALL_FORMATS, weights_help="how the file stores its large weights (int8 with a scale per output "
                                                          "channel; int4 in blocks, rounded on the training clips: docs/models/weights.md)",
                         shipped_help="no checkpoint: read the network back from DIR/<id>.onnx (default the shipped one) and keep its JSON")
    args = parser.parse_args(argv)
    model_id = args.id or args.run
    if args.from_shipped is not None:
        onnx_path = rewrite_dance_model(args.from_shipped, model_id, args.out, args.weights, args.mocap)
        print(f"wrote {onnx_path} ({onnx_path.stat().st_size / 1e6:.2f} MB) and {model_id}.json")
        return
    checkpoint = Path(args.checkpoint)
    if not checkpoint.is_file():
        checkpoint = RUNS_DIR / args.run / args.checkpoint
    if not checkpoint.exists():
        raise SystemExit(f"error: no checkpoint at {checkpoint}; train first with python -m training.aclstm.train")
    onnx_path = export_dance_model(checkpoint, model_id, args.out, args.mocap, args.weights, args.temperature, args.tune_frames)
    print(f"wrote {onnx_path} ({onnx_path.stat().st_size / 1e6:.2f} MB) and {model_id}.json")


if __name__ == "__main__":
    main()
