"""Export the trained motion autoencoder to public/models/manifold-{encoder,decoder}.onnx and manifold.json.

    python -m training.autoencoder.export [--checkpoint runs/autoencoder/best.pt] [--out public/models]

Parity (torch against onnxruntime) is checked before anything is written to the manifest; the held-out
reconstruction errors go into the JSON.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..data.locomotion import load_clips
from ..data.windows import WindowCorpus
from ..paths import MODELS_DIR, REPO_ROOT, add_mocap_argument
from .exporting import export_autoencoder
from .training import control_rmse, live_channels, load_autoencoder, position_error_cm


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_mocap_argument(parser)
    parser.add_argument("--checkpoint", default=str(REPO_ROOT / "runs" / "autoencoder" / "best.pt"))
    parser.add_argument("--out", default=str(MODELS_DIR))
    args = parser.parse_args(argv)
    model, meta = load_autoencoder(Path(args.checkpoint))
    corpus = WindowCorpus(load_clips(args.mocap))
    windows = corpus.valid_windows()
    report = {"held_out_windows": len(windows),
              "reconstruction_cm_clean": round(position_error_cm(model, corpus, windows), 3),
              "reconstruction_cm_masked_0.3": round(position_error_cm(model, corpus, windows, 0.3), 3),
              "control_rmse": [round(float(v), 4) for v in control_rmse(model, corpus, windows)],
              "live_latent_channels": live_channels(model, corpus)}
    export_autoencoder(model, meta, windows, report, Path(args.out))


if __name__ == "__main__":
    main()
