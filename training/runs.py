"""Shared plumbing for training runs: run directory, log file, timed checkpoints, resume."""
from __future__ import annotations

import logging
import time
from pathlib import Path

import torch

from .paths import REPO_ROOT

RUNS_DIR = REPO_ROOT / "runs"


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
        torch.save(state, tmp)
        tmp.replace(path)  # never leave a half-written checkpoint behind
        if path == self.checkpoint_path:
            self.last_save = time.monotonic()

    def due(self) -> bool:
        return time.monotonic() - self.last_save >= self.interval

    def load(self) -> dict | None:
        if not self.checkpoint_path.exists():
            return None
        return torch.load(self.checkpoint_path, weights_only=False)

    def resume(self, rng, **parts) -> dict:
        """Restore each of `parts` (models, optimisers, schedules: anything with load_state_dict, saved under
        the same key) and both random generators from the latest checkpoint; returns the checkpoint for the
        caller's own counters. Exits with a message when there is none."""
        state = self.load()
        if state is None:
            raise SystemExit(f"error: --resume but no checkpoint at {self.checkpoint_path}")
        for key, part in parts.items():
            part.load_state_dict(state[key])
        rng.bit_generator.state = state["rng"]
        torch.set_rng_state(state["torch_rng"])
        return state

    def start(self, resume: bool, rng, **parts) -> tuple[int, float, float]:
        """(iteration, best, seconds trained before) to start from: from the latest checkpoint (restoring
        `parts` and the random generators, as `resume`) when `resume`, else a fresh start."""
        if not resume:
            return 0, float("inf"), 0.0
        state = self.resume(rng, **parts)
        self.log.info("resumed at iteration %d", state["iteration"])
        return state["iteration"], state["best"], state["elapsed"]

    @staticmethod
    def state(rng, iteration: int, best: float, elapsed: float, meta: dict, **parts) -> dict:
        """A checkpoint that `start` reads back: each part's state_dict under its name, the random generators,
        the counters and the meta."""
        return {**{k: p.state_dict() for k, p in parts.items()}, "rng": rng.bit_generator.state,
                "torch_rng": torch.get_rng_state(), "iteration": iteration, "best": best, "elapsed": elapsed, "meta": meta}
