"""Build the acLSTM dance cache (cache/aclstm_positions.npz, training/data/dance.py) and print a summary.
With --extra: cache/aclstm_positions_extra.npz, the set plus the two CMU trials of ../shared/mocap/aclstm-extra/
brought onto its standard skeleton (training/data/dance_extra.py).

    python -m training.data.build_dance [--mocap DIR] [--extra]
"""
from __future__ import annotations

import argparse

from ..paths import add_mocap_argument, resolve_mocap_dir
from .dance import SOURCE_FPS, STYLES, build_cache, load_clips


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_mocap_argument(parser)
    parser.add_argument("--extra", action="store_true", help="include the two converted CMU trials (own cache)")
    args = parser.parse_args(argv)
    out = build_cache(resolve_mocap_dir(args.mocap), extra=args.extra)
    skel, clips = load_clips(args.mocap, extra=args.extra)
    print(f"wrote {out}: {len(skel.names)} points")
    for style in STYLES:
        mine = [c for c in clips if c.style == style]
        secs = sum(c.seconds for c in mine)
        held = [c.file for c in mine if c.held_out]
        print(f"  {style}: {len(mine)} clips, {secs / 60:.1f} min at {SOURCE_FPS[style]:.0f} fps; held out {held}")


if __name__ == "__main__":
    main()
