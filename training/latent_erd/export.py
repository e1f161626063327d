"""Export the trained latent ERD to public/models/latent-erd.onnx and latent-erd.json (with seeds), and write
tests/fixtures/latent_erd_reference.json. Export the autoencoder first (python -m training.autoencoder.export):
the fixture runs the exported decoder.

    python -m training.latent_erd.export [--checkpoint runs/latent-erd/best.pt] [--out public/models] [--weights int8]
    python -m training.latent_erd.export --from-shipped [DIR] [--weights int8]   # no checkpoint: rewrite DIR's file
    python -m training.latent_erd.export --seeds-only [--out public/models]       # new seeds for the exported network

The large weights are stored as --weights (int8 with a scale per output channel by default; training/onnx/compact.py),
parity checked against torch holding the weights as stored. --from-shipped reads the network back from
DIR/latent-erd.onnx (default public/models) and keeps its JSON but for the parity fields, the seeds (picked again
through --out's exported autoencoder) and the bytes; compact from a float32 export. --seeds-only and --from-shipped
need no checkpoint: the autoencoder is read from --out's manifold graphs.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..autoencoder.training import load_autoencoder
from ..data.locomotion import load_clips
from ..data.windows import WindowCorpus
from ..onnx.compact import FORMATS
from ..paths import add_mocap_argument
from ..runs import add_export_arguments
from .exporting import export_latent_erd, reseed, rewrite_latent_erd
from .training import load_erd


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_mocap_argument(parser)
    add_export_arguments(parser, FORMATS, run="latent-erd", weights_help="how the file stores its large weights",
                         shipped_help="no checkpoint: read the network back from DIR/latent-erd.onnx and keep DIR/latent-erd.json")
    parser.add_argument("--seeds-only", action="store_true",
                        help="rewrite only the seeds of --out's latent-erd.json (and the fixture), for its ONNX as it is")
    args = parser.parse_args(argv)
    if args.seeds_only or args.from_shipped is not None:
        corpus = WindowCorpus(load_clips(args.mocap))
        try:
            if args.seeds_only:
                reseed(args.out, corpus)
            else:
                rewrite_latent_erd(args.from_shipped, args.out, corpus, args.weights)
        except (OSError, ValueError, KeyError) as error:
            raise SystemExit(f"error: cannot rewrite the exported latent ERD: {error}")
        return
    erd, meta = load_erd(Path(args.checkpoint))
    if meta["space"] != "latent":
        raise SystemExit(f"error: {args.checkpoint} is a {meta['space']}-space ERD; only the latent ERD ships")
    autoencoder, _ = load_autoencoder(Path(meta["autoencoder"]))
    corpus = WindowCorpus(load_clips(args.mocap))
    export_latent_erd(erd, meta, autoencoder, corpus, {}, args.out, args.weights)


if __name__ == "__main__":
    main()
