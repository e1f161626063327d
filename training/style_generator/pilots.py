"""Pilot measures of the style-conditioned generator against the shipped one (issue 39), on raw generator output (no
refiner, no foot lock), both models sampled the same way:

- both run in torch (the shipped one rebuilt from public/models/generator.onnx, generator/recovery.py), sampled as the
  page samples (temperature 0.5, one uniform and held normals per row with the shipped correlation 0.8, contacts
  snapped: generator/sampling.py), from initial states estimated by eq. 26 (generator/exporting.py) on the same six
  real frames for both models: CMU's the shipped generator's seed clips (exporting.pick_seeds: 6 walks, 2 runs), each
  Bandai style's a clip of each content (walk, turn left, turn right, run);
- held-out NLL per style, per frame in physical units (the normalised NLL plus the sum of log std: the two models
  normalise differently; both encode with the shipped rotation references, so the features are the same);
- the refiner report's two-sample test (refiner/measures.py: window and single-frame classifiers trained on real
  training windows of the style against stream set B, scored on its held-out clips against stream set A), cut down as
  refiner/pilots.py cuts it: one classifier seed (or the mean of --classifier-seeds), PILOT_FRAMES per seed;
- the hip-bob probe (docs/models/refiner.md, "What gives generated walking away"): the amplitude spectrum of the hips'
  vertical velocity in the classifier's 32-frame windows (mean removed per window; bins of 0.94 Hz), at 0.94 Hz (slow
  change) and 2.81 Hz (the step's bob), and the mean above 5 Hz (noise); and the hips' height spread (sd within each
  window, cm);
- root speed, and the lowest pose change over any second against the freeze line (20% of the real median).
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from .. import metrics
from ..data.features import FeatureCodec, mirror_clip
from ..data.locomotion import SPEED_FACTORS, change_speed, is_validation
from ..data.style_locomotion import STYLES, StyledClip, load_styled_clips
from ..generator.exporting import estimate_initial_state, pick_seeds
from ..generator.recovery import model_from_onnx
from ..generator.sampling import draw_mixture, held_normals, snap_contacts
from ..generator.shipped import DecodedMotion
from ..generator.training import load_generator
from ..mocap.rotations import quat_to_matrix
from ..mocap.skeleton import canonical_skeleton
from ..models.generator import MixtureLSTM, StyledGenerator, mixture_nll
from ..paths import MODELS_DIR
from ..refiner.measures import WINDOW, classifier_frames, motion_windows, two_sample_accuracy, windows
from ..refiner.report import locked_variants
from .training import nll_per_clip

TEMPERATURE = 0.5
PILOT_FRAMES = 1500
STREAM_SEEDS = (2024, 7)  # streams A (measured, the classifiers' test) and B (the classifiers' training)
SEED_FRAMES = 6
BANDAI_SEED_CONTENTS = ("walk", "walk-turn-left", "walk-turn-right", "run")
FREEZE_FRACTION = 0.2
HIP_VEL_COLUMN = 3 * 25 + 1  # classifier_frames: 25 joints' root-frame positions, then velocities; Hips is joint 0, y
HIP_HEIGHT_COLUMN = 1


@dataclass
class Candidate:
    """A generator to measure: its torch model, normalisation and codec; `styled` when it takes a style input."""
    name: str
    model: MixtureLSTM
    mean: np.ndarray
    std: np.ndarray
    codec: FeatureCodec
    styled: bool

    def run(self, style: int):
        """The model as a plain generator (x, state) for one style (a style model) or as it is."""
        return StyledGenerator(self.model, style) if self.styled else self.model


def shipped_candidate(models_dir: Path = MODELS_DIR) -> Candidate:
    info = json.loads((models_dir / "generator.json").read_text())
    o = info["onnx"]
    model = model_from_onnx(models_dir / info["file"], o["dim"], o["hidden"], o["mixtures"])
    refs = quat_to_matrix(np.array(info["features"]["references"], np.float64))
    return Candidate("shipped generator (CMU)", model, np.array(info["normalisation"]["mean"]),
                     np.array(info["normalisation"]["std"]), FeatureCodec(canonical_skeleton(), refs), False)


def style_candidate(checkpoint: Path) -> Candidate:
    model, meta, _ = load_generator(checkpoint)
    if list(meta["styles"]) != list(STYLES):
        raise ValueError(f"{checkpoint}: styles {meta['styles']} are not {list(STYLES)}")
    refs = np.array(meta["references"], np.float64)
    return Candidate("style generator", model, np.array(meta["mean"]), np.array(meta["std"]),
                     FeatureCodec(canonical_skeleton(), refs), True)


def seed_clips(clips: list[StyledClip], style: str) -> list[StyledClip]:
    """The clips whose frames start the streams of `style`: for CMU the shipped generator's seed clips (pick_seeds), for
    a Bandai style the middle clip by name of each content."""
    if style == "cmu":
        return []  # pick_seeds works on the CMU clips directly (seed_inputs)
    out = []
    for content in BANDAI_SEED_CONTENTS:
        pool = sorted((c for c in clips if c.style == style and c.content == content and c.clip.frames > 12),
                      key=lambda c: c.clip.file)
        out.append(pool[len(pool) // 2])
    return out


def seed_inputs(cand: Candidate, clips: list[StyledClip], style: str) -> list[tuple[str, np.ndarray]]:
    """(name, SEED_FRAMES normalised frames) per stream of `style`, from the same real frames for every candidate."""
    if style == "cmu":
        cmu = [c.clip for c in clips if c.style == "cmu"]
        return [(s["name"], s["frames"]) for s in pick_seeds(cmu, cand.codec, cand.mean, cand.std)]
    out = []
    for c in seed_clips(clips, style):
        x = cand.codec.encode(c.clip.root, c.clip.rotations, c.clip.contacts)
        start = len(x) // 3
        out.append((f"{style} {c.content}", ((x[start:start + SEED_FRAMES] - cand.mean) / cand.std).astype(np.float32)))
    return out


def initial_states(cand: Candidate, seeds: list[tuple[int, np.ndarray]]):
    """x (B, dim), h and c (2, B, H), style ids (B,): eq. 26's state for each (style id, seed frames)."""
    xs, hs, cs = [], [], []
    for style, frames in seeds:
        h, c, _, _ = estimate_initial_state(cand.run(style), torch.from_numpy(frames))
        xs.append(frames[0]), hs.append(h), cs.append(c)
    return (torch.from_numpy(np.stack(xs)), torch.cat(hs, dim=1), torch.cat(cs, dim=1),
            torch.tensor([s for s, _ in seeds], dtype=torch.long))


def sample(cand: Candidate, start, frames: int, rng: np.random.Generator, temperature: float = TEMPERATURE,
           noise_correlation: float = 0.8) -> np.ndarray:
    """Features (B, frames, dim) in physical units from `start` (initial_states), drawn as ShippedGenerator.sample
    draws (one uniform per row, held normals, contacts snapped)."""
    x, h, c, styles = start
    model = cand.model.eval()
    b = len(x)
    out = np.zeros((b, frames, len(cand.mean)), np.float32)
    z = None
    xn = x.numpy().astype(np.float32)
    state = (h, c)
    with torch.no_grad():
        for t in range(frames):
            inp = torch.from_numpy(xn).unsqueeze(1)
            logits, mu, log_sigma, state = model(inp, state, styles) if cand.styled else model(inp, state)
            w = torch.softmax(logits[:, 0], -1).numpy()
            u = rng.random(b)
            z = held_normals(z, rng.standard_normal((b, cand.mean.shape[0])), noise_correlation)
            xn = draw_mixture(w, mu[:, 0].numpy(), torch.exp(log_sigma[:, 0]).numpy(), temperature, u, z)
            xn = snap_contacts(xn, cand.mean, cand.std)
            out[:, t] = xn * cand.std + cand.mean
    return out


def decode(cand: Candidate, features: np.ndarray) -> DecodedMotion:
    f = features.astype(np.float64)
    return DecodedMotion(f, cand.codec.positions(f), (f[:, -2:] > 0.5).astype(np.uint8))


def held_out_motion(codec: FeatureCodec, clips: list[StyledClip], style: str) -> list[DecodedMotion]:
    """The style's held-out clips, encoded and decoded (each on its own, root from the origin)."""
    out = []
    for c in clips:
        if c.style == style and is_validation(c.clip):
            f = codec.encode(c.clip.root, c.clip.rotations, c.clip.contacts)
            out.append(DecodedMotion(f, codec.positions(f), c.clip.contacts[1:]))
    return out


def training_frames(codec: FeatureCodec, clips: list[StyledClip], style: str, fps: float) -> list[np.ndarray]:
    """Classifier frames of the style's training clips as the corpus trains on them (every speed factor, mirrored
    too): the two-sample test's real training side, as refiner/report.real_training_frames builds it."""
    out = []
    for c in clips:
        if c.style != style or is_validation(c.clip):
            continue
        for factor in SPEED_FACTORS:
            root, rot, con = change_speed(c.clip, factor)
            for variant in [(root, rot, con), mirror_clip(root, rot, con)]:
                f = codec.encode(*variant)
                out.append(classifier_frames(codec.positions(f), np.cumsum(f[:, 2]), f[:, -2:] > 0.5, fps))
    return out


def hip_bob(w: np.ndarray, fps: float) -> dict:
    """The hip-bob probe on classifier windows (n, 32, columns): mean amplitude spectrum of the hips' vertical velocity
    (m/s, mean removed per window) at 0.94 and 2.81 Hz and averaged above 5 Hz; the hips' height sd within windows (cm)."""
    v = w[:, :, HIP_VEL_COLUMN].astype(np.float64)
    amp = np.abs(np.fft.rfft(v - v.mean(axis=1, keepdims=True), axis=1)).mean(axis=0)
    freqs = np.fft.rfftfreq(w.shape[1], 1 / fps)
    return {"slow_0.9Hz": float(amp[1]), "bob_2.8Hz": float(amp[3]), "above_5Hz": float(amp[freqs > 5].mean()),
            "peak_Hz": float(freqs[1 + np.argmax(amp[1:])]),
            "hip_height_sd_cm": float(100 * w[:, :, HIP_HEIGHT_COLUMN].std(axis=1).mean())}


def motion_summary(seqs: list[DecodedMotion], fps: float, freeze_line: float | None = None) -> dict:
    speed = np.concatenate([metrics.root_speed(s.features, fps) for s in seqs])
    out = {"root_speed_mean": float(speed.mean())}
    change = [metrics.pose_change_per_second(s.positions, fps) for s in seqs if len(s.positions) > fps]
    if change:
        allc = np.concatenate(change)
        out["pose_change_median"] = float(np.median(allc))
        out["pose_change_min"] = float(allc.min())
        if freeze_line is not None:
            out["frozen_seconds"] = int((allc < freeze_line).sum())
    return out


def physical_nll(cand: Candidate, clips: list[StyledClip], style: str) -> float:
    """Mean NLL per frame of the style's held-out clips, in physical feature units (normalised NLL + sum log std)."""
    seqs, ids = [], []
    for c in clips:
        if c.style == style and is_validation(c.clip):
            f = cand.codec.encode(c.clip.root, c.clip.rotations, c.clip.contacts)
            seqs.append(((f - cand.mean) / cand.std).astype(np.float32))
            ids.append(STYLES.index(style))
    per = nll_per_clip(cand.model, seqs, np.array(ids) if cand.styled else None)
    total, count = sum(t for t, _ in per), sum(n for _, n in per)
    return total / count + float(np.log(cand.std).sum())


def two_sample(real_train, train_w, real_test, test_w, seed: int, seeds: int, steps: int | None) -> dict[str, list[float]]:
    """The refiner report's two-sample test, window and single-frame classifiers, with `seeds` classifier seeds from
    `seed`: balanced accuracies per kind."""
    return {kind: [two_sample_accuracy(real_train, train_w, real_test, test_w, seed + k, steps=steps, kind=kind)["balanced_accuracy"]
                   for k in range(seeds)] for kind in ("window", "frame")}


def measure(cands: list[Candidate], styles_by_cand: dict[str, list[str]], frames: int = PILOT_FRAMES,
            classifier_seed: int = 0, steps: int | None = None, mocap: str | None = None, classifier_seeds: int = 1,
            temperature: float = TEMPERATURE, refiner=None,
            log=lambda line: print(line, flush=True)) -> dict:
    """Every measure above, for each candidate on each of its styles (the shipped one: CMU only, since it has no
    style input; its NLL on every style all the same). `refiner` (anything with refiner/pilots.CheckpointRefiner's
    refine): the style candidate's streams are also measured with the foot lock, refined, and refined with the lock
    (two-sample test and sliding by both measures, `variants`)."""
    t0 = time.perf_counter()
    clips = load_styled_clips(mocap)
    fps = 30.0
    out = {"frames_per_seed": frames, "temperature": temperature, "noise_correlation": 0.8,
           "classifier_seed": classifier_seed, "classifier_seeds": classifier_seeds, "classifier_steps": steps or 1500, "real": {}, "models": {}}
    codec = cands[0].codec  # both candidates encode with the shipped references: the real motion is the same
    real_cache = {}
    skel = canonical_skeleton()
    for style in STYLES:
        real = held_out_motion(codec, clips, style)
        real_test = motion_windows(real, fps)
        summ = motion_summary(real, fps)
        real_cache[style] = (real_test, summ)
        out["real"][style] = {"held_out_clips": len(real), "held_out_windows": len(real_test), **summ, "hip_bob": hip_bob(real_test, fps),
                              "low_foot_sliding": float(np.concatenate([metrics.low_foot_speeds(s.positions, fps, skel) for s in real]).mean()),
                              "foot_skating_by_contacts": float(np.concatenate([metrics.planted_toe_speeds(s.positions, s.contacts, fps, skel)
                                                                                for s in real]).mean())}
    for cand in cands:
        m = out["models"][cand.name] = {"nll": {s: physical_nll(cand, clips, s) for s in STYLES}, "styles": {}}
        log(f"{cand.name}: held-out NLL per frame (physical) " + ", ".join(f"{s} {v:.1f}" for s, v in m["nll"].items()))
        measured = styles_by_cand[cand.name]
        seeds, names = [], []
        for style in measured:
            for name, x in seed_inputs(cand, clips, style):
                seeds.append((STYLES.index(style) if cand.styled else 0, x))
                names.append((style, name))
        start = initial_states(cand, seeds)
        streams = [sample(cand, start, frames, np.random.default_rng(s), temperature) for s in STREAM_SEEDS]
        log(f"{cand.name}: sampled {len(seeds)} streams x {frames} frames x 2 sets ({(time.perf_counter() - t0) / 60:.1f} min)")
        # Per stream set (A, B), each variant's decoded streams: raw only, or with a refiner also locked and refined.
        if refiner is not None and cand.styled:
            seed_physical = start[0].numpy() * cand.std + cand.mean  # the frame before each stream's first
            decoded = [locked_variants(s, refiner.refine(s, seed_physical), cand.codec, fps, skel) for s in streams]
            log(f"{cand.name}: refined and locked ({(time.perf_counter() - t0) / 60:.1f} min)")
        else:
            decoded = [{"raw": [decode(cand, f) for f in s]} for s in streams]

        for style in measured:
            rows = [k for k, (s, _) in enumerate(names) if s == style]
            var_a = [decoded[0]["raw"][k] for k in rows]
            var_b = [decoded[1]["raw"][k] for k in rows]
            real_test, real_summ = real_cache[style]
            real_train = windows(training_frames(codec, clips, style, fps))
            test_w, train_w = motion_windows(var_a, fps), motion_windows(var_b, fps)
            runs = two_sample(real_train, train_w, real_test, test_w, classifier_seed, classifier_seeds, steps)
            acc = {kind: float(np.mean(v)) for kind, v in runs.items()}
            line = real_summ.get("pose_change_median")
            r = {"seeds": [n for s, n in names if s == style], "two_sample": acc, "two_sample_runs": runs,
                 "hip_bob": hip_bob(test_w, fps),
                 **motion_summary(var_a, fps, FREEZE_FRACTION * line if line else None),
                 "windows": {"real_train": len(real_train), "real_test": len(real_test), "generated": len(test_w)}}
            if len(decoded[0]) > 1:
                r["variants"] = {}
                for v in [v for v in decoded[0] if v != "raw"]:  # raw is measured above
                    va, vb = [decoded[0][v][k] for k in rows], [decoded[1][v][k] for k in rows]
                    tw, bw = motion_windows(va, fps), motion_windows(vb, fps)
                    r["variants"][v] = {
                        **{kind: float(np.mean(accs)) for kind, accs in
                           two_sample(real_train, bw, real_test, tw, classifier_seed, classifier_seeds, steps).items()},
                        "low_foot_sliding": float(np.concatenate([metrics.low_foot_speeds(s.positions, fps, skel) for s in va]).mean()),
                        "foot_skating_by_contacts": float(np.concatenate([metrics.planted_toe_speeds(s.positions, s.contacts, fps, skel)
                                                                          for s in va]).mean()),
                        "hip_bob": hip_bob(tw, fps)}
                    log(f"{cand.name} [{style}] {v}: two-sample windows {100 * r['variants'][v]['window']:.1f}% "
                        f"frames {100 * r['variants'][v]['frame']:.1f}%, lowest-foot sliding {r['variants'][v]['low_foot_sliding']:.3f} m/s")
            m["styles"][style] = r
            log(f"{cand.name} [{style}]: two-sample windows {100 * acc['window']:.1f}% frames {100 * acc['frame']:.1f}%, "
                f"hip bob {r['hip_bob']}, root speed {r['root_speed_mean']:.2f} (real {real_summ['root_speed_mean']:.2f}) "
                f"({(time.perf_counter() - t0) / 60:.1f} min)")
    out["minutes"] = (time.perf_counter() - t0) / 60
    return out
