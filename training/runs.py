"""Shared plumbing for training runs: run directory, log file, timed checkpoints, resume; the start and end every
training loop shares (TrainingLoop), and the flags the train, export and evaluate commands share."""
from __future__ import annotations

import argparse
import json
import logging
import time
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

from .paths import MODELS_DIR, REPO_ROOT, REPORTS_DIR, add_mocap_argument

RUNS_DIR = REPO_ROOT / "runs"


def add_run_arguments(parser: argparse.ArgumentParser, run: str, minutes: float, iterations: int | None = None) -> None:
    """The flags every train command has, with its default run name and time budget (TrainingLoop reads them),
    and --iterations with its default where the command counts its run in iterations."""
    add_mocap_argument(parser)
    parser.add_argument("--run", default=run, help="run name under runs/")
    if iterations is not None:
        parser.add_argument("--iterations", type=int, default=iterations, help="training iterations in all")
    parser.add_argument("--minutes", type=float, default=minutes, help="stop cleanly after this much training time")
    parser.add_argument("--checkpoint-minutes", type=float, default=3.0, help="minutes between checkpoints")
    parser.add_argument("--resume", action="store_true", help="continue from runs/<run>/checkpoint.pt")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--threads", type=int, default=1, help="torch CPU threads (1 is steadiest when the machine is shared)")


def add_export_arguments(parser: argparse.ArgumentParser, weight_formats, weights_help: str, shipped_help: str,
                         run: str | None = None) -> None:
    """The flags the export commands share: with `run`, --checkpoint (default runs/<run>/best.pt); where the files
    go, how they store their large weights (`weight_formats`: onnx/compact.py FORMATS, passed in since runs.py sits
    below onnx/), and --from-shipped DIR (default public/models) to rewrite an exported model without a checkpoint."""
    if run is not None:
        parser.add_argument("--checkpoint", type=Path, default=RUNS_DIR / run / "best.pt")
    parser.add_argument("--out", type=Path, default=MODELS_DIR)
    parser.add_argument("--weights", choices=weight_formats, default="int8", help=weights_help)
    parser.add_argument("--from-shipped", type=Path, nargs="?", const=MODELS_DIR, default=None, metavar="DIR",
                        help=shipped_help)


def add_report_arguments(parser: argparse.ArgumentParser, frames: int, seeds: int, seeds_help: str | None = None) -> None:
    """The flags the evaluate commands of the exported models share: how long and how many runs to draw, the
    corpus and the folder of the exported models."""
    parser.add_argument("--frames", type=int, default=frames, help="frames per seed")
    parser.add_argument("--seeds", type=int, default=seeds, help=seeds_help)
    add_mocap_argument(parser)
    parser.add_argument("--models", type=Path, default=MODELS_DIR, help="directory with the exported models")


def add_from_json_argument(parser: argparse.ArgumentParser, report: str) -> None:
    """--from-json: the evaluate command of docs/models/<report>.md writes it again from <report>.json (rewrote_from_json)."""
    parser.add_argument("--from-json", action="store_true", help=f"only write {report}.md from the stored {report}.json")


def rewrote_from_json(args: argparse.Namespace, report: str, rewrite_markdown) -> bool:
    """With --from-json, write docs/models/<report>.md again from the stored <report>.json, measuring nothing
    (`rewrite_markdown` does it), and say so; whether it did, so the command can stop there."""
    if not args.from_json:
        return False
    rewrite_markdown()
    print(f"wrote {REPORTS_DIR / f'{report}.md'} from {report}.json")
    return True


def on_cpu(state):
    """`state` (nested dicts, lists and tuples of tensors and plain values) with every tensor on the CPU, so a
    checkpoint written by a GPU run loads anywhere."""
    if isinstance(state, torch.Tensor):
        return state.detach().cpu()
    if isinstance(state, dict):
        return {k: on_cpu(v) for k, v in state.items()}
    if isinstance(state, tuple) and hasattr(state, "_fields"):  # a named tuple
        return type(state)(*(on_cpu(v) for v in state))
    if isinstance(state, (list, tuple)):
        return type(state)(on_cpu(v) for v in state)
    return state


class Run:
    """A training run living in runs/<name>/: train.log, checkpoint.pt (latest), best.pt."""

    def __init__(self, name: str, checkpoint_minutes: float = 3.0):
        self.dir = RUNS_DIR / name
        self.dir.mkdir(parents=True, exist_ok=True)
        self.checkpoint_path = self.dir / "checkpoint.pt"
        self.best_path = self.dir / "best.pt"
        self.log = logging.getLogger(f"run.{name}")
        self.log.setLevel(logging.INFO)
        if not self.log.handlers:
            handler = logging.FileHandler(self.dir / "train.log")
            handler.setFormatter(logging.Formatter("%(asctime)s %(message)s"))
            self.log.addHandler(handler)
        self.interval = checkpoint_minutes * 60
        self.last_save = time.monotonic()

    def save(self, state: dict, path: Path | None = None) -> None:
        path = path or self.checkpoint_path
        tmp = path.with_suffix(".tmp")
        torch.save(on_cpu(state), tmp)  # on the CPU: load_state_dict puts each part back on its own device
        tmp.replace(path)  # never leave a half-written checkpoint behind
        if path == self.checkpoint_path:
            self.last_save = time.monotonic()

    def due(self) -> bool:
        return time.monotonic() - self.last_save >= self.interval

    def load(self) -> dict | None:
        if not self.checkpoint_path.exists():
            return None
        # On the CPU first: load_state_dict then puts each part on its own device (a GPU run resumes on the GPU).
        return torch.load(self.checkpoint_path, map_location="cpu", weights_only=False)

    def resume(self, rng, **parts) -> dict:
        """Restore each of `parts` (models, optimisers, schedules: anything with load_state_dict, saved under
        the same key) and both random generators from the latest checkpoint; returns the checkpoint for the
        caller's own counters. Exits with a message when there is none."""
        state = self.load()
        if state is None:
            raise SystemExit(f"error: --resume but no checkpoint at {self.checkpoint_path}")
        missing = [key for key in (*parts, "rng", "torch_rng") if key not in state]
        if missing:
            raise SystemExit(f"error: --resume, but {self.checkpoint_path} lacks {', '.join(missing)}"
                             + (f" ({state['note']})" if "note" in state else ""))
        for key, part in parts.items():
            part.load_state_dict(state[key])
        rng.bit_generator.state = state["rng"]
        torch.set_rng_state(state["torch_rng"])
        if "cuda_rng" in state and torch.cuda.is_available():  # a GPU run's own generator (draws made on the GPU)
            torch.cuda.set_rng_state_all(state["cuda_rng"])
        return state


class TrainingLoop:
    """The start and end of a training loop, from the flags of add_run_arguments (args.run, .minutes,
    .checkpoint_minutes, .resume, .seed, .threads): the run directory, torch's threads and seed, resuming,
    the clock over all sessions of the run, the progress bar, timed checkpoints, the stop at --minutes, and
    the last checkpoint and summary.json at the end. A recipe keeps its best validation measure in `best`.

    A checkpoint holds each part's state_dict under its name, the random generators, `iteration`, `best`,
    `elapsed` (seconds trained in all sessions), `meta` and what the recipe adds to it (`extra`)."""

    def __init__(self, args: argparse.Namespace, run: Run | None = None):
        self.args = args
        torch.set_num_threads(args.threads)
        self.run = run or Run(args.run, args.checkpoint_minutes)  # `run`: another Run (own/distributed.py's followers)
        self.log = self.run.log
        self.best = float("inf")
        self.stopped = "iterations done"
        self.elapsed_before = 0.0
        self.t0 = time.monotonic()

    def seed(self) -> np.random.Generator:
        """numpy's generator for --seed, with torch's seeded too. Each recipe calls it where it always seeded (some
        before building the model, some after), so a run draws the same numbers as before."""
        torch.manual_seed(self.args.seed)
        self.rng = np.random.default_rng(self.args.seed)
        return self.rng

    def start(self, meta: dict, position: str = "iteration {iteration}", **parts) -> int:
        """Resume from runs/<run>/checkpoint.pt with --resume (restoring `parts`, the random generators of
        seed(), `best` and the clock; the checkpoint stays in `resumed` for the recipe's own counters), else
        start fresh. Returns the iteration to start from. `position` says in the log where a checkpoint stands,
        from its fields; `parts["model"]` is counted in `parameters`."""
        self.meta, self.parts, self.position = meta, parts, position
        self.parameters = sum(p.numel() for p in parts["model"].parameters())
        self.resumed = self.run.resume(self.rng, **parts) if self.args.resume else None
        iteration = 0
        if self.resumed is not None:
            iteration, self.best = self.resumed["iteration"], self.resumed["best"]
            self.start_clock(self.resumed["elapsed"])
            self.log.info("resumed at " + position.format(**self.resumed))
        else:
            self.start_clock(0.0)
        return iteration

    def start_clock(self, elapsed_before: float) -> None:
        """Count training time from now on top of `elapsed_before` seconds of earlier sessions."""
        self.elapsed_before, self.t0 = elapsed_before, time.monotonic()

    def elapsed(self) -> float:
        """Seconds trained, in all sessions of the run."""
        return self.elapsed_before + time.monotonic() - self.t0

    def out_of_time(self) -> bool:
        """Whether the --minutes budget is used; if so, that is why the run stopped."""
        if self.elapsed() <= self.args.minutes * 60:
            return False
        self.stopped = f"time budget of {self.args.minutes:.0f} minutes used"
        return True

    def progress_bar(self, desc: str, total: int, initial: int, unit: str = "it") -> tqdm:
        self.bar = tqdm(total=total, initial=initial, desc=desc, unit=unit)
        return self.bar

    def checkpoint(self, iteration: int, **extra) -> dict:
        return {**{k: p.state_dict() for k, p in self.parts.items()}, "rng": self.rng.bit_generator.state,
                "torch_rng": torch.get_rng_state(),
                **({"cuda_rng": torch.cuda.get_rng_state_all()} if torch.cuda.is_initialized() else {}),
                "iteration": iteration, "best": self.best,
                "elapsed": self.elapsed(), **extra, "meta": self.meta}

    def save(self, iteration: int, **extra) -> None:
        self.run.save(self.checkpoint(iteration, **extra))

    def step_done(self, iteration: int, **extra) -> bool:
        """After a step: a checkpoint at `iteration` when one is due; True when the time budget is used (stop)."""
        if self.run.due():
            self.save(iteration, **extra)
        return self.out_of_time()

    def finish(self, iteration: int, summary: dict, save_last: bool = False, **extra) -> None:
        """Close the bar, log why the run stopped, save the checkpoint at `iteration` (with `extra`) and, with
        `save_last`, the last weights as last.pt beside best.pt; write summary.json: `summary`, then the minutes
        trained and the parameter count."""
        self.bar.close()
        self.log.info("stopped: %s (%s)", self.stopped, self.position.format(iteration=iteration, **extra))
        self.save(iteration, **extra)
        if save_last:
            self.run.save({"model": self.parts["model"].state_dict(), "iteration": iteration, "meta": self.meta},
                          self.run.dir / "last.pt")
        summary = {**summary, "minutes": self.elapsed() / 60, "parameters": self.parameters}
        (self.run.dir / "summary.json").write_text(json.dumps(summary, indent=1))
