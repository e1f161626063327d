"""Export the trained motion autoencoder to public/models/manifold-{encoder,decoder}.onnx and manifold.json.

    python -m training.autoencoder.export [--checkpoint runs/autoencoder/best.pt] [--out public/models] [--weights int8]
    python -m training.autoencoder.export --from-shipped [DIR] [--weights int8]   # no checkpoint: rewrite DIR's files

The large weights are stored as --weights (int8 with a scale per output channel by default; training/onnx/compact.py).
Parity (torch holding the weights as stored against onnxruntime) is checked before anything is written to the
manifest; the held-out reconstruction errors of the network as stored go into the JSON. --from-shipped reads the
network back from DIR's graphs (default public/models) and its meta from DIR/manifold.json; compact from a float32
export. Then export the latent ERD again (python -m training.latent_erd.export --from-shipped): its seeds and
fixture come from this autoencoder.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..data.locomotion import load_clips
from ..data.windows import WindowCorpus
from ..onnx.compact import FORMATS
from ..paths import add_mocap_argument
from ..runs import add_export_arguments
from .exporting import export_autoencoder, rewrite_autoencoder
from .training import load_autoencoder


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_mocap_argument(parser)
    add_export_arguments(parser, FORMATS, run="autoencoder", weights_help="how the files store their large weights",
                         shipped_help="no checkpoint: read the network back from DIR's graphs and manifold.json")
    args = parser.parse_args(argv)
    corpus = WindowCorpus(load_clips(args.mocap))
    if args.from_shipped is not None:
        try:
            rewrite_autoencoder(args.from_shipped, corpus, args.out, args.weights)
        except (OSError, ValueError, KeyError) as error:
            raise SystemExit(f"error: cannot read the autoencoder back from {args.from_shipped}: {error}")
        return
    model, meta = load_autoencoder(Path(args.checkpoint))
    export_autoencoder(model, meta, corpus, args.out, args.weights)


if __name__ == "__main__":
    main()
