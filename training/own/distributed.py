"""Training on more processes or machines with PyTorch's own engine: torchrun starts the processes and sets RANK,
WORLD_SIZE, LOCAL_RANK, MASTER_ADDR and MASTER_PORT; each process runs the same trainer, which wraps its model in
DistributedDataParallel. Without those variables (a plain `python -m training.own`) there is one process and nothing
here changes the run.

How a run on N processes stays the run of one process (the same numbers within float rounding):
- every process draws the same whole batch and input noise from the same seeded generators and trains on its own
  equal slice of it (`part`), so the sampling sequence does not depend on N;
- each process's loss is its slice's NLL sum over the frames of the whole batch, times N: DistributedDataParallel
  averages gradients over the N processes, which gives the gradient of the whole batch's mean NLL;
- process 0 alone writes the log, checkpoints, best.pt and the pack, and its checkpoint is sent to the others on
  --resume (the run folder need not be shared between machines);
- whether to stop (the time budget, Ctrl-C on any process) is agreed after every step, so all stop together."""
from __future__ import annotations

import contextlib
import logging
import math
import os
import signal
import time
from pathlib import Path

import numpy as np
import torch
import torch.distributed as dist
from tqdm import tqdm

from ..runs import Run, TrainingLoop


def launched_rank() -> int:
    """This process's rank as torchrun set it (0 without torchrun): only rank 0 prints and writes."""
    return int(os.environ.get("RANK", "0"))


class Processes:
    """The processes of one run: world (how many), rank (this one's number), device; `start` joins torchrun's group."""

    def __init__(self):
        self.world = int(os.environ.get("WORLD_SIZE", "1"))
        self.rank = launched_rank()
        self.local_rank = int(os.environ.get("LOCAL_RANK", "0"))
        self.lead = self.rank == 0
        self.device = torch.device("cpu")
        self.interrupted = False
        self._previous_handler = None

    @property
    def distributed(self) -> bool:
        return self.world > 1

    def start(self, batch: int) -> None:
        """Join the process group: gloo on CPU, nccl with a GPU per process. Ctrl-C (SIGINT, which torchrun also
        forwards) only marks the run as stopped, so that every process leaves after the same step."""
        if not self.distributed:
            return
        if batch % self.world:
            raise SystemExit(f"error: --batch {batch} does not split evenly over {self.world} processes; "
                             f"use a multiple of {self.world}")
        if not dist.is_available():
            raise SystemExit("error: this PyTorch has no torch.distributed; run one process (plain python -m training.own)")
        if torch.cuda.is_available():
            self.device = torch.device("cuda", self.local_rank)
            torch.cuda.set_device(self.device)
        dist.init_process_group(backend="nccl" if self.device.type == "cuda" else "gloo")
        self._previous_handler = signal.signal(signal.SIGINT, self._mark_interrupted)

    def _mark_interrupted(self, signum, frame) -> None:
        self.interrupted = True

    def stop(self) -> None:
        """Leave the process group (also after an error or Ctrl-C) and give SIGINT its handler back."""
        if not self.distributed:
            return
        if self._previous_handler is not None:
            signal.signal(signal.SIGINT, self._previous_handler)
        if dist.is_initialized():
            dist.destroy_process_group()

    def part(self, batch_size: int) -> slice:
        """This process's equal slice of a batch of `batch_size` (the whole batch for one process)."""
        share = batch_size // self.world
        return slice(self.rank * share, (self.rank + 1) * share)

    def total(self, value: torch.Tensor) -> float:
        """The sum of `value` over all processes (the value itself for one process)."""
        if not self.distributed:
            return value.item()
        value = value.detach().clone().to(self.device)
        dist.all_reduce(value)
        return value.item()

    def agree_to_stop(self, stop: bool) -> bool:
        """True on every process when any process wants to stop (the lead's budget, or Ctrl-C anywhere); after a
        Ctrl-C anywhere, `interrupted` is True on all."""
        if not self.distributed:
            return stop
        flags = torch.tensor([float(stop), float(self.interrupted)], device=self.device)
        dist.all_reduce(flags)
        self.interrupted = flags[1].item() > 0
        return flags.sum().item() > 0

    def own_dropout(self, seed: int, step: int):
        """A context for the forward pass. With several processes each draws its own dropout masks (seeded from
        --seed, its rank and the step, so a resumed run draws the same ones) and leaves torch's generator as it
        was, so the next batch's noise stays the same on all. With dropout the masks then differ from those of one
        process, so only a run without dropout gives the one-process numbers exactly."""
        if not self.distributed:
            return contextlib.nullcontext()
        forked = torch.random.fork_rng(devices=[self.device] if self.device.type == "cuda" else [])

        @contextlib.contextmanager
        def seeded():
            with forked:
                torch.manual_seed(int(np.random.SeedSequence([seed, self.rank, step]).generate_state(1)[0]))
                yield
        return seeded()

    def share_checkpoint(self, run: Run, resume: bool) -> dict | None:
        """The lead's checkpoint (None without --resume or without one), sent to every process."""
        state = run.load() if resume and self.lead else None
        if not self.distributed or not resume:
            return state
        box = [state]
        dist.broadcast_object_list(box, src=0)
        return box[0]


class FollowerRun(Run):
    """The run as a process other than 0 sees it: it writes nothing (no folder, log file or checkpoint) and resumes
    from the checkpoint process 0 sent."""

    def __init__(self, name: str, state: dict | None):
        self.dir = Path(name)  # named in messages only
        self.checkpoint_path = self.dir / "checkpoint.pt"
        self.best_path = self.dir / "best.pt"
        self.log = logging.getLogger("run.follower")
        self.log.propagate = False  # nothing reaches the root logger; process 0's log file is the run's
        self.interval = math.inf
        self.last_save = time.monotonic()
        self.state = state

    def save(self, state: dict, path: Path | None = None) -> None:
        pass

    def load(self) -> dict | None:
        return self.state


class FollowerLoop(TrainingLoop):
    """TrainingLoop for processes other than 0: the same seeding and resuming, no bar, no files; the time budget is
    the lead's (its decision reaches the others through Processes.agree_to_stop)."""

    def __init__(self, args, state: dict | None):
        super().__init__(args, run=FollowerRun(args.run, state))

    def progress_bar(self, desc: str, total: int, initial: int, unit: str = "it") -> tqdm:
        self.bar = tqdm(total=total, initial=initial, desc=desc, unit=unit, disable=True)
        return self.bar

    def out_of_time(self) -> bool:
        return False

    def finish(self, iteration: int, summary: dict, save_last: bool = False, **extra) -> None:
        self.bar.close()
