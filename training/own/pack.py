"""The model pack of a training run on a user's folder: the generator's ONNX step and its JSON exactly as the shipped
generator's (training/generator/exporting.py, graph.py), under the pack's own id, and card.md with its thumbnail,
written from measurements of the exported file run with onnxruntime (as the page runs it):

- the data: minutes, clips, held-out clips, the skeletons the mapper found (naming scheme, joints);
- training: time, iterations, epochs, held-out NLL per frame, why it stopped;
- foot sliding by both measures of training/metrics.py (toe speed while the contact bit is on; the lowest foot point's
  speed near the floor), on the user's own held-out clips against generated motion, raw and after the page's foot
  lock (training/footlock.py plant_feet);
- a 10,000-frame stability run: pose change per second against the held-out clips' median, seconds below 20% of it
  (the freeze line of the generator's report), finite frames, root height;
- pose_change.png, the stability run's pose change per second."""
from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import onnx
import torch

from .. import metrics
from ..data.features import FIXED_JOINTS, FeatureCodec, feature_names
from ..footlock import plant_feet
from ..generator.exporting import estimate_initial_state, sampling_info
from ..generator.graph import INPUTS, OUTPUTS, check_parity, export_onnx
from ..generator.recovery import model_from_onnx
from ..generator.sampling import draw_mixture, held_normals, snap_contacts
from ..generator.training import load_generator
from ..mocap.rotations import matrix_to_quat, quat_to_matrix
from ..mocap.skeleton import canonical_skeleton
from ..onnx.compact import weight_format
from ..onnx.graph import OPSET
from ..onnx.sessions import cpu_session
from .dataset import FPS, OwnData
from .trainer import TrainingResult

FREEZE_FRACTION = 0.2  # a second below this share of the real median pose change counts as frozen
STABILITY_FRAMES = 10_000
SLIDING_STREAMS, SLIDING_FRAMES = 4, 600  # generated motion measured for sliding: streams × frames (20 s each)
SEED_FRAMES = 6  # real frames each seed state is estimated from (eq. 26)
MAX_SEEDS = 6


def pick_seeds(data: OwnData, codec: FeatureCodec, mean: np.ndarray, std: np.ndarray) -> list[dict]:
    """Seed frames from a third of the way into clips spread over the folder (by name), training and held out."""
    pool = sorted((c for c in data.clips if c.frames > 3 * SEED_FRAMES), key=lambda c: c.name)
    seeds = []
    for k in sorted(set(np.linspace(0, len(pool) - 1, min(MAX_SEEDS, len(pool))).round().astype(int))):
        c = pool[k]
        x = codec.encode(c.root, c.rotations, c.contacts)
        start = len(x) // 3
        seeds.append({"name": Path(c.name).name.split(".")[0], "file": c.name,
                      "frames": ((x[start:start + SEED_FRAMES] - mean) / std).astype(np.float32)})
    return seeds


def export_pack(checkpoint: Path, data: OwnData, pack_id: str, out: Path, weights: str, terms: dict,
                seed_iterations: int = 300) -> tuple[Path, Path, dict]:
    """Writes out/<id>.onnx and out/<id>.json (the shipped generator.json's fields); returns both paths and the info."""
    # The seed states' small optimisations run many times slower on several threads of a busy machine.
    torch.set_num_threads(1)
    model, meta, state = load_generator(checkpoint)
    out.mkdir(parents=True, exist_ok=True)
    onnx_path = out / f"{pack_id}.onnx"
    export_onnx(model, onnx_path, weights)
    stored = model_from_onnx(onnx_path, model.dim, model.hidden, model.mixtures)
    parity = {**check_parity(stored, onnx_path), "reference": f"torch with the weights as stored ({weights})"}
    skel = canonical_skeleton()
    codec = FeatureCodec(skel, np.array(meta["references"]))
    mean, std = np.array(meta["mean"]), np.array(meta["std"])
    seeds = []
    for seed in pick_seeds(data, codec, mean, std):
        h, c, zero_nll, est_nll = estimate_initial_state(model, torch.from_numpy(seed["frames"]), seed_iterations)
        seeds.append({"name": seed["name"], "file": seed["file"], "category": "own",
                      "x": [round(float(v), 6) for v in seed["frames"][0]],
                      "h": [round(float(v), 6) for v in h.reshape(-1)], "c": [round(float(v), 6) for v in c.reshape(-1)],
                      "nll_zero_state": round(zero_nll, 3), "nll_estimated_state": round(est_nll, 3)})
    info = {
        "id": pack_id, "kind": "lstm-gmm", "fps": meta["fps"], "file": onnx_path.name,
        "bytes": onnx_path.stat().st_size,
        "description": f"Contact-aware LSTM with a {meta['mixtures']}-component Gaussian mixture over the next frame "
                       f"(Wang, Chai, Xia §4.1), trained on {data.folder.name} ({data.minutes:.1f} minutes, "
                       f"{len(data.clips)} clips) with python -m training.own.",
        "skeleton": skel.to_json(),
        "onnx": {"inputs": INPUTS, "outputs": OUTPUTS, "opset": OPSET, "layers": 2, "hidden": meta["hidden"],
                 "graph": "gate-level LSTM layers (Gemm + gate maths, no LSTM op), fc3 as three Gemms",
                 "mixtures": meta["mixtures"], "dim": meta["dim"]},
        "features": {
            "names": feature_names(skel), "joints": codec.joints, "fixed_joints": [skel.index(n) for n in FIXED_JOINTS],
            "layout": "as public/models/generator.json: x = [dtx, dtz, dry, ty, root tilt rotvec(3), joint rotvecs, "
                      "contact L, contact R]; rotvecs relative to `references`",
            "references": [[round(float(v), 7) for v in q] for q in matrix_to_quat(codec.references)],
        },
        "normalisation": {"mean": [round(float(v), 7) for v in mean], "std": [round(float(v), 7) for v in std]},
        "seeds": seeds,
        "sampling": sampling_info(),
        "training": {"epochs": state.get("epoch"), "valid_nll_per_frame": state.get("valid_nll"),
                     "valid_files": meta["valid_files"], "train_frames": meta["train_frames"], "args": meta["args"]},
        "parity": parity,
        "weights": weight_format(onnx.load(str(onnx_path))),
        "pack": {**terms, "card": "card.md", "thumbnail": "pose_change.png", "data_folder": data.folder.name,
                 "data_minutes": round(data.minutes, 3), "clips": len(data.clips)},
    }
    json_path = out / f"{pack_id}.json"
    json_path.write_text(json.dumps(info) + "\n")
    return onnx_path, json_path, info


class PackGenerator:
    """The exported step run with onnxruntime, drawn from as the page draws (training/generator/shipped.py's rule)."""

    def __init__(self, onnx_path: Path, info: dict):
        self.info = info
        self.session = cpu_session(onnx_path, threads=1)
        self.mean = np.array(info["normalisation"]["mean"], np.float32)
        self.std = np.array(info["normalisation"]["std"], np.float32)
        self.codec = FeatureCodec(canonical_skeleton(), quat_to_matrix(np.array(info["features"]["references"], np.float64)))

    def sample(self, seeds: list[int], frames: int, rng: np.random.Generator, temperature: float = 1.0) -> np.ndarray:
        """Features (len(seeds), frames, dim) in physical units, one stream per seed state."""
        layers, hidden = self.info["onnx"]["layers"], self.info["onnx"]["hidden"]
        chosen = [self.info["seeds"][i] for i in seeds]
        x = np.array([s["x"] for s in chosen], np.float32)
        h = np.stack([np.array(s["h"], np.float32).reshape(layers, hidden) for s in chosen], axis=1)
        c = np.stack([np.array(s["c"], np.float32).reshape(layers, hidden) for s in chosen], axis=1)
        corr = self.info["sampling"]["noise_correlation"]
        out = np.zeros((len(seeds), frames, len(self.mean)), np.float32)
        z = None
        for t in range(frames):
            w, mu, sigma, h, c = self.session.run(None, {"x": x, "h": h, "c": c})
            z = held_normals(z, rng.standard_normal((len(seeds), mu.shape[-1])), corr)
            x = snap_contacts(draw_mixture(w, mu, sigma, temperature, rng.random(len(seeds)), z), self.mean, self.std)
            out[:, t] = x * self.std + self.mean
        return out


def measure_pack(onnx_path: Path, info: dict, data: OwnData, stability_frames: int = STABILITY_FRAMES,
                 sliding_frames: int = SLIDING_FRAMES) -> dict:
    """The card's measurements of the exported pack against the user's held-out clips."""
    gen = PackGenerator(onnx_path, info)
    skel = gen.codec.skel
    held = data.held_out_clips()
    real_positions = [c.positions for c in held]
    real = {
        "clips": len(held), "seconds": sum(c.frames for c in held) / FPS,
        "sliding_contact_bits": metrics.foot_skating_clips([(c.positions, c.contacts) for c in held], FPS, skel),
        "sliding_low_foot": metrics.low_foot_sliding_clips(real_positions, FPS, skel),
    }
    changes = [metrics.pose_change_per_second(p, FPS) for p in real_positions if len(p) > FPS]
    real["median_pose_change"] = float(np.median(np.concatenate(changes))) if changes else float("nan")

    rng = np.random.default_rng(2024)
    streams = min(SLIDING_STREAMS, len(info["seeds"]))
    t0 = time.perf_counter()
    feats = gen.sample(list(range(streams)), sliding_frames, rng)
    raw, locked, bit_pairs = [], [], []
    for f in feats:
        pos = gen.codec.positions(f.astype(np.float64))
        bits = (f[:, -2:] > 0.5).astype(np.uint8)
        bit_pairs.append((pos, bits))
        raw.append(pos)
        locked.append(plant_feet(pos, bits, FPS, skel)[0])
    generated = {
        "streams": streams, "frames": sliding_frames,
        "sliding_contact_bits": metrics.foot_skating_clips(bit_pairs, FPS, skel),
        "sliding_low_foot": metrics.low_foot_sliding_clips(raw, FPS, skel),
        "sliding_low_foot_locked": metrics.low_foot_sliding_clips(locked, FPS, skel),
        "sample_seconds": time.perf_counter() - t0,
    }
    long = gen.sample([0], stability_frames, np.random.default_rng(7))[0]
    finite = bool(np.isfinite(long).all())
    pos = gen.codec.positions(long.astype(np.float64)) if finite else None
    change = metrics.pose_change_per_second(pos, FPS) if finite else np.zeros(1)
    line = FREEZE_FRACTION * real["median_pose_change"]
    stability = {
        "frames": stability_frames, "seed": info["seeds"][0]["name"], "finite": finite,
        "pose_change_curve": change.tolist(), "freeze_line": line,
        "min_pose_change": float(change.min()), "median_pose_change": float(np.median(change)),
        "frozen_seconds": int((change < line).sum()), "seconds": len(change),
        "root_height": metrics.summary(long[:, 3]) if finite else None,
    }
    return {"real": real, "generated": generated, "stability": stability}


def plot_pose_change(stability: dict, real_median: float, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(4.8, 2.0), dpi=100)
    ax.plot(stability["pose_change_curve"], lw=0.8, color="#2a6fdb", label="generated")
    ax.axhline(real_median, color="#555", lw=1, label="held-out median")
    ax.axhline(stability["freeze_line"], color="#c33", ls="--", lw=1, label="freeze line (20%)")
    ax.set_xlabel("second of the stability run")
    ax.set_ylabel("pose change (m/s)")
    ax.set_ylim(bottom=0)
    ax.legend(fontsize=6, loc="upper right")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def number_or_na(v: float) -> str:
    return "n/a" if v != v else f"{v:.3f}"


def card_data_lines(data: OwnData, target: str, info: dict) -> list[str]:
    """The card's "Data" section: minutes, clips, held-out clips, skeletons (mapped onto `target`), files left out,
    and the data's terms (the pack's licence fields in `info`)."""
    skeletons = "; ".join(f"{s['scheme']}, {s['joints']} joints ({s['files']} file{'s' * (s['files'] != 1)})"
                          for s in data.skeletons)
    return [
        "## Data", "",
        f"- {data.minutes:.2f} minutes of motion in {len(data.clips)} clips at {FPS:g} fps "
        f"({len(data.held_out)} held out: {', '.join(data.held_out)}).",
        f"- Skeleton: {skeletons}; mapped onto {target} by the humanoid mapper.",
        f"- Unreadable, left out: {len(data.skipped)} file{'s' * (len(data.skipped) != 1)}" + (": " + "; ".join(data.skipped) if data.skipped else "."),
        f"- Shorter than the training window ({data.min_seconds:.2f} s), left out: {len(data.too_short)} clip{'s' * (len(data.too_short) != 1)}"
        + (": " + ", ".join(data.too_short) if data.too_short else "."),
        f"- Licence: {info['pack']['licence']}" + ("; non-commercial use only." if not info["pack"]["commercial"] else "."),
    ]


def write_card(path: Path, pack_id: str, data: OwnData, result: TrainingResult, info: dict, measures: dict) -> None:
    real, gen, stab = measures["real"], measures["generated"], measures["stability"]
    ratio = gen["sliding_low_foot_locked"] / real["sliding_low_foot"] if real["sliding_low_foot"] > 0 else float("nan")
    frozen = stab["frozen_seconds"]
    lines = [
        f"# {pack_id}", "",
        f"A locomotion generator (LSTM + Gaussian mixture, {info['onnx']['hidden']} hidden units, {info['bytes'] / 1e6:.2f} MB "
        f"ONNX, weights {info['weights']}) trained by `python -m training.own` on the folder `{data.folder.name}`. "
        "Every number below was measured on this pack's own ONNX file with onnxruntime.", "",
        *card_data_lines(data, "the canonical skeleton", info),
        "", "## Training", "",
        f"- {result.minutes:.1f} minutes, {result.iterations} iterations ({result.epochs_done} whole epoch{'s' * (result.epochs_done != 1)}); stopped: {result.stopped}.",
        f"- Held-out NLL per frame (normalised features, lower is better): {result.best_valid_nll:.3f}.",
        "", "## Foot sliding (m/s)", "",
        f"On the {real['clips']} held-out clip{'s' * (real['clips'] != 1)} ({real['seconds']:.1f} s) against "
        f"{gen['streams']} generated streams of {gen['frames']} frames.", "",
        "| measure | held-out clips | generated | generated, feet locked |", "|---|---|---|---|",
        f"| toe speed while the contact bit is on | {number_or_na(real['sliding_contact_bits'])} | {number_or_na(gen['sliding_contact_bits'])} | |",
        f"| lowest foot point within 4 cm of the floor | {number_or_na(real['sliding_low_foot'])} | {number_or_na(gen['sliding_low_foot'])} | "
        f"{number_or_na(gen['sliding_low_foot_locked'])} |",
        "", f"Locked generated sliding is {number_or_na(ratio)}× the held-out clips' (lowest foot point).",
        "", "## Stability", "",
        f"{stab['frames']:,} frames from seed {stab['seed']}: "
        + (f"all finite; pose change per second median {stab['median_pose_change']:.3f} m/s, lowest "
           f"{stab['min_pose_change']:.3f} m/s, against the held-out median {real['median_pose_change']:.3f} m/s. "
           f"{frozen} of {stab['seconds']} seconds {'were' if frozen != 1 else 'was'} below the freeze line "
           f"({stab['freeze_line']:.3f} m/s, 20% of the held-out median)"
           + (": the motion freezes." if frozen else ". No freezing.")
           + f" Root height median {stab['root_height']['p50']:.2f} m (p10 {stab['root_height']['p10']:.2f}, "
             f"p90 {stab['root_height']['p90']:.2f})."
           if stab["finite"] else "the run produced non-finite values (NaN or infinity): the model diverges."),
        "", "![pose change per second over the stability run](pose_change.png)", "",
    ]
    path.write_text("\n".join(lines))


def record_measures(json_path: Path, info: dict, result: TrainingResult, measures: dict) -> None:
    """The card's numbers kept in the pack's JSON too ("pack" field), for the page and for checks."""
    stability = {k: v for k, v in measures["stability"].items() if k != "pose_change_curve"}
    info["pack"]["training"] = {"minutes": result.minutes, "iterations": result.iterations, "epochs_done": result.epochs_done,
                                "held_out_nll": result.best_valid_nll, "stopped": result.stopped}
    info["pack"]["measures"] = {"real": measures["real"], "generated": measures["generated"], "stability": stability}
    json_path.write_text(json.dumps(info) + "\n")
