"""Train the locomotion generator (LSTM + Gaussian mixture) on CMU walking and running.

    python -m training.train_generator [--epochs 150] [--hidden 192] [--minutes 85] [--resume]

Recipe from Wang, Chai, Xia §4.1.3: 30 fps, Gaussian input noise sigma 0.05 (in normalised units),
RMSProp with learning rate 1e-3 multiplied by 0.95 each epoch, gradients clipped to [-5, 5],
batches of 20 windows of 50 frames. Clips are split into training and validation by clip.
Mirrored copies and copies played 10% slower and faster are added to the training clips; running
clips (1 minute of 20) are drawn 4x as often. Dropout (0.25) keeps the mixture from overfitting the
small corpus: without it, validation NLL rises after about 10 epochs while training NLL keeps falling.
Writes runs/generator/{train.log, checkpoint.pt, best.pt}; export with python -m training.export_generator.
"""
from __future__ import annotations

import argparse
import json
import time

import numpy as np
import torch
from tqdm import tqdm

from ..data.cmu import DEFAULT_CACHE, build, load_cache
from ..data.features import FeatureCodec, mirror_clip
from ..models.generator import MixtureLSTM, mixture_nll
from ..paths import add_mocap_argument, resolve_mocap_dir
from ..mocap.resample import resample
from ..mocap.retarget import CanonicalClip
from ..runs import Run

FPS = 30
CATEGORIES = ["walk", "run"]
RUN_WEIGHT = 4.0
NOISE_SIGMA = 0.05
SPEED_FACTORS = (0.9, 1.0, 1.1)


def is_validation(clip: dict) -> bool:
    """Every 8th clip of each category (by file name) is held out."""
    return clip["rank"] % 8 == 3


def load_clips(mocap_flag: str | None) -> list[dict]:
    cache = DEFAULT_CACHE / f"cmu_{'-'.join(CATEGORIES)}_{FPS}fps.npz"
    if not cache.exists():
        build(resolve_mocap_dir(mocap_flag), FPS, CATEGORIES, DEFAULT_CACHE)
    data = load_cache(cache)
    clips = []
    for cat in CATEGORIES:
        for rank, c in enumerate(sorted((c for c in data["clips"] if c["category"] == cat), key=lambda c: c["file"])):
            s, e = c["start"], c["start"] + c["frames"]
            clips.append(dict(c, rank=rank, root=data["root"][s:e].astype(np.float64),
                              rotations=data["rotations"][s:e].astype(np.float64), contacts=data["contacts"][s:e]))
    return clips


def change_speed(clip: dict, factor: float):
    """The clip played `factor` times as fast, still at 30 fps (slerped poses, nearest contacts)."""
    if factor == 1.0:
        return clip["root"], clip["rotations"], clip["contacts"]
    src = CanonicalClip(clip["file"], FPS * factor, clip["root"], clip["rotations"], np.zeros((len(clip["root"]), 1, 3)))
    out = resample(src, FPS)
    idx = np.minimum(np.round(np.arange(out.frames) * factor).astype(int), len(clip["contacts"]) - 1)
    return out.root, out.rotations, clip["contacts"][idx]


class Corpus:
    """Normalised feature sequences, split by clip, with window sampling."""

    def __init__(self, clips: list[dict]):
        train = [c for c in clips if not is_validation(c)]
        self.codec = FeatureCodec()
        self.codec.fit_references(np.concatenate([c["rotations"] for c in train]))
        seqs, weights = [], []
        for c in train:
            for factor in SPEED_FACTORS:
                root, rot, con = change_speed(c, factor)
                for variant in [(root, rot, con), mirror_clip(root, rot, con)]:
                    seqs.append(self.codec.encode(*variant))
                    weights.append(len(seqs[-1]) * (RUN_WEIGHT if c["category"] == "run" else 1.0))
        allx = np.concatenate(seqs)
        self.mean = allx.mean(axis=0)
        self.std = np.maximum(allx.std(axis=0), 1e-2)
        self.train = [self.normalise(s) for s in seqs]
        self.weights = np.array(weights) / sum(weights)
        self.valid = [self.normalise(self.codec.encode(c["root"], c["rotations"], c["contacts"]))
                      for c in clips if is_validation(c)]
        self.train_frames = len(allx)
        self.valid_files = [c["file"] for c in clips if is_validation(c)]

    def normalise(self, x: np.ndarray) -> np.ndarray:
        return ((x - self.mean) / self.std).astype(np.float32)

    def batch(self, rng: np.random.Generator, size: int, length: int):
        """Windows of length+1 frames (inputs and next-frame targets), padded, with a mask of real targets."""
        x = np.zeros((size, length + 1, self.mean.shape[0]), np.float32)
        mask = np.zeros((size, length), np.float32)
        for i, k in enumerate(rng.choice(len(self.train), size=size, p=self.weights)):
            seq = self.train[k]
            start = rng.integers(0, max(1, len(seq) - length))
            w = seq[start:start + length + 1]
            x[i, :len(w)] = w
            mask[i, :len(w) - 1] = 1
        return torch.from_numpy(x), torch.from_numpy(mask)


def validation_nll(model: MixtureLSTM, corpus: Corpus) -> float:
    """Mean NLL per frame over whole held-out clips (teacher forcing, no noise)."""
    model.eval()
    total, count = 0.0, 0
    with torch.no_grad():
        for seq in corpus.valid:
            if len(seq) < 2:
                continue
            x = torch.from_numpy(seq).unsqueeze(0)
            logits, mu, log_sigma, _ = model(x[:, :-1])
            nll = mixture_nll(logits, mu, log_sigma, x[:, 1:])
            total += float(nll.sum())
            count += nll.numel()
    model.train()
    return total / max(count, 1)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_mocap_argument(parser)
    parser.add_argument("--epochs", type=int, default=150)
    parser.add_argument("--hidden", type=int, default=192)
    parser.add_argument("--batch", type=int, default=20)
    parser.add_argument("--window", type=int, default=50)
    parser.add_argument("--lr", type=float, default=1e-3)
    parser.add_argument("--dropout", type=float, default=0.25)
    parser.add_argument("--minutes", type=float, default=85.0, help="stop cleanly after this much training time")
    parser.add_argument("--checkpoint-minutes", type=float, default=3.0)
    parser.add_argument("--run", default="generator", help="run name under runs/")
    parser.add_argument("--resume", action="store_true", help="continue from runs/<run>/checkpoint.pt")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--threads", type=int, default=1, help="torch CPU threads (1 is steadiest when the machine is shared)")
    parser.add_argument("--iters-per-epoch", type=int, default=200,
                        help="iterations between learning-rate decays; 150 x 200 matches the paper's ~30k iterations")
    args = parser.parse_args(argv)

    torch.set_num_threads(args.threads)
    run = Run(args.run, args.checkpoint_minutes)
    corpus = Corpus(load_clips(args.mocap))
    dim = corpus.mean.shape[0]
    model = MixtureLSTM(dim, args.hidden, dropout=args.dropout)
    optimiser = torch.optim.RMSprop(model.parameters(), lr=args.lr, alpha=0.9)
    scheduler = torch.optim.lr_scheduler.ExponentialLR(optimiser, gamma=0.95)
    rng = np.random.default_rng(args.seed)
    torch.manual_seed(args.seed)
    iters_per_epoch = args.iters_per_epoch
    start_epoch, start_iter, best, elapsed_before = 0, 0, float("inf"), 0.0
    if args.resume:
        state = run.resume(rng, model=model, optimiser=optimiser, scheduler=scheduler)
        start_epoch, start_iter, best = state["epoch"], state["iteration"], state["best"]
        elapsed_before = state["elapsed"]
        run.log.info("resumed at epoch %d iteration %d", start_epoch, start_iter)
    meta = {"dim": dim, "hidden": args.hidden, "mixtures": model.mixtures, "fps": FPS,
            "mean": corpus.mean.tolist(), "std": corpus.std.tolist(),
            "references": corpus.codec.references.tolist(), "valid_files": corpus.valid_files,
            "train_frames": corpus.train_frames, "args": vars(args)}
    params = sum(p.numel() for p in model.parameters())
    run.log.info("start: %d features, %d parameters, %d training frames (with mirroring), %d validation clips, "
                 "%d iterations per epoch", dim, params, corpus.train_frames, len(corpus.valid), iters_per_epoch)
    t0 = time.monotonic()

    def checkpoint(epoch: int, iteration: int) -> dict:
        return {"model": model.state_dict(), "optimiser": optimiser.state_dict(), "scheduler": scheduler.state_dict(),
                "rng": rng.bit_generator.state, "torch_rng": torch.get_rng_state(), "epoch": epoch,
                "iteration": iteration, "best": best, "elapsed": elapsed_before + time.monotonic() - t0, "meta": meta}

    total = args.epochs * iters_per_epoch
    bar = tqdm(total=total, initial=start_epoch * iters_per_epoch + start_iter, desc="generator", unit="it")
    out_of_time = False
    for epoch in range(start_epoch, args.epochs):
        losses = []
        for it in range(start_iter if epoch == start_epoch else 0, iters_per_epoch):
            x, mask = corpus.batch(rng, args.batch, args.window)
            inputs = x[:, :-1] + NOISE_SIGMA * torch.randn_like(x[:, :-1])
            logits, mu, log_sigma, _ = model(inputs)
            nll = mixture_nll(logits, mu, log_sigma, x[:, 1:])
            loss = (nll * mask).sum() / mask.sum()
            optimiser.zero_grad()
            loss.backward()
            torch.nn.utils.clip_grad_value_(model.parameters(), 5.0)
            optimiser.step()
            losses.append(float(loss))
            bar.update(1)
            bar.set_postfix(epoch=epoch + 1, nll=f"{np.mean(losses[-50:]):.2f}")
            if run.due():
                run.save(checkpoint(epoch, it + 1))
            if elapsed_before + time.monotonic() - t0 > args.minutes * 60:
                out_of_time = True
                run.save(checkpoint(epoch, it + 1))
                break
        if out_of_time:
            run.log.info("stopped: time budget of %.0f minutes used (epoch %d)", args.minutes, epoch + 1)
            break
        scheduler.step()
        val = validation_nll(model, corpus)
        if val < best:
            best = val
            run.save({"model": model.state_dict(), "epoch": epoch + 1, "valid_nll": val, "meta": meta}, run.best_path)
        run.save(checkpoint(epoch + 1, 0))
        run.log.info("epoch %d train_nll %.3f valid_nll %.3f best %.3f lr %.2e minutes %.1f", epoch + 1,
                     np.mean(losses), val, best, scheduler.get_last_lr()[0], (elapsed_before + time.monotonic() - t0) / 60)
    bar.close()
    (run.dir / "summary.json").write_text(json.dumps({"best_valid_nll": best, "epochs_done": epoch + 1 if not out_of_time else epoch,
                                                       "minutes": (elapsed_before + time.monotonic() - t0) / 60, "parameters": params}, indent=1))
    print(f"done: best validation NLL {best:.3f} per frame; checkpoints in {run.dir}")


if __name__ == "__main__":
    main()
