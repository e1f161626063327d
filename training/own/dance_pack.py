"""The model pack of --kind dance: the acLSTM's step graph and JSON exactly as public/models/aclstm.json's (the fields
web/runtime/aclstm/danceModel.ts checks) with one style, under the pack's own id, plus card.md and its thumbnail,
written from measurements of the exported file run with onnxruntime as the page runs it (aclstm/shipped.py):

- the data: minutes, clips, held-out clips, skeletons;
- training: time, iterations, held-out error (teacher-forced and auto-conditioned, normalised units);
- foot sliding by both measures of training/metrics.py on the held-out clips against generated dance (contacts
  labelled on both by the corpus's rule, training/mocap/contacts.py, as the model predicts none);
- a 10,000-frame stability run from each of three seeds: finite, bone lengths, root height (divergence), and the
  freeze rule of the acLSTM report (aclstm/freeze_rule.py) against the held-out clips, with jitter beside it;
- pose_change.png, the first stability run's pose change per second."""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from .. import metrics
from ..aclstm.exporting import SEED_FRAMES, load_dance_model, pick_seeds, write_dance_graph
from ..aclstm.freeze_rule import LOW_FRACTION, judge, jitter_cm, real_jitter_cm, real_reference
from ..aclstm.shipped import ShippedDance
from ..aclstm.training import DanceRun
from ..data.dance import LIMB_MIN_LENGTH, bone_length_error, decode, real_pose_change
from ..mocap.contacts import contacts_for
from ..mocap.skeleton import FOOT_POINTS, canonical_skeleton
from .dance import dance_data
from .dataset import FPS, OwnData
from .options import pack_terms
from .pack import STABILITY_FRAMES, card_data_lines, number_or_na, plot_pose_change

STABILITY_SEEDS = 3
# A run diverges when its limbs stretch or shrink by more than this share on average, or its root leaves the band of
# heights the real clips span by more than DIVERGED_HEIGHT metres.
DIVERGED_BONES = 0.25
DIVERGED_HEIGHT = 0.5


def export_dance_pack(checkpoint: Path, data: OwnData, pack_id: str, out: Path, weights: str, terms: dict) -> tuple[Path, Path, dict]:
    """Writes out/<id>.onnx (parity checked) and out/<id>.json; returns both paths and the info."""
    model, meta, state = load_dance_model(checkpoint)
    skel, clips, styles = dance_data(data)
    out.mkdir(parents=True, exist_ok=True)
    onnx_path = out / f"{pack_id}.onnx"
    onnx_fields, parity = write_dance_graph(model, onnx_path, weights)
    info = {
        "id": pack_id, "kind": "aclstm", "fps": meta["fps"], "file": onnx_path.name,
        "description": f"Auto-conditioned LSTM (Zhou et al.), u = v = 5, trained on {data.folder.name} "
                       f"({data.minutes:.1f} minutes, {len(data.clips)} clips) with python -m training.own.",
        "training_scheme": "auto-conditioned",
        "styles": list(styles),
        "skeleton": skel.to_json(),
        "features": {"dim": meta["dim"], "seed_frames": SEED_FRAMES,
                     "layout": "x = [root dx (m/frame), root height y (m), root dz (m/frame), then for each point of the "
                               f"canonical skeleton after the root: its position minus the root's (m, world axes)]; y up, {FPS:g} fps"},
        "onnx": onnx_fields,
        "normalisation": {"mean": [round(float(v), 7) for v in meta["mean"]], "std": [round(float(v), 7) for v in meta["std"]]},
        "real_pose_change": real_pose_change(clips, styles),
        "seeds": pick_seeds(clips, styles),
        "training": {"iterations": state.get("iteration"), "valid": state.get("valid"), "valid_files": meta["valid_files"],
                     "args": meta["args"]},
        "parity": parity,
        "pack": {**terms, "card": "card.md", "thumbnail": "pose_change.png", "data_folder": data.folder.name,
                 "data_minutes": round(data.minutes, 3), "clips": len(data.clips)},
    }
    info["bytes"] = onnx_path.stat().st_size
    json_path = out / f"{pack_id}.json"
    json_path.write_text(json.dumps(info) + "\n")
    return onnx_path, json_path, info


def _labelled(positions: np.ndarray) -> np.ndarray:
    return contacts_for(positions, canonical_skeleton().joints, FPS, FOOT_POINTS)


def measure_dance_pack(out: Path, info: dict, data: OwnData, stability_frames: int = STABILITY_FRAMES) -> dict:
    """The card's measurements of the exported pack against the user's held-out clips."""
    skel = canonical_skeleton()
    dance_skel, clips, styles = dance_data(data)
    style = styles[0]
    held = data.held_out_clips()
    ref = real_reference(clips, styles)[style]
    real_low_foot = [c.positions for c in held]
    heights = np.concatenate([c.positions[:, 0, 1] for c in held])
    real = {
        "clips": len(held), "seconds": sum(c.frames for c in held) / FPS,
        "median_pose_change": ref["median"], "low_share": ref["low_share"], "longest_low_s": ref["longest_low_s"],
        "jitter_cm": real_jitter_cm(clips, styles)[style],
        "sliding_contact_bits": metrics.foot_skating_clips([(p, _labelled(p)) for p in real_low_foot], FPS, skel),
        "sliding_low_foot": metrics.low_foot_sliding_clips(real_low_foot, FPS, skel),
        "root_height": [float(heights.min()), float(heights.max())],
    }
    model = ShippedDance(out, info["id"])
    seeds = model.seeds_of(style)[:STABILITY_SEEDS]
    feats = model.generate(np.array([s["frames"] for s in seeds], np.float32), [style] * len(seeds), stability_frames)
    runs = []
    for seed, f in zip(seeds, feats):
        finite = bool(np.isfinite(f).all())
        run = {"seed": seed["name"], "finite": finite}
        if finite:
            pos = decode(f.astype(np.float64))
            curve = metrics.pose_change_per_second(pos, FPS)
            limbs = bone_length_error(pos, dance_skel, LIMB_MIN_LENGTH)
            root = pos[:, 0, 1]
            away = max(real["root_height"][0] - root.min(), root.max() - real["root_height"][1], 0.0)
            run.update({
                "pose_change_curve": curve.tolist(), "median_pose_change": float(np.median(curve)),
                "min_pose_change": float(curve.min()), **judge(curve, ref), "jitter_cm": jitter_cm(pos),
                "bone_length_error": float(limbs.mean()), "root_height": [float(root.min()), float(root.max())],
                "sliding_contact_bits": metrics.foot_skating(pos, _labelled(pos), FPS, skel),
                "sliding_low_foot": metrics.low_foot_sliding_clips([pos], FPS, skel),
            })
            run["diverged"] = bool(run["bone_length_error"] > DIVERGED_BONES or away > DIVERGED_HEIGHT)
        else:
            run["diverged"] = True
        runs.append(run)
    first = runs[0]
    stability = {"frames": stability_frames, "runs": runs, "seed": first["seed"], "finite": first["finite"],
                 "freeze_line": LOW_FRACTION * ref["median"], "pose_change_curve": first.get("pose_change_curve", [0.0])}
    return {"real": real, "stability": stability}


def write_dance_card(path: Path, pack_id: str, data: OwnData, result: DanceRun, info: dict, measures: dict) -> None:
    real, stab = measures["real"], measures["stability"]
    valid = (info["training"]["valid"] or {}).get(info["styles"][0], {})
    runs = stab["runs"]
    measured = [r for r in runs if r["finite"]]
    passing = sum(r.get("passes", False) for r in runs)
    diverged = sum(r["diverged"] for r in runs)
    lines = [
        f"# {pack_id}", "",
        f"A dance model (auto-conditioned LSTM, Zhou et al.; {info['onnx']['layers']} × {info['onnx']['hidden']} units, "
        f"{info['bytes'] / 1e6:.2f} MB ONNX, weights {info['onnx']['weights']}) trained by `python -m training.own --kind dance` "
        f"on the folder `{data.folder.name}` as one style, \"{info['styles'][0]}\". Every number below was measured on this "
        "pack's own ONNX file with onnxruntime.", "",
        *card_data_lines(data, "the canonical skeleton's 25 points", info),
        "", "## Training", "",
        f"- {result.minutes:.1f} minutes, {result.iterations} iterations; stopped: {result.stopped}.",
        f"- Held-out mean squared error per feature (normalised, lower is better): {valid.get('teacher_forced', float('nan')):.4f} "
        f"fed the real frames, {valid.get('auto_conditioned', float('nan')):.4f} fed its own output half the time (u = v = 5).",
        "", "## Stability and freezing", "",
        f"{len(runs)} runs of {stab['frames']:,} frames, one per seed motion, judged by the acLSTM report's freeze rule "
        f"(a second is low below {LOW_FRACTION:.0%} of the held-out median pose change, {real['median_pose_change']:.3f} m/s; "
        "a run passes with (a) at most twice the real share of low seconds, (b) no low stretch of 5 s, (c) a median at "
        f"least half the real one). The held-out clips spend {real['low_share']:.1%} of their seconds low, longest "
        f"{real['longest_low_s']} s; their jitter is {real['jitter_cm']:.3f} cm per frame².", "",
        "| seed | finite | median pose change (× real) | low seconds | longest low (s) | freeze rule | jitter (× real) | limb length error | root height (m) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in runs:
        if not r["finite"]:
            lines.append(f"| {r['seed']} | no | | | | fails | | | |")
            continue
        lines.append(f"| {r['seed']} | yes | {r['median_ratio']:.2f} | {r['low_share']:.1%} | {r['longest_low_s']} | "
                     f"{'passes' if r['passes'] else 'fails'} | {r['jitter_cm'] / real['jitter_cm']:.2f} | "
                     f"{r['bone_length_error']:.1%} | {r['root_height'][0]:.2f}–{r['root_height'][1]:.2f} |")
    verdict = (f"{passing} of {len(runs)} runs pass the freeze rule"
               + (": this model freezes." if passing == 0 else "; the others freeze." if passing < len(runs) else ": none freezes."))
    lines += ["", f"{verdict} {diverged} of {len(runs)} diverge (non-finite values, limbs more than "
              f"{DIVERGED_BONES:.0%} off their length on average, or the root more than {DIVERGED_HEIGHT} m outside the "
              f"real clips' heights {real['root_height'][0]:.2f}–{real['root_height'][1]:.2f} m).", "",
              "## Foot sliding (m/s)", "",
              f"The model predicts no contacts; both real and generated motion are labelled by the corpus's rule. "
              f"{len(measured)} generated runs of {stab['frames']:,} frames against the {real['clips']} held-out clip"
              f"{'s' * (real['clips'] != 1)} ({real['seconds']:.1f} s).", "",
              "| measure | held-out clips | generated |", "|---|---|---|",
              f"| toe speed while the contact label is on | {number_or_na(real['sliding_contact_bits'])} | "
              f"{number_or_na(float(np.mean([r['sliding_contact_bits'] for r in measured])) if measured else float('nan'))} |",
              f"| lowest foot point within 4 cm of the floor | {number_or_na(real['sliding_low_foot'])} | "
              f"{number_or_na(float(np.mean([r['sliding_low_foot'] for r in measured])) if measured else float('nan'))} |",
              "", "![pose change per second over the first stability run](pose_change.png)", ""]
    path.write_text("\n".join(lines))


def record_dance_measures(json_path: Path, info: dict, result: DanceRun, measures: dict) -> None:
    """The card's numbers kept in the pack's JSON too ("pack" field)."""
    runs = [{k: v for k, v in r.items() if k != "pose_change_curve"} for r in measures["stability"]["runs"]]
    info["pack"]["training"] = {"minutes": result.minutes, "iterations": result.iterations, "held_out": info["training"]["valid"],
                                "stopped": result.stopped}
    info["pack"]["measures"] = {"real": measures["real"], "stability": {"frames": measures["stability"]["frames"], "runs": runs}}
    json_path.write_text(json.dumps(info) + "\n")


def write_dance_pack(args: argparse.Namespace, data: OwnData, model_id: str, result: DanceRun) -> tuple[Path, Path]:
    """The dance pack of a finished run into args.out: ONNX, JSON, measured card and plot; returns the ONNX and JSON."""
    onnx_path, json_path, info = export_dance_pack(Path(args.run) / "best.pt", data, model_id, args.out, args.weights,
                                                   pack_terms(args))
    measures = measure_dance_pack(args.out, info, data, args.stability_frames)
    plot_pose_change(measures["stability"], measures["real"]["median_pose_change"], args.out / "pose_change.png")
    write_dance_card(args.out / "card.md", model_id, data, result, info, measures)
    record_dance_measures(json_path, info, result, measures)
    return onnx_path, json_path
