"""Training the adversarial refiner R against a discriminator D (Wang, Chai, Xia §4.2, §4.3), and reading its
checkpoints back. The command is python -m training.refiner.train.

R is trained on motion sampled from the generator (runs/generator/best.pt, the weights of the shipped
public/models/generator.onnx) at temperature 0.5, against real windows of the generator's own training
split (data/locomotion.Corpus: mirrored and speed-changed copies of the training clips; the held-out
validation clips are not used here). Generated streams start from a short teacher-forced warm-up on a
random real training window, so they cover many states; they are cached in cache/refiner_generated_*.npz.

Losses: D minimises eq. (10), -log(1 - D(R(x))) - log D(x_real); R minimises eq. (13),
-log D(R(x)) + lambda * |root(x) - root(R(x))|^2 with lambda = 20, where root() is the root trajectory
integrated over the window (metres). D gives one logit per frame; losses are means over frames.
Recipe (§4.2.2): 75 initial updates of R (root term only: D is untrained) and 75 of D, then k = 5 R updates
per D update, k doubled when the D loss is below 0.01 and halved when it is above 1; a history buffer of
B = 320 refined windows, each D update sees b/2 = 16 from the current R and 16 from the buffer (then 16
buffer entries are replaced); RMSProp (decay 0.9), learning rates 0.002 (R) and 0.005 (D), b = 32.

R sees windows of --window frames (90) from a zero state, so it learns to start cold as the browser does;
D judges --crop-frame crops (30, one second: the running clips are barely longer) of them.

One deviation from the paper, and one variant that was tried (measured in docs/models/refiner.md):
- --pose-weight (default 1, the shipped run): eq. 13 regularises the root only. Trained that way
  (--pose-weight 0, runs/refiner-faithful) R changed the frames by 0.86 standard deviations on average and
  flipped a third of the contact bits within 1,000 updates while D won (D(refined) 0.05): the joints D cannot
  see drift freely. The extra term is the mean squared change of all other features (tilt, joint rotations,
  contacts; normalised units), the "self-regularisation" of the paper's Fig. 2 applied to the whole frame.
- --d-input pose (default ends = the paper): D also sees the rest of the frame (root motion, tilt, joint rotations).
  Tried with --pose-weight 0.5 (runs/refiner-dpose): D won faster and validation skating stayed higher
  (0.95 against 0.71 m/s at 1,500 updates), so the refiner of 2026-11 was trained against the paper's D.
- --d-input joints: D sees every joint's root-frame position and velocity and the contact bits, what the report's
  two-sample classifiers see (models/refiner.JointFeatures); --d-arch conv makes D a window classifier shaped like
  the report's (Adam, one logit per window) instead of the paper's bidirectional LSTM; --skate-weight adds the mean
  planted-toe speed (planted by the generator's bits) to R's loss. Pilots and runs: docs/models/refiner.md.

The generated streams are drawn as the page draws them, normals held over frames (generator/sampling.py
NOISE_CORRELATION); streams drawn with fresh normals every frame (the refiner of 2026-11 was trained on those) are
cached under names without the _rho suffix.

With --style-generator (issue 39), R learns from the style generator's motion instead: the streams come in every
style, an equal share each, each warmed up on real windows of its own style (streams.generated_cache), against real
windows of every style drawn as the style model's training drew them (data/style_locomotion.StyleCorpus). R itself
has no style input: one refiner for every style.

Writes runs/refiner/{train.log, checkpoint.pt, best.pt, last.pt}; best.pt is the checkpoint with the lowest
validation skating (contact share within 0.1 of the generator's). Longer training lowers that measure but makes
the motion easier to tell from real motion (docs/models/refiner.md), so the shipped model is an early best.pt,
kept as runs/refiner/shipped.pt. Export with python -m training.refiner.export --checkpoint <file>.
"""
from __future__ import annotations

import argparse
import hashlib
import json
from pathlib import Path

import numpy as np
import torch
import torch.nn.functional as F

from ..data.locomotion import Corpus, load_clips
from ..data.style_locomotion import StyleCorpus, load_styled_clips
from ..generator.training import load_generator
from ..models.refiner import ConvDiscriminator, Discriminator, FeatureGeometry, JointFeatures, Refiner, discriminator_input, discriminator_inputs
from ..runs import TrainingLoop
from .streams import TEMPERATURE, WindowSampler, generated_cache, streams_to_seqs

TOE_NAMES = ("LeftToeBase", "RightToeBase")


def load_refiner(checkpoint: Path) -> tuple[Refiner, dict, dict]:
    """The refiner (eval mode), its meta and the whole checkpoint dictionary."""
    state = torch.load(checkpoint, weights_only=False)
    meta = state["meta"]
    model = Refiner(np.array(meta["mean"]), np.array(meta["std"]), np.array(meta["references"]), meta["hidden"],
                    np.array(meta["end_mean"]), np.array(meta["end_std"]), fps=meta["fps"])
    model.load_state_dict(state["refiner"])
    return model.eval(), meta, state


def crops(d: torch.Tensor, length: int) -> torch.Tensor:
    """(B, T, F) -> (B * T // length, length, F): non-overlapping crops."""
    b, t, f = d.shape
    n = t // length
    return d[:, :n * length].reshape(b * n, length, f)


def root_loss(refiner: Refiner, x: torch.Tensor, y: torch.Tensor) -> torch.Tensor:
    """Mean squared distance (m^2) between the root trajectories of input and refined windows (eq. 13)."""
    geo = refiner.geometry
    a, b = geo.root_trajectory(refiner.physical(x)), geo.root_trajectory(refiner.physical(y))
    return ((a - b) ** 2).sum(-1).mean()


@torch.no_grad()
def skating(refiner: Refiner, x: torch.Tensor, x_prev: torch.Tensor) -> tuple[float, float]:
    """Mean horizontal toe speed (m/s) while planted in this frame and the one before (as metrics.foot_skating,
    using the windows' own contact bits), and the share of planted frames."""
    geo = refiner.geometry
    f, fp = refiner.physical(x), refiner.physical(x_prev)
    _, v = geo.end_effectors(f, fp)
    bits = torch.cat([fp.unsqueeze(1), f], 1)[..., -2:] > 0.5
    planted = bits[:, 1:] & bits[:, :-1]
    speeds = []
    for side, name in enumerate(TOE_NAMES):
        k = geo.end_names.index(name)
        speed = torch.linalg.norm(v[..., k, [0, 2]], dim=-1)
        speeds.append(speed[planted[..., side]])
    s = torch.cat(speeds)
    return float(s.mean()) if len(s) else float("nan"), float(bits[:, 1:].float().mean())


def planted_toe_speed(refiner: Refiner, y: torch.Tensor, xp: torch.Tensor, bits_from: torch.Tensor) -> torch.Tensor:
    """Mean horizontal toe speed (m/s) of refined windows y after xp over the frame pairs in which the foot is planted by
    the bits of `bits_from` (the generator's input windows, so R cannot lower it by turning contacts off): the
    differentiable form of skating(), for --skate-weight."""
    geo = refiner.geometry
    _, v = geo.end_effectors(refiner.physical(y), refiner.physical(xp))
    bits = refiner.physical(bits_from)[..., -2:] > 0.5
    planted = (bits[:, 1:] & bits[:, :-1]).float()
    total = torch.zeros(())
    for side, name in enumerate(TOE_NAMES):
        speed = torch.sqrt((v[:, 1:, geo.end_names.index(name)][..., [0, 2]] ** 2).sum(-1) + 1e-8)
        total = total + (speed * planted[..., side]).sum()
    return total / planted.sum().clamp(min=1.0)


def joint_statistics(geometry: FeatureGeometry, refiner: Refiner, sampler: WindowSampler, rng, n: int = 1024) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard deviation of every joint's physical root-frame position and velocity over real windows."""
    x, xp = sampler(rng, n)
    with torch.no_grad():
        p, v = geometry.end_effectors(refiner.physical(x), refiner.physical(xp))
        e = torch.cat([p.flatten(-2), v.flatten(-2)], -1).reshape(-1, p.shape[-2] * 6).numpy()
    return e.mean(0), np.maximum(e.std(0), 1e-2)


def end_statistics(refiner: Refiner, sampler: WindowSampler, rng, n: int = 1024) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard deviation of the physical [p_end, v_end] over real windows."""
    x, xp = sampler(rng, n)
    with torch.no_grad():
        f = refiner.physical(x)
        p, v = refiner.geometry.end_effectors(f, refiner.physical(xp))
        e = torch.cat([p.flatten(-2), v.flatten(-2)], -1).reshape(-1, 6 * refiner.ends).numpy()
    return e.mean(0), np.maximum(e.std(0), 1e-2)


class RefinerTraining:
    """One training run with the options of python -m training.refiner.train: the real and generated windows,
    R and D with their optimisers, D's history buffer and the counters (`state`), one method per step."""

    def __init__(self, args: argparse.Namespace):
        self.args = args
        # Threads, run directory, seed and clock; the refiner keeps its own checkpoints (two networks, D's buffer).
        self.loop = TrainingLoop(args)
        self.run = self.loop.run
        styles, tag = 0, ""
        if args.style_generator:  # issue 39: R learns from the style model's motion in every style, against real
            # windows of every style drawn as its training drew them (streams.style_shares keeps the mix the same)
            generator, gmeta, _ = load_generator(args.style_generator)
            corpus = StyleCorpus(load_styled_clips(args.mocap), np.array(gmeta["references"]),
                                 cmu_share=gmeta["args"].get("cmu_share"))
            # The cache is named by the checkpoint's run, file and contents: streams of other weights are never reused.
            path = Path(args.style_generator)
            styles = len(gmeta["styles"])
            tag = f"_{path.parent.name}-{path.stem}-{hashlib.sha1(path.read_bytes()).hexdigest()[:8]}"
        else:
            generator, gmeta, _ = load_generator(args.generator)
            corpus = Corpus(load_clips(args.mocap))
        if np.abs(corpus.mean - np.array(gmeta["mean"])).max() > 1e-5:
            raise SystemExit("error: the corpus's normalisation differs from the generator's; was the cache rebuilt?")
        mean, std, refs = np.array(gmeta["mean"]), np.array(gmeta["std"]), np.array(gmeta["references"])
        corpus.mean, corpus.std = mean, std

        self.rng = self.loop.seed()
        self.real = WindowSampler(corpus.train, args.window, corpus.weights)
        self.real_crop = WindowSampler(corpus.train, args.crop, corpus.weights)
        self.fake = WindowSampler(streams_to_seqs(generated_cache(generator, corpus, args, "train", styles, tag)), args.window)
        valid_fake = generated_cache(generator, corpus, args, "valid", styles, tag)[0]
        valid_real = WindowSampler(corpus.valid, args.crop)
        self.vx, self.vxp = torch.from_numpy(valid_fake[:, 1:]), torch.from_numpy(valid_fake[:, 0])
        self.vr = valid_real(np.random.default_rng(7), 256)

        probe = Refiner(mean, std, refs, args.hidden)
        end_mean, end_std = end_statistics(probe, self.real, np.random.default_rng(3))
        self.refiner = Refiner(mean, std, refs, args.hidden, end_mean, end_std, fps=gmeta["fps"])
        self.joints = None
        if args.d_input == "joints":
            geometry = JointFeatures(refs, np.zeros(1), np.ones(1), fps=gmeta["fps"]).geometry
            joint_mean, joint_std = joint_statistics(geometry, self.refiner, self.real, np.random.default_rng(4))
            self.joints = JointFeatures(refs, joint_mean, joint_std, fps=gmeta["fps"])
        d_inputs = discriminator_inputs(self.refiner, args.d_input)
        self.disc = ConvDiscriminator(d_inputs, args.d_hidden) if args.d_arch == "conv" else Discriminator(d_inputs, args.d_hidden)
        self.opt_r = torch.optim.RMSprop(self.refiner.parameters(), lr=args.lr_r, alpha=0.9)
        # The convolutional D trains like the report's classifiers (Adam); the paper's D with RMSProp.
        self.opt_d = torch.optim.Adam(self.disc.parameters(), lr=args.lr_d, betas=(0.5, 0.999)) if args.d_arch == "conv" \
            else torch.optim.RMSprop(self.disc.parameters(), lr=args.lr_d, alpha=0.9)
        self.meta = {"dim": self.refiner.dim, "hidden": args.hidden, "d_hidden": args.d_hidden, "fps": gmeta["fps"],
                     "mean": mean.tolist(), "std": std.tolist(), "references": refs.tolist(),
                     "end_effectors": self.refiner.geometry.end_names, "end_mean": end_mean.tolist(),
                     "end_std": end_std.tolist(), "temperature": TEMPERATURE,
                     "generator": str(args.style_generator or args.generator), **({"styles": gmeta["styles"]} if styles else {}),
                     "valid_files": corpus.valid_files,
                     "args": {k: (str(v) if isinstance(v, Path) else v) for k, v in vars(args).items()}}
        self.half = args.batch // 2
        self.buffer = self.initial_buffer()
        self.state = {"r_updates": 0, "d_updates": 0, "k": args.ratio, "best": float("inf"), "elapsed": 0.0, "history": []}
        if args.resume:
            ck = self.run.resume(self.rng, refiner=self.refiner, discriminator=self.disc, opt_r=self.opt_r, opt_d=self.opt_d)
            self.buffer = ck["buffer"]
            self.state = ck["state"]
            self.run.log.info("resumed at %d refiner / %d discriminator updates", self.state["r_updates"], self.state["d_updates"])
        else:
            params_r = sum(p.numel() for p in self.refiner.parameters())
            params_d = sum(p.numel() for p in self.disc.parameters())
            self.run.log.info("start: refiner %d parameters (hidden %d), discriminator %d (hidden %d), %d generated streams, "
                              "%d real training sequences, args %s", params_r, args.hidden, params_d, args.d_hidden,
                              len(self.fake.seqs), len(self.real.seqs), json.dumps(self.meta["args"]))
        self.validate_before_training()
        self.loop.start_clock(self.state["elapsed"])

    def elapsed(self) -> float:
        return self.loop.elapsed()

    # ---- windows -----------------------------------------------------------------------------------

    def refine_batch(self):
        x, xp = self.fake(self.rng, self.args.batch)
        y, _ = self.refiner(x, xp)
        return x, xp, y

    def d_fake_input(self, y, xp):
        return crops(self.d_input(y, xp), self.args.crop)

    def d_real_input(self):
        x, xp = self.real_crop(self.rng, self.args.batch)
        return self.d_input(x, xp)

    def d_input(self, x, xp):
        return discriminator_input(self.refiner, x, xp, self.args.d_input, self.joints)

    @torch.no_grad()
    def initial_buffer(self) -> torch.Tensor:
        """B refined D windows from the untrained R."""
        _, xp0, y0 = self.refine_batch()
        buf = self.d_fake_input(y0, xp0)
        while len(buf) < self.args.buffer:
            _, xpi, yi = self.refine_batch()
            buf = torch.cat([buf, self.d_fake_input(yi, xpi)])
        return buf[:self.args.buffer].clone()

    # ---- updates -----------------------------------------------------------------------------------

    def r_update(self, adversarial: bool) -> dict:
        args = self.args
        x, xp, y = self.refine_batch()
        reg = root_loss(self.refiner, x, y)
        loss = args.lam * reg
        if args.pose_weight > 0:
            loss = loss + args.pose_weight * ((y - x)[..., 4:] ** 2).mean()
        if args.skate_weight > 0:
            loss = loss + args.skate_weight * planted_toe_speed(self.refiner, y, xp, x)
        adv = torch.zeros(())
        if adversarial:
            logits = self.disc(self.d_fake_input(y, xp))
            adv = F.binary_cross_entropy_with_logits(logits, torch.ones_like(logits))  # -log D(R(x)), eq. 9
            loss = loss + adv
        self.opt_r.zero_grad()
        loss.backward()
        torch.nn.utils.clip_grad_norm_(self.refiner.parameters(), 10.0)
        self.opt_r.step()
        self.state["r_updates"] += 1
        return {"adv": float(adv.detach()), "root": float(reg.detach()), "y": y.detach(), "xp": xp}

    def d_update(self, last: dict | None) -> float:
        rng, half = self.rng, self.half
        if last is None:
            with torch.no_grad():
                _, xp, y = self.refine_batch()
        else:
            xp, y = last["xp"], last["y"]
        with torch.no_grad():
            current = self.d_fake_input(y, xp)
            current = current[torch.from_numpy(rng.choice(len(current), half, replace=False))]
        old = self.buffer[torch.from_numpy(rng.choice(len(self.buffer), half, replace=False))]
        fake_in = torch.cat([current, old])
        real_in = self.d_real_input()
        lf, lr = self.disc(fake_in), self.disc(real_in)
        # eq. 10 as the mean cross-entropy over the batch of refined and real windows (a chance-level D scores
        # ln 2 = 0.69, so the thresholds 0.01 and 1 of the adaptive multiplier mean "too strong" and "lost")
        loss = 0.5 * (F.binary_cross_entropy_with_logits(lf, torch.zeros_like(lf))
                      + F.binary_cross_entropy_with_logits(lr, torch.ones_like(lr)))
        self.opt_d.zero_grad()
        loss.backward()
        torch.nn.utils.clip_grad_norm_(self.disc.parameters(), 10.0)
        self.opt_d.step()
        self.buffer[torch.from_numpy(rng.choice(len(self.buffer), half, replace=False))] = current
        self.state["d_updates"] += 1
        return float(loss)

    def adapt_ratio(self, d_loss: float) -> None:
        """The multiplier k follows a running mean of the D loss (single updates are noisy) and changes at
        most once per 10 D updates: doubled below 0.01, halved above 1."""
        state = self.state
        state["d_ema"] = d_loss if state.get("d_ema") is None else 0.8 * state["d_ema"] + 0.2 * d_loss
        state["since_change"] = state.get("since_change", 0) + 1
        if state["since_change"] >= 10 and (state["d_ema"] < 0.01 or state["d_ema"] > 1.0):
            state["k"] = min(state["k"] * 2, 80) if state["d_ema"] < 0.01 else max(state["k"] // 2, 1)
            state["since_change"] = 0

    # ---- validation and checkpoints ----------------------------------------------------------------

    @torch.no_grad()
    def validate_before_training(self) -> None:
        raw_skate, raw_share = skating(self.refiner, self.vx, self.vxp) if self.state["r_updates"] == 0 else (None, None)
        real_skate, real_share = skating(self.refiner, *self.vr)
        if raw_skate is not None:
            self.state["raw_valid"] = {"skating": raw_skate, "contact_share": raw_share}
            self.run.log.info("validation before training: generated skating %.3f m/s (contact share %.2f), "
                              "real held-out %.3f m/s (%.2f)", raw_skate, raw_share, real_skate, real_share)

    @torch.no_grad()
    def validate(self) -> dict:
        refiner, vx, vxp = self.refiner, self.vx, self.vxp
        refiner.eval()
        y, _ = refiner(vx, vxp)
        skate, share = skating(refiner, y, vxp)
        root = float(root_loss(refiner, vx, y))
        change = float((y - vx)[..., :-2].abs().mean())
        flips = float(((refiner.physical(y)[..., -2:] > 0.5) != (refiner.physical(vx)[..., -2:] > 0.5)).float().mean())
        pf = torch.sigmoid(self.disc(self.d_fake_input(y, vxp))).mean()
        pr = torch.sigmoid(self.disc(self.d_input(*self.vr))).mean()
        refiner.train()
        return {"skating": skate, "contact_share": share, "root_mse": root, "feature_change": change,
                "contact_flips": flips, "d_real": float(pr), "d_refined": float(pf)}

    def validation_step(self, adv_hist: list, d_hist: list, root_hist: list) -> None:
        """Validate, log, and save best.pt: the lowest validation skating once adversarial training has started,
        as long as the contact share stays near the generator's (turning contacts off would lower the measure
        trivially)."""
        args, state = self.args, self.state
        v = self.validate()
        v.update(r_updates=state["r_updates"], d_updates=state["d_updates"], k=state["k"], minutes=self.elapsed() / 60,
                 adv=float(np.mean(adv_hist[-args.eval_every:])) if adv_hist else None,
                 d_loss=float(np.mean(d_hist[-50:])) if d_hist else None,
                 root=float(np.mean(root_hist[-args.eval_every:])))
        state["history"].append(v)
        self.run.log.info("R %d D %d k %d | adv %.3f d_loss %.3f root %.5f | valid skating %.3f (raw %.3f) share %.2f "
                          "root_mse %.4f change %.3f flips %.3f D(real) %.2f D(refined) %.2f | %.1f min",
                          v["r_updates"], v["d_updates"], v["k"], v["adv"] or 0, v["d_loss"] or 0, v["root"],
                          v["skating"], state.get("raw_valid", {}).get("skating", float("nan")), v["contact_share"],
                          v["root_mse"], v["feature_change"], v["contact_flips"], v["d_real"], v["d_refined"], v["minutes"])
        raw_share = state.get("raw_valid", {}).get("contact_share", v["contact_share"])
        if state["d_updates"] >= args.initial and abs(v["contact_share"] - raw_share) < 0.1 and v["skating"] < state["best"]:
            state["best"] = v["skating"]
            self.run.save({"refiner": self.refiner.state_dict(), "state": dict(state, elapsed=self.elapsed()),
                           "meta": self.meta, "valid": v}, self.run.best_path)

    def checkpoint(self) -> dict:
        return {"refiner": self.refiner.state_dict(), "discriminator": self.disc.state_dict(),
                "opt_r": self.opt_r.state_dict(), "opt_d": self.opt_d.state_dict(), "buffer": self.buffer,
                "rng": self.rng.bit_generator.state, "torch_rng": torch.get_rng_state(),
                "state": dict(self.state, elapsed=self.elapsed()), "meta": self.meta}

    # ---- the run -----------------------------------------------------------------------------------

    def train(self) -> dict:
        """The §4.2.2 schedule until --iterations R updates or --minutes; writes last.pt and summary.json and
        returns the final counters."""
        args, state = self.args, self.state
        bar = self.loop.progress_bar("refiner", args.iterations, state["r_updates"], unit="R-update")
        adv_hist, root_hist, d_hist = [], [], []
        last = None
        next_eval = (state["r_updates"] // args.eval_every + 1) * args.eval_every
        while state["r_updates"] < args.iterations:
            if state["r_updates"] < args.initial:
                last = self.r_update(adversarial=False)
                root_hist.append(last["root"])
                bar.update(1)
            elif state["d_updates"] < args.initial:
                d_hist.append(self.d_update(None))
            else:
                for _ in range(state["k"]):
                    last = self.r_update(adversarial=True)
                    adv_hist.append(last["adv"])
                    root_hist.append(last["root"])
                    bar.update(1)
                ld = self.d_update(last)
                d_hist.append(ld)
                self.adapt_ratio(ld)
            bar.set_postfix(k=state["k"], adv=f"{np.mean(adv_hist[-50:]) if adv_hist else 0:.2f}",
                            d=f"{np.mean(d_hist[-20:]) if d_hist else 0:.2f}", root=f"{np.mean(root_hist[-50:]):.4f}")
            if state["r_updates"] >= next_eval:
                next_eval += args.eval_every
                self.validation_step(adv_hist, d_hist, root_hist)
            if self.run.due():
                self.run.save(self.checkpoint())
            if self.loop.out_of_time():
                self.run.log.info("stopped: %s", self.loop.stopped)
                break
        bar.close()
        self.run.save(self.checkpoint())
        self.run.save({"refiner": self.refiner.state_dict(), "state": dict(state, elapsed=self.elapsed()), "meta": self.meta},
                      self.run.dir / "last.pt")
        (self.run.dir / "summary.json").write_text(json.dumps(
            {"r_updates": state["r_updates"], "d_updates": state["d_updates"], "best_valid_skating": state["best"],
             "raw_valid": state.get("raw_valid"), "minutes": self.elapsed() / 60,
             "last_valid": state["history"][-1] if state["history"] else None}, indent=1))
        return state
