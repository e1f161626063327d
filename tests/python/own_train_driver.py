"""The training of python -m training.own without the pack: for tests/python/test_own_ddp.py, run as one process or
under torchrun. Process 0 writes the loss of each iteration to <run>/losses.json."""
import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from training.own.dataset import OwnCorpus, load_folder  # noqa: E402
from training.own.options import add_own_arguments, apply_kind_defaults, min_clip_frames  # noqa: E402
from training.own.trainer import train_locomotion  # noqa: E402

parser = argparse.ArgumentParser()
add_own_arguments(parser)
args = parser.parse_args()
apply_kind_defaults(args)
result = train_locomotion(OwnCorpus(load_folder(args.data, min_clip_frames(args), log=lambda *_: None)), args)
if result.lead:
    (Path(args.run) / "losses.json").write_text(json.dumps(result.losses))
