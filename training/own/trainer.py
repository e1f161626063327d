"""Training on a user's folder: one function per model kind, each taking a dataset and a config, so that a
distributed wrapper can run the same loop later. The generator's recipe is training/generator/training.py's (Wang,
Chai, Xia §4.1.3): Gaussian input noise, RMSProp with the learning rate decayed each epoch, gradients clipped,
windows of 50 frames; the run conventions are training/runs.py's TrainingLoop (progress bar, log, checkpoints every
few minutes, --resume, the time budget). Ctrl-C stops cleanly: the last checkpoint and summary are written. Under
torchrun the same loop runs on several processes or machines (DistributedDataParallel; own/distributed.py says how
the result stays that of one process)."""
from __future__ import annotations

import argparse
import copy
from dataclasses import dataclass, field

import numpy as np
import torch
from torch.nn.parallel import DistributedDataParallel

from ..generator.training import NOISE_SIGMA, validation_nll
from ..models.generator import MixtureLSTM, mixture_nll
from ..runs import TrainingLoop
from .dataset import FPS, OwnCorpus
from .distributed import FollowerLoop, Processes


@dataclass
class TrainingResult:
    best_valid_nll: float
    iterations: int
    epochs_done: int
    minutes: float
    stopped: str  # why the run stopped
    interrupted: bool = False  # Ctrl-C: the checkpoint is saved, nothing is exported
    losses: list[float] = field(default_factory=list)  # the whole batch's training NLL at each iteration of this session
    lead: bool = True  # False on torchrun's processes other than 0, which write and export nothing


def _same_data(saved: dict, now: dict) -> bool:
    """Whether a checkpoint was trained on the data now loaded: the same held-out clips and feature statistics."""
    return (saved["valid_files"] == now["valid_files"] and saved["dim"] == now["dim"]
            and np.allclose(saved["mean"], now["mean"], atol=1e-6) and np.allclose(saved["std"], now["std"], atol=1e-6))


def train_locomotion(corpus: OwnCorpus, config: argparse.Namespace) -> TrainingResult:
    """Trains the LSTM-GMM generator on `corpus`. `config` holds the flags of add_run_arguments (run, minutes,
    checkpoint_minutes, resume, seed, threads) and hidden, dropout, lr, batch, window, epochs, iters_per_epoch and
    iterations (a cap on all iterations, None for none). The best weights by held-out NLL go to best.pt in the run.
    Under torchrun each process calls it alike; process 0 alone writes."""
    processes = Processes()
    processes.start(config.batch)
    try:
        return _train_locomotion(corpus, config, processes)
    finally:
        processes.stop()


def _train_locomotion(corpus: OwnCorpus, config: argparse.Namespace, processes: Processes) -> TrainingResult:
    lead = processes.lead
    if lead:
        loop = TrainingLoop(config)
        saved = processes.share_checkpoint(loop.run, config.resume)
    else:
        saved = processes.share_checkpoint(None, config.resume)
        loop = FollowerLoop(config, saved)
    run = loop.run
    dim = corpus.mean.shape[0]
    torch.manual_seed(config.seed)  # the first weights follow --seed too (torch's own start seed is random)
    model = MixtureLSTM(dim, config.hidden, dropout=config.dropout)
    if processes.distributed:
        model.to(processes.device)
    optimiser = torch.optim.RMSprop(model.parameters(), lr=config.lr, alpha=0.9)
    scheduler = torch.optim.lr_scheduler.ExponentialLR(optimiser, gamma=0.95)
    rng = loop.seed()
    per_epoch = config.iters_per_epoch
    meta = {"dim": dim, "hidden": config.hidden, "mixtures": model.mixtures, "fps": FPS,
            "mean": corpus.mean.tolist(), "std": corpus.std.tolist(),
            "references": corpus.codec.references.tolist(), "valid_files": corpus.valid_files,
            "train_frames": corpus.train_frames, "args": {k: str(v) if not isinstance(v, (int, float, str, bool, type(None))) else v
                                                          for k, v in vars(config).items()}}
    if saved is not None and (saved["meta"]["hidden"] != config.hidden or not _same_data(saved["meta"], meta)):
        raise SystemExit(f"error: --resume, but the checkpoint in {run.dir} was trained on other data or another "
                         "--hidden: train without --resume, or into another --run")
    iteration = loop.start(meta, "epoch {epoch} iteration {iteration}", model=model, optimiser=optimiser, scheduler=scheduler)
    epoch = loop.resumed["epoch"] if loop.resumed else 0
    # DistributedDataParallel averages the gradients of the processes (and starts them all from process 0's weights).
    trained = DistributedDataParallel(model) if processes.distributed else model
    total_cap = config.iterations if config.iterations else config.epochs * per_epoch
    run.log.info("start: %d features, %d parameters, %d training frames (with mirroring and speed changes), "
                 "%d held-out clips, %d iterations per epoch", dim, loop.parameters, corpus.train_frames,
                 len(corpus.valid), per_epoch)
    bar = loop.progress_bar("own generator", total_cap, epoch * per_epoch + iteration)
    losses: list[float] = []  # this epoch's
    all_losses: list[float] = []
    interrupted = False

    def end_epoch() -> None:
        nonlocal epoch, iteration
        scheduler.step()
        epoch, iteration = epoch + 1, 0
        if not lead:
            losses.clear()
            return
        val = held_out_nll(model, corpus)
        if val < loop.best:
            loop.best = val
            run.save({"model": model.state_dict(), "epoch": epoch, "valid_nll": val, "meta": meta}, run.best_path)
        loop.save(iteration, epoch=epoch)
        run.log.info("epoch %d train_nll %.3f valid_nll %.3f best %.3f lr %.2e minutes %.1f", epoch,
                     np.mean(losses) if losses else float("nan"), val, loop.best, scheduler.get_last_lr()[0],
                     loop.elapsed() / 60)
        losses.clear()

    try:
        while epoch * per_epoch + iteration < total_cap:
            # Every process draws the whole batch and its noise (the same numbers), then trains on its own slice.
            x, mask = corpus.batch(rng, config.batch, config.window)
            noise = NOISE_SIGMA * torch.randn_like(x[:, :-1])
            frames = mask.sum()
            part = processes.part(config.batch)
            x, mask, noise = (t[part].to(processes.device) for t in (x, mask, noise))
            inputs = x[:, :-1] + noise
            with processes.own_dropout(config.seed, epoch * per_epoch + iteration):
                logits, mu, log_sigma, _ = trained(inputs)
            # This slice's share of the whole batch's mean NLL; DDP divides the summed gradients by the world size.
            loss = (mixture_nll(logits, mu, log_sigma, x[:, 1:]) * mask).sum() / frames.to(processes.device)
            optimiser.zero_grad()
            (loss * processes.world if processes.distributed else loss).backward()
            torch.nn.utils.clip_grad_value_(model.parameters(), 5.0)
            optimiser.step()
            iteration += 1
            losses.append(processes.total(loss))
            all_losses.append(losses[-1])
            bar.update(1)
            bar.set_postfix(epoch=epoch + 1, nll=f"{np.mean(losses[-50:]):.2f}")
            if iteration >= per_epoch:
                end_epoch()
            if processes.agree_to_stop(loop.step_done(iteration, epoch=epoch)):
                if processes.interrupted:
                    raise KeyboardInterrupt
                break
    except KeyboardInterrupt:
        loop.stopped = "stopped by Ctrl-C"
        interrupted = True
    done = epoch * per_epoch + iteration
    if lead and (iteration > 0 or not run.best_path.exists()):
        # A part epoch (the budget, the cap or Ctrl-C cut it) is still measured, so a short run has weights to export.
        val = held_out_nll(model, corpus)
        if val < loop.best or not run.best_path.exists():
            loop.best = val
            run.save({"model": model.state_dict(), "epoch": epoch, "valid_nll": val, "meta": meta}, run.best_path)
    loop.finish(iteration, {"best_valid_nll": loop.best, "epochs_done": epoch, "iterations": done}, epoch=epoch)
    return TrainingResult(loop.best, done, epoch, loop.elapsed() / 60, loop.stopped, interrupted, all_losses, lead)


def held_out_nll(model: MixtureLSTM, corpus: OwnCorpus) -> float:
    """validation_nll, on a CPU copy of a model trained on a GPU."""
    on_cpu = model if next(model.parameters()).device.type == "cpu" else copy.deepcopy(model).cpu()
    return validation_nll(on_cpu, corpus)
