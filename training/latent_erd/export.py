"""Export the trained latent ERD to public/models/latent-erd.onnx and latent-erd.json (with seeds), and write
tests/fixtures/latent_erd_reference.json. Export the autoencoder first (python -m training.autoencoder.export):
the fixture runs the exported decoder.

    python -m training.latent_erd.export [--checkpoint runs/latent-erd/best.pt] [--out public/models]
    python -m training.latent_erd.export --seeds-only [--out public/models]   # new seeds for the exported network
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..autoencoder.training import load_autoencoder
from ..data.locomotion import load_clips
from ..data.windows import WindowCorpus
from ..paths import MODELS_DIR, REPO_ROOT, add_mocap_argument
from .exporting import export_latent_erd, reseed
from .training import load_erd


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_mocap_argument(parser)
    parser.add_argument("--checkpoint", default=str(REPO_ROOT / "runs" / "latent-erd" / "best.pt"))
    parser.add_argument("--out", default=str(MODELS_DIR))
    parser.add_argument("--seeds-only", action="store_true",
                        help="rewrite only the seeds of --out's latent-erd.json (and the fixture), for its ONNX as it is; "
                             "needs runs/autoencoder/best.pt (python -m training.autoencoder.recover), not the ERD's checkpoint")
    args = parser.parse_args(argv)
    if args.seeds_only:
        autoencoder, _ = load_autoencoder(REPO_ROOT / "runs" / "autoencoder" / "best.pt")
        reseed(Path(args.out), autoencoder, WindowCorpus(load_clips(args.mocap)))
        return
    erd, meta = load_erd(Path(args.checkpoint))
    if meta["space"] != "latent":
        raise SystemExit(f"error: {args.checkpoint} is a {meta['space']}-space ERD; only the latent ERD ships")
    autoencoder, _ = load_autoencoder(Path(meta["autoencoder"]))
    corpus = WindowCorpus(load_clips(args.mocap))
    export_latent_erd(erd, meta, autoencoder, corpus, {}, Path(args.out))


if __name__ == "__main__":
    main()
