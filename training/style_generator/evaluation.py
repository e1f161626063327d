"""Per-style long runs of the style generator (issue 39's report): stability and foot sliding, measured the same way
on generated streams and on each style's real held-out clips.

Streams: for every style, N_SEEDS streams of `frames` frames; stream k starts from the style's seed k (mod the
style's seed count: pilots.seed_inputs, eq. 26's state) and draws with random seed 1000 + k, so the report does not
choose seeds by result. Sampled as the page samples (pilots.sample: temperature 0.5, held normals, snapped contacts).

Per stream: finite, the lowest pose change over any second against the style's freeze line (20% of the median of its
held-out clips), frozen seconds, root height range, and sliding by both measures, raw and after the page's lock
(footlock.plant_feet: contacts labelled, then the lock): the toe's speed while its contact bit is on, and the speed of
the lowest foot point within 4 cm of the floor (metrics.low_foot_speeds), which needs no contact bits.
"""
from __future__ import annotations

import numpy as np

from .. import metrics
from ..data.style_locomotion import STYLES, StyledClip
from ..footlock import plant_feet
from ..mocap.skeleton import canonical_skeleton
from .pilots import FREEZE_FRACTION, Candidate, decode, held_out_motion, initial_states, sample, seed_inputs

N_SEEDS = 5
FPS = 30.0
HEIGHT_BAND = (0.4, 1.3)  # plausible hip heights (m) on the canonical skeleton, walking to running and crouched styles


def real_measures(codec, clips: list[StyledClip], style: str) -> dict:
    skel = canonical_skeleton()
    real = held_out_motion(codec, clips, style)
    change = np.concatenate([metrics.pose_change_per_second(r.positions, FPS) for r in real if len(r.positions) > FPS])
    return {"clips": len(real), "pose_change_median": float(np.median(change)),
            "sliding_contact_bits": metrics.foot_skating_clips([(r.positions, r.contacts) for r in real], FPS, skel),
            "sliding_low_foot": metrics.low_foot_sliding_clips([r.positions for r in real], FPS, skel)}


def long_runs(cand: Candidate, clips: list[StyledClip], styles: list[str], frames: int = 10_000, n_seeds: int = N_SEEDS,
              log=lambda line: print(line, flush=True)) -> dict:
    skel = canonical_skeleton()
    seeds, names = [], []
    for style in styles:
        pool = seed_inputs(cand, clips, style)
        for k in range(n_seeds):
            name, x = pool[k % len(pool)]
            seeds.append((STYLES.index(style) if cand.styled else 0, x))
            names.append((style, name, 1000 + k))
    start = initial_states(cand, seeds)
    # One batched run per random seed k (row r of batch k is style r's stream k), so every stream's draws depend on k
    # alone, not on which other styles are measured.
    feats = {}
    for k in range(n_seeds):
        rows = [i for i, (_, _, s) in enumerate(names) if s == 1000 + k]
        sub = tuple(t[:, rows] if t.dim() == 3 else t[rows] for t in start)
        out = sample(cand, sub, frames, np.random.default_rng(1000 + k))
        for j, i in enumerate(rows):
            feats[i] = out[j]
        log(f"long runs: random seed {1000 + k} sampled ({len(rows)} streams x {frames} frames)")
    report = {"frames": frames, "seeds_per_style": n_seeds, "height_band": HEIGHT_BAND, "styles": {}}
    for style in styles:
        real = real_measures(cand.codec, clips, style)
        line = FREEZE_FRACTION * real["pose_change_median"]
        runs, raw_pos, locked_pos, raw_bits, locked_bits = [], [], [], [], []
        for i, (s, name, seed) in enumerate(names):
            if s != style:
                continue
            f = feats[i]
            finite = bool(np.isfinite(f).all())
            run = {"seed": name, "random_seed": seed, "finite": finite}
            if finite:
                m = decode(cand, f)
                change = metrics.pose_change_per_second(m.positions, FPS)
                locked, labels = plant_feet(m.positions, m.contacts, FPS, skel)
                hips = m.positions[:, 0, 1]
                run.update({"min_pose_change": float(change.min()), "frozen_seconds": int((change < line).sum()),
                            "hip_height": [float(hips.min()), float(hips.max())],
                            "root_speed_mean": float(np.mean(metrics.root_speed(f, FPS)))})
                run["stable"] = bool(run["frozen_seconds"] == 0 and HEIGHT_BAND[0] <= hips.min() and hips.max() <= HEIGHT_BAND[1])
                raw_pos.append(m.positions), locked_pos.append(locked)
                raw_bits.append((m.positions, m.contacts)), locked_bits.append((locked, labels))
            else:
                run["stable"] = False
            runs.append(run)
        gen = {"sliding_contact_bits": metrics.foot_skating_clips(raw_bits, FPS, skel) if raw_bits else None,
               "sliding_low_foot": metrics.low_foot_sliding_clips(raw_pos, FPS, skel) if raw_pos else None,
               "sliding_contact_bits_locked": metrics.foot_skating_clips(locked_bits, FPS, skel) if locked_bits else None,
               "sliding_low_foot_locked": metrics.low_foot_sliding_clips(locked_pos, FPS, skel) if locked_pos else None}
        report["styles"][style] = {"real": real, "freeze_line": line, "runs": runs, "generated": gen,
                                   "stable": sum(r["stable"] for r in runs)}
        low = min((r.get("min_pose_change", 0.0) for r in runs), default=0.0)
        log(f"long runs [{style}]: {report['styles'][style]['stable']}/{len(runs)} stable, lowest second "
            f"{low / real['pose_change_median']:.2f}x the real median; sliding after the lock (lowest foot) "
            f"{gen['sliding_low_foot_locked']:.3f} m/s against real {real['sliding_low_foot']:.3f}")
    return report


def pct(v) -> str:
    return "—" if v is None else f"{100 * v:.1f}%"


def num(v, digits: int = 3) -> str:
    return "—" if v is None else f"{v:.{digits}f}"


def report_markdown(result: dict) -> str:
    """The full run's tables from python -m training.style_generator.evaluate's JSON."""
    pilot, check, runs = result["pilot"], result["style_check"], result["long_runs"]
    shipped, style = pilot["models"]["shipped generator (CMU)"], pilot["models"]["style generator"]
    lines = [f"Checkpoint `{result['checkpoint']}`; measured {result['date']} on this project's 2-core machine.", "",
             "### Raw output against the shipped generator (no refiner, no lock)", "",
             f"Two-sample test as the pilot measured it ({pilot['frames_per_seed']} frames per seed and stream set, "
             f"{pilot['classifier_seeds']} classifier seed(s); 50% = cannot tell), hip-bob probe, held-out NLL per frame "
             "(physical units), root speed.", "",
             "| style | NLL shipped / style | windows shipped / style | single frames shipped / style | hip bob 0.94 Hz real / style | 2.81 Hz real / style | above 5 Hz real / style | root speed real / style (m/s) |",
             "|---|---|---|---|---|---|---|---|"]
    for s, r in style["styles"].items():
        real = pilot["real"][s]
        sh = shipped["styles"].get(s)
        lines.append(f"| {s} | {shipped['nll'][s]:.4g} / {style['nll'][s]:.4g} | "
                     f"{pct(sh['two_sample']['window']) if sh else '—'} / {pct(r['two_sample']['window'])} | "
                     f"{pct(sh['two_sample']['frame']) if sh else '—'} / {pct(r['two_sample']['frame'])} | "
                     f"{real['hip_bob']['slow_0.9Hz']:.2f} / {r['hip_bob']['slow_0.9Hz']:.2f} | "
                     f"{real['hip_bob']['bob_2.8Hz']:.2f} / {r['hip_bob']['bob_2.8Hz']:.2f} | "
                     f"{real['hip_bob']['above_5Hz']:.2f} / {r['hip_bob']['above_5Hz']:.2f} | "
                     f"{real['root_speed_mean']:.2f} / {r['root_speed_mean']:.2f} |")
    names = check["styles"]
    lines += ["", "### Style check", "",
              f"A classifier trained on real Bandai walks (32-frame windows) names real held-out walks right in "
              f"{pct(check['real_accuracy'])} of windows, and generated walks ({len(check['stream_seeds'])} streams of "
              f"{check['frames_per_stream']} frames per style) in **{pct(check['generated_accuracy'])} of windows** and "
              f"{pct(check['generated_stream_accuracy'])} of streams (chance {100 / len(names):.0f}%). Confusion of the "
              "generated walks (rows: the style asked for; columns: the style named, in windows):", "",
              "| asked \\ named | " + " | ".join(names) + " | right |", "|---|" + "---|" * (len(names) + 1)]
    for i, (s, row) in enumerate(zip(names, check["generated_confusion"])):
        lines.append(f"| {s} | " + " | ".join(str(v) for v in row) + f" | {pct(row[i] / max(1, sum(row)))} |")
    lines += ["", "Pace per style: mean speed, and cadence by the contact bits and by the feet's spacing (steps/min).", "",
              "| style | speed real | speed generated | cadence real (bits / feet) | cadence generated (bits / feet) |",
              "|---|---|---|---|---|"]
    for s, p in check["pace"].items():
        lines.append(f"| {s} | {p['speed_real']:.2f} | {p['speed_generated']:.2f} | {p['cadence_real']:.0f} / "
                     f"{p['cadence_by_feet_real']:.0f} | {p['cadence_generated']:.0f} / {p['cadence_by_feet_generated']:.0f} |")
    lines += ["", f"### Long runs: {runs['frames']} frames, {runs['seeds_per_style']} seeds per style", "",
              "Stable: no second below 20% of the style's real median pose change, hips within "
              f"{runs['height_band'][0]}–{runs['height_band'][1]} m, all finite. Sliding (m/s) by the contact bits / by "
              "the lowest foot point, raw and after the page's lock, against the style's real held-out clips.", "",
              "| style | stable | lowest second / real median | sliding real (bits / lowest foot) | raw | after the lock |",
              "|---|---|---|---|---|---|"]
    for s, r in runs["styles"].items():
        low = min((x.get("min_pose_change", 0.0) for x in r["runs"]), default=0.0)
        g, real = r["generated"], r["real"]
        lines.append(f"| {s} | {r['stable']}/{len(r['runs'])} | {low / real['pose_change_median']:.2f} | "
                     f"{num(real['sliding_contact_bits'])} / {num(real['sliding_low_foot'])} | "
                     f"{num(g['sliding_contact_bits'])} / {num(g['sliding_low_foot'])} | "
                     f"{num(g['sliding_contact_bits_locked'])} / {num(g['sliding_low_foot_locked'])} |")
    return "\n".join(lines) + "\n"
