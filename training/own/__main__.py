"""Train a model on your own motion: a folder of BVH or ASF/AMC files (plain or gzipped, any humanoid skeleton) in,
a model pack out (ONNX + JSON as the shipped models, card.md and its pose-change plot, all from measurements).

    python -m training.own --data DIR --kind locomotion|dance --out DIR [--minutes 20] [--resume]

locomotion trains the LSTM-GMM generator (Random walk, Path and Steer); dance the acLSTM (Dance), one style.

The folder is read and checked before training starts (training/own/dataset.py); the run keeps its log and
checkpoints in runs/own-<id>/ (--run), resumes with --resume and stops cleanly on Ctrl-C, keeping the last checkpoint.
The same command (--kind locomotion) runs on several processes or machines under torchrun (python -m torch.distributed.run … -m
training.own …); process 0 writes the run and the pack.
docs/training.md, "Train on your own motion", has the whole story.
"""
from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from .dataset import OwnCorpus, RefusedFolder, load_folder
from .distributed import launched_rank
from .dance import train_dance
from .dance_pack import write_dance_pack
from .options import add_own_arguments, apply_kind_defaults, min_clip_frames, pack_id, pack_terms, run_folder
from .pack import export_pack, measure_pack, plot_pose_change, record_measures, write_card
from .trainer import train_locomotion


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m training.own", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    add_own_arguments(parser)
    args = parser.parse_args(argv)
    apply_kind_defaults(args)
    if args.kind == "dance" and int(os.environ.get("WORLD_SIZE", "1")) > 1:
        raise SystemExit("error: --kind dance trains on one process; run it without torchrun (torchrun is for --kind locomotion)")
    model_id = pack_id(args)
    args.run = run_folder(args, model_id)
    lead = launched_rank() == 0  # under torchrun, only process 0 prints, writes and exports
    say = print if lead else (lambda *_: None)
    t0 = time.perf_counter()
    try:
        data = load_folder(args.data, min_clip_frames(args), log=say, source_fps=args.source_fps)
    except RefusedFolder as err:
        message = f"error: {err}"
        raise SystemExit(message if len(message) <= 300 else message[:299] + "…") from None
    say(f"data: {data.minutes:.2f} minutes in {len(data.clips)} clips ({len(data.held_out)} held out), "
          f"read in {time.perf_counter() - t0:.0f} s")
    if args.kind == "dance":
        result = train_dance(data, args)
        if result.interrupted:
            print(f"stopped by Ctrl-C after {result.iterations} iterations; the checkpoint is in {args.run}: "
                  "run the same command with --resume to go on")
            raise SystemExit(130)
        print(f"trained {result.minutes:.1f} minutes, {result.iterations} iterations ({result.stopped}); "
              f"held-out error {result.best:.4f}; run in {args.run}")
        onnx_path, json_path = write_dance_pack(args, data, model_id, result)
        print(f"wrote the pack {model_id} to {args.out}: {onnx_path.name}, {json_path.name}, card.md, pose_change.png")
        return
    result = train_locomotion(OwnCorpus(data), args)
    if result.interrupted:
        say(f"stopped by Ctrl-C after {result.iterations} iterations; the checkpoint is in {args.run}: "
              "run the same command with --resume to go on")
        raise SystemExit(130)
    if not lead:
        return
    print(f"trained {result.minutes:.1f} minutes, {result.iterations} iterations ({result.stopped}); "
          f"held-out NLL {result.best_valid_nll:.3f} per frame; run in {args.run}")
    onnx_path, json_path, info = export_pack(Path(args.run) / "best.pt", data, model_id, args.out, args.weights,
                                              pack_terms(args))
    measures = measure_pack(onnx_path, info, data, args.stability_frames)
    plot_pose_change(measures["stability"], measures["real"]["median_pose_change"], args.out / "pose_change.png")
    write_card(args.out / "card.md", model_id, data, result, info, measures)
    record_measures(json_path, info, result, measures)
    print(f"wrote the pack {model_id} to {args.out}: {onnx_path.name}, {json_path.name}, card.md, pose_change.png")


if __name__ == "__main__":
    main()
