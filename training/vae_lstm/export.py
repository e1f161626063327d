"""Export the trained VAE-LSTM to public/models/vae-lstm*.onnx and vae-lstm.json (parity checked), and write
tests/fixtures/vae_lstm_reference.json.

    python -m training.vae_lstm.export [--checkpoint runs/vae-lstm/best.pt] [--out public/models]
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..paths import MODELS_DIR, REPO_ROOT
from .exporting import export_vae_lstm
from .training import load_vae_lstm


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--checkpoint", default=str(REPO_ROOT / "runs" / "vae-lstm" / "best.pt"))
    parser.add_argument("--out", default=str(MODELS_DIR))
    args = parser.parse_args(argv)
    checkpoint = Path(args.checkpoint)
    if not checkpoint.exists():
        raise SystemExit(f"error: no checkpoint at {checkpoint} (train first: python -m training.vae_lstm.train)")
    model, meta = load_vae_lstm(checkpoint)
    export_vae_lstm(model, meta, {}, Path(args.out))


if __name__ == "__main__":
    main()
