"""The generator report: sampled motion against the generator's held-out validation clips (foot skating,
root speed and turning-rate distributions, NPSS, a long stability run, a temperature sweep), written to
docs/models/generator.{md,json,png} by python -m training.generator.evaluate."""
from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from .. import metrics
from ..data.features import wraparound_report
from ..data.locomotion import load_clips
from ..paths import MODELS_DIR, REPORTS_DIR
from .shipped import ShippedGenerator

FREEZE_FRACTION = 0.2
STANDING_SPEED = 0.2  # m/s: a run whose median root speed is below this stands in place (real walks: p10 0.05, p50 0.88)
HEIGHT_BAND = (0.6, 1.2)  # plausible pelvis heights (m) for walking and running on the canonical skeleton


def evaluate_generator(frames: int, n_seeds: int, temperature: float, mocap: str | None, models_dir=MODELS_DIR,
                       plot: bool = True) -> dict:
    gen = ShippedGenerator(models_dir)
    fps = gen.info["fps"]
    real = gen.held_out(load_clips(mocap))
    seeds = list(range(min(n_seeds, len(gen.info["seeds"]))))
    # One run of all seeds, batched: stream k uses seed k.
    t0 = time.perf_counter()
    rng = np.random.default_rng(2024)
    feats = gen.sample(seeds, frames, temperature, rng, progress=True)
    sample_seconds = time.perf_counter() - t0

    skel = gen.skel
    real_feats = [r.features for r in real]
    real_speed = np.concatenate([metrics.root_speed(f, fps) for f in real_feats])
    real_turn = np.concatenate([metrics.turning_rate(f, fps) for f in real_feats])
    real_change = np.concatenate([metrics.pose_change_per_second(r.positions, fps) for r in real if len(r.positions) > fps])
    real_skate = metrics.foot_skating_clips([(r.positions, r.contacts) for r in real], fps, skel)
    real_low_foot = metrics.low_foot_sliding_clips([r.positions for r in real], fps, skel)
    freeze_line = FREEZE_FRACTION * float(np.median(real_change))
    joint_dims = slice(7, feats.shape[-1] - 2)
    real_windows = metrics.windows_of([f[:, joint_dims] for f in real_feats], 60, 30)

    runs = []
    for k, s in enumerate(seeds):
        f = feats[k]
        finite = bool(np.isfinite(f).all())
        pos = gen.positions(f) if finite else None
        contacts = (f[:, -2:] > 0.5).astype(np.uint8)
        change = metrics.pose_change_per_second(pos, fps) if finite else np.array([0.0])
        height = f[:, 3]
        run = {
            "seed": gen.info["seeds"][s]["name"], "frames": frames, "finite": finite,
            "min_pose_change": float(change.min()), "frozen_seconds": int((change < freeze_line).sum()),
            "root_height_min": float(height.min()), "root_height_max": float(height.max()),
            "height_in_band": bool(HEIGHT_BAND[0] <= height.min() and height.max() <= HEIGHT_BAND[1]),
            "foot_skating": metrics.foot_skating(pos, contacts, fps, skel) if finite else None,
            "low_foot_sliding": float(metrics.low_foot_speeds(pos, fps, skel).mean()) if finite else None,
            "contact_share": contacts.mean(axis=0).tolist(),
            "root_speed": metrics.summary(metrics.root_speed(f, fps)),
            "turning_rate_abs": metrics.summary(np.abs(metrics.turning_rate(f, fps))),
            "npss": metrics.npss(real_windows, metrics.windows_of([f[:, joint_dims]], 60, 30)) if finite else None,
            "pose_change_curve": change.tolist(),
        }
        run["stable"] = run["finite"] and run["frozen_seconds"] == 0 and run["height_in_band"]
        runs.append(run)

    # NPSS scale: how different are two halves of real data from each other?
    half = len(real_feats) // 2
    real_vs_real = metrics.npss(metrics.windows_of([f[:, joint_dims] for f in real_feats[:half]], 60, 30),
                                metrics.windows_of([f[:, joint_dims] for f in real_feats[half:]], 60, 30))
    gen_speed = np.concatenate([metrics.root_speed(f, fps) for f in feats])
    gen_turn = np.concatenate([metrics.turning_rate(f, fps) for f in feats])
    report = {
        "model": "generator", "file": gen.info["file"], "bytes": gen.info["bytes"], "weights": gen.info.get("weights", "float32"), "fps": fps,
        "temperature": temperature, "noise_correlation": gen.noise_correlation, "frames_per_seed": frames, "sampling_seconds": sample_seconds,
        "real": {"clips": len(real), "frames": int(sum(len(f) for f in real_feats)), "foot_skating": real_skate,
                 "low_foot_sliding": real_low_foot,
                 "root_speed": metrics.summary(real_speed), "turning_rate_abs": metrics.summary(np.abs(real_turn)),
                 "median_pose_change": float(np.median(real_change)), "npss_half_vs_half": real_vs_real},
        "generated": {"foot_skating_mean": float(np.nanmean([r["foot_skating"] for r in runs if r["foot_skating"] is not None])),
                      "low_foot_sliding": metrics.low_foot_sliding_clips([gen.positions(f) for f in feats if np.isfinite(f).all()], fps, skel),
                      "root_speed": metrics.summary(gen_speed), "turning_rate_abs": metrics.summary(np.abs(gen_turn)),
                      "root_speed_wasserstein": metrics.wasserstein_1d(gen_speed, real_speed),
                      "turning_rate_wasserstein": metrics.wasserstein_1d(gen_turn, real_turn),
                      "npss_mean": float(np.mean([r["npss"] for r in runs if r["npss"] is not None]))},
        "freeze_threshold": freeze_line, "height_band": HEIGHT_BAND,
        "all_stable": all(r["stable"] for r in runs), "runs": runs,
        "training": {k: gen.info["training"][k] for k in ("epochs", "valid_nll_per_frame")},
    }
    if plot:
        plot_generator(report, real_speed, real_turn, gen_speed, gen_turn)
        report["model_info"] = dict(gen.info["onnx"], train_frames=gen.info["training"]["train_frames"],
                                    parameters=count_parameters(gen.info["onnx"]), seeds=gen.info["seeds"],
                                    stop_note=stop_note(REPORTS_DIR / "generator-train.log"))
        clips = [c for c in load_clips(mocap) if c.category in ("walk", "run")]
        starts = np.cumsum([0] + [len(c.rotations) for c in clips])[:-1].tolist()
        report["wraparound"] = wraparound_report(np.concatenate([c.rotations for c in clips]), starts)
    return report


def stop_note(log: Path) -> str:
    text = log.read_text() if log.exists() else ""
    return " (stopped by hand once validation NLL flattened; see the log)" if "stopped by hand" in text else ""


def count_parameters(onnx: dict) -> int:
    d, h, m = onnx["dim"], onnx["hidden"], onnx["mixtures"]
    lstm = 2 * (4 * h * (h + h) + 8 * h)
    return (d * h + h) + (h * h + h) + lstm + (h * m * (1 + 2 * d) + m * (1 + 2 * d))


def plot_generator(report: dict, real_speed, real_turn, gen_speed, gen_turn) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(15, 4))
    bins = np.linspace(0, 4, 41)
    axes[0].hist(real_speed, bins, density=True, alpha=0.6, label="real (held out)")
    axes[0].hist(gen_speed, bins, density=True, alpha=0.6, label="generated")
    axes[0].set(title="root speed", xlabel="m/s")
    axes[0].legend()
    bins = np.linspace(-4, 4, 41)
    axes[1].hist(real_turn, bins, density=True, alpha=0.6, label="real (held out)")
    axes[1].hist(gen_turn, bins, density=True, alpha=0.6, label="generated")
    axes[1].set(title="turning rate", xlabel="rad/s")
    for r in report["runs"]:
        axes[2].plot(r["pose_change_curve"], lw=0.8, label=r["seed"])
    axes[2].axhline(report["freeze_threshold"], color="k", ls="--", lw=1, label="freeze line (20% of real median)")
    axes[2].set(title=f"pose change per second over {report['frames_per_seed']} frames", xlabel="second", ylabel="m/s")
    axes[2].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(REPORTS_DIR / "generator.png", dpi=90)
    plt.close(fig)


# Measured by hand with this report on 2026-12-03, changing only generator.json's sampling.noise_correlation.
HELD_NOISE_NOTE = (
    "**Noise held over frames** (generator.json `sampling`, the page's sampler and ShippedGenerator.sample alike): each "
    "frame's normals keep a share ρ of the last frame's, z = ρ·z' + sqrt(1 − ρ²)·n, so every value is still N(0, 1) but "
    "the noise drifts instead of jumping. Main run (τ 0.5, 5 seeds × 10,000 frames), ρ = 0 / 0.8 / 0.9 / 0.95: skating "
    "0.991 / 0.546 / 0.436 / 0.376 m/s, lowest-point sliding 1.189 / 0.854 / 0.753 / 0.691, NPSS 3.985 / 1.113 / 0.951 / "
    "0.977 (real half against half 0.916); at ρ = 0 walk 16_19 stood in place (median root speed 0.05 m/s, feet planted "
    "100% of frames) and the jitter of fresh noise kept it above the freeze line; at 0.8 it walks (0.45 m/s). Stability "
    "decides ρ: at 0.9 walk 16_19 drops below the freeze line for 1 second, at 0.95 for 23, so 0.8 is shipped. At τ = 1 "
    "held noise lets two streams leave the root height band (below); at ρ = 0 every τ row was stable.")
REPORT_JSON = REPORTS_DIR / "generator.json"
REPORT_MD = REPORTS_DIR / "generator.md"


def targets(report: dict) -> list[tuple[str, bool, str]]:
    """Each target the report checks: (the target, whether it is met, the measured numbers)."""
    r, g = report["real"], report["generated"]
    stable = sum(run["stable"] for run in report["runs"])
    return [
        ("foot skating no more than real", g["foot_skating_mean"] <= r["foot_skating"],
         f"{g['foot_skating_mean'] / r['foot_skating']:.1f}× real"),
        ("lowest-point sliding no more than real", g["low_foot_sliding"] <= r["low_foot_sliding"],
         f"{g['low_foot_sliding'] / r['low_foot_sliding']:.1f}× real"),
        ("NPSS no further from the held-out clips than half of them from the other half",
         g["npss_mean"] <= r["npss_half_vs_half"], f"{g['npss_mean']:.3f} against {r['npss_half_vs_half']:.3f}"),
        (f"every {report['frames_per_seed']:,}-frame run stable", report["all_stable"],
         f"{stable} of {len(report['runs'])}"),
    ]


def summary_lines(report: dict) -> list[str]:
    """The five lines a report opens with: what the model does, how the page uses it, the headline numbers against
    real held-out clips, and what is not met."""
    r, g = report["real"], report["generated"]
    unmet = [f"{name} ({numbers})" for name, met, numbers in targets(report) if not met]
    met = [name for name, met, _ in targets(report) if met]
    return [
        "- **What it does:** generates walking and running frame by frame: an LSTM gives a Gaussian mixture over the "
        "next frame (pose, root motion, foot contacts) and a frame is drawn from it.",
        f"- **In the page:** Random walk samples it in a worker at temperature {report['temperature']} (noise held over "
        "frames); the refiner and the foot lock clean it up, and Path and Steer drive it with the MAP optimiser.",
        f"- **Against {r['clips']} real held-out clips:** foot skating {g['foot_skating_mean']:.3f} m/s against "
        f"{r['foot_skating']:.3f}; lowest-point sliding {g['low_foot_sliding']:.3f} m/s against {r['low_foot_sliding']:.3f}.",
        f"- **Also:** root speed {g['root_speed']['mean']:.2f} m/s against {r['root_speed']['mean']:.2f}, turning "
        f"{g['turning_rate_abs']['mean']:.2f} rad/s against {r['turning_rate_abs']['mean']:.2f}, NPSS {g['npss_mean']:.3f} "
        f"(real half against half {r['npss_half_vs_half']:.3f}).",
        "- **Not met:** " + ("; ".join(unmet) if unmet else "nothing") + (f". Met: {'; '.join(met)}." if met else "."),
    ]


def generator_markdown(report: dict) -> str:
    """docs/models/generator.md from the numbers in generator.json (nothing here measures)."""
    r, g = report["real"], report["generated"]
    lines = [
        "# Generator report (LSTM + Gaussian mixture)",
        "",
        *summary_lines(report),
        "",
        "![distributions and stability](generator.png)",
        "",
        "Made by `python -m training.generator.evaluate` from the shipped `public/models/generator.onnx`",
        f"({report['bytes'] / 1e6:.2f} MB), sampled with onnxruntime at temperature {report['temperature']} as the page samples it "
        f"(normals held over frames with correlation {report.get('noise_correlation', 0.0)}, generator.json `sampling`; the sweep "
        f"rows too), {report['frames_per_seed']} frames per seed at {report['fps']} fps, against {r['clips']} held-out real clips "
        f"({r['frames']} frames). Training: {report['training']['epochs']} epochs, validation NLL "
        f"{report['training']['valid_nll_per_frame']:.2f} per frame.",
        "",
        "| measure | real held-out | generated |",
        "|---|---|---|",
        f"| foot skating: toe speed while planted (m/s) | {r['foot_skating']:.3f} | {g['foot_skating_mean']:.3f} |",
        f"| foot sliding: lowest foot point's speed within 4 cm of the floor, no contacts needed (m/s) | {r['low_foot_sliding']:.3f} | {g['low_foot_sliding']:.3f} |",
        f"| root speed mean / p10 / p50 / p90 (m/s) | {r['root_speed']['mean']:.2f} / {r['root_speed']['p10']:.2f} / {r['root_speed']['p50']:.2f} / {r['root_speed']['p90']:.2f} "
        f"| {g['root_speed']['mean']:.2f} / {g['root_speed']['p10']:.2f} / {g['root_speed']['p50']:.2f} / {g['root_speed']['p90']:.2f} |",
        f"| turning rate abs. mean / p90 (rad/s) | {r['turning_rate_abs']['mean']:.2f} / {r['turning_rate_abs']['p90']:.2f} | {g['turning_rate_abs']['mean']:.2f} / {g['turning_rate_abs']['p90']:.2f} |",
        f"| root speed distance to real (Wasserstein, m/s) | 0 | {g['root_speed_wasserstein']:.3f} |",
        f"| turning rate distance to real (Wasserstein, rad/s) | 0 | {g['turning_rate_wasserstein']:.3f} |",
        f"| NPSS of joint rotations vs held-out (0 = same spectra) | {r['npss_half_vs_half']:.3f} (half vs half of real) | {g['npss_mean']:.3f} |",
        "",
        f"## Stability: {report['frames_per_seed']} frames per seed",
        "",
        f"Freeze line: pose change below {report['freeze_threshold']:.3f} m/s in any second (20% of the real median "
        f"{r['median_pose_change']:.3f} m/s). Root height band {report['height_band'][0]}–{report['height_band'][1]} m.",
        "",
        "| seed | finite | frozen seconds | min pose change (m/s) | root speed p50 (m/s) | root height min–max (m) | skating (m/s) | contact share L/R | NPSS | stable |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for run in report["runs"]:
        lines.append(f"| {run['seed']} | {run['finite']} | {run['frozen_seconds']} | {run['min_pose_change']:.3f} | "
                     f"{run['root_speed']['p50']:.2f} | "
                     f"{run['root_height_min']:.2f}–{run['root_height_max']:.2f} | {run['foot_skating']:.3f} | "
                     f"{run['contact_share'][0]:.2f}/{run['contact_share'][1]:.2f} | {run['npss']:.3f} | {'yes' if run['stable'] else 'NO'} |")
    lines += ["", f"All runs stable: **{'yes' if report['all_stable'] else 'no'}**.", ""]
    standing = [run for run in report["runs"] if run["root_speed"]["p50"] < STANDING_SPEED]
    if standing:
        lines += ["Stable here means finite, never below the freeze line and inside the height band; it does not mean "
                  "walking. " + "; ".join(
                      f"{run['seed']} settles into standing in place (median root speed {run['root_speed']['p50']:.2f} m/s, "
                      f"feet planted {run['contact_share'][0]:.0%}/{run['contact_share'][1]:.0%} of frames)" for run in standing)
                  + f". The freeze line does not catch it: it measures pose change, and the independent draw of every "
                  "frame keeps the joints jittering above it. Standing runs are counted as stable, and their spectra "
                  "raise the mean NPSS.", ""]
    if report.get("sweep"):
        lines += ["## Temperature", "",
                  "Sampling temperature τ scales the mixture's standard deviations (and sharpens its weights). "
                  f"Each row: {report['sweep'][0]['frames_per_seed']} frames for each of the same seeds.", "",
                  "| τ | foot skating (m/s) | root speed mean (m/s) | turning abs. mean (rad/s) | NPSS | min pose change (m/s) | all stable |",
                  "|---|---|---|---|---|---|---|"]
        for row in report["sweep"]:
            rg = row["generated"]
            lines.append(f"| {row['temperature']} | {rg['foot_skating_mean']:.3f} | {rg['root_speed']['mean']:.2f} | "
                         f"{rg['turning_rate_abs']['mean']:.2f} | {rg['npss_mean']:.3f} | "
                         f"{min(run['min_pose_change'] for run in row['runs']):.3f} | {'yes' if row['all_stable'] else 'no'} |")
        unstable = [(row["temperature"], run) for row in report["sweep"] for run in row["runs"] if not run["stable"]]
        if unstable:
            lines += ["", "Not stable: " + "; ".join(
                f"τ {t}, {run['seed']}: " + ", ".join(why for why, bad in (
                    ("not finite", not run["finite"]), (f"{run['frozen_seconds']} frozen seconds", run["frozen_seconds"] > 0),
                    (f"root height {run['root_height_min']:.2f}–{run['root_height_max']:.2f} m, outside the band", not run["height_in_band"])) if bad)
                for t, run in unstable) + "."]
        lines.append("")
    m = report["model_info"]
    lines += [
        "## Reading the numbers", "",
        f"- Foot skating is {g['foot_skating_mean'] / r['foot_skating']:.1f}× that of real motion measured the same way: "
        f"every frame draws new noise from the mixture (held only in part, correlation {report.get('noise_correlation', 0.0)}), so "
        "planted feet still jitter. The refiner and the contact "
        "clean-up remove exactly this ([refiner.md](refiner.md) measures refined + foot-locked skating the same way). "
        f"The independent measure, which needs no contact bits (so it also sees feet near the floor whose bit is off), "
        f"{'says the same' if g['low_foot_sliding'] > r['low_foot_sliding'] else 'disagrees'} "
        f"({g['low_foot_sliding'] / r['low_foot_sliding']:.1f}× real): {g['low_foot_sliding']:.3f} against {r['low_foot_sliding']:.3f} m/s.",
        f"- Generated root speed averages {g['root_speed']['mean']:.2f} m/s against {r['root_speed']['mean']:.2f} m/s for the "
        f"held-out clips, and turning is {'milder' if g['turning_rate_abs']['mean'] < r['turning_rate_abs']['mean'] else 'sharper'} "
        f"({g['turning_rate_abs']['mean']:.2f} vs {r['turning_rate_abs']['mean']:.2f} rad/s); the fastest tenth of the frames "
        f"start at {g['root_speed']['p90']:.2f} m/s against {r['root_speed']['p90']:.2f}: "
        + (f"free-running samples mostly settle into a steady, moderate walk ({', '.join(run['seed'] for run in standing)} "
           f"{'stands' if len(standing) == 1 else 'stand'} in place instead: see the stability section). " if standing else
           "free-running samples settle into a steady, moderate walk. ")
        + "Faster walking, running and sharp turns are in the model but need steering (path and speed control) to come out.",
        "- NPSS is on a scale set by the real data: two halves of the held-out set differ by the first column's value.",
        "",
        "## Model", "",
        f"FC {m['dim']}→{m['hidden']} → FC → 2 × LSTM({m['hidden']}) → FC to a {m['mixtures']}-component diagonal mixture "
        f"over {m['dim']} features; {m['parameters']:,} parameters, {report['bytes'] / 1e6:.2f} MB of ONNX "
        f"(weights stored as {report.get('weights', 'float32')}: int8 with the mixture head float16, computed in float32; "
        "a float32 file was 3.11 MB and its report numbers differ from these by no more than float16 storage's do, "
        "see [weights.md](weights.md)). "
        "The ONNX step is written by `training/generator/graph.py` directly as a gate-level graph (Gemm products and "
        "the gate maths, no ONNX LSTM op); its parity with torch is in generator.json. "
        f"The width was chosen for the browser budget: in onnxruntime (1 thread) a step costs about 0.3 ms at batch 1 "
        f"(widths 128/192/256 gave 10.9k/3.7k/2.8k steps/s at batch 1 and 83k/51k/31k particle-steps/s at batch 64). "
        f"Trained on {m['train_frames']:,} frames (walk and run clips, mirrored, and 0.9×/1.1× speed copies), "
        f"{report['training']['epochs']} epochs{m['stop_note']}, dropout 0.25; the training log is copied to "
        "[generator-train.log](generator-train.log). A width-128 variant was trained and measured, and not shipped "
        "([bench.md](../bench.md)).",
        "",
        "**Rotation parameterisation.** Joint rotations are rotation vectors relative to each joint's mean rotation. "
        f"Measured over {report['wraparound']['pairs_checked']:,} consecutive joint-frame pairs of the walking and running "
        f"data whose true rotation changes by less than {report['wraparound']['small_turn_rad']} rad: the largest jump is "
        f"{report['wraparound']['rotvec_max_jump']:.2f} in rotation-vector units, against {report['wraparound']['euler_zyx_max_jump']:.2f} rad for "
        f"ZYX Euler angles of the same rotations (Euler angles jump near gimbal lock and at ±π). The largest angle from a "
        f"reference is {report['wraparound']['rotvec_max_angle_from_reference']:.2f} rad, inside the chart's π limit.",
        "",
        "**Initial state (eq. 26).** Each seed's (h, c) is optimised so the following real frames are likely. "
        "Mean NLL per frame of the next 5 real frames, zero state → estimated state: "
        + "; ".join(f"{sd['name']}: {sd['nll_zero_state']:.0f} → {sd['nll_estimated_state']:.0f}" for sd in m["seeds"]) + ".",
        "",
        "## History", "",
        "Real skating is pooled over the held-out clips each measured on its own (frame pairs never span two clips); "
        "reports before 2026-12-01 joined the clips end to end and gave 0.393 m/s.",
        "",
        HELD_NOISE_NOTE,
        "",
    ]
    return "\n".join(lines)


def slim_report(report: dict) -> dict:
    """What generator.json keeps: no per-second curves, and of the seeds only their names and likelihoods."""
    slim_runs = lambda rep: [{k: v for k, v in r.items() if k != "pose_change_curve"} for r in rep["runs"]]
    seeds = [{k: sd[k] for k in ("name", "nll_zero_state", "nll_estimated_state")} for sd in report["model_info"]["seeds"]]
    return dict(report, runs=slim_runs(report), sweep=[dict(row, runs=slim_runs(row)) for row in report["sweep"]],
                model_info=dict(report["model_info"], seeds=seeds))


def rewrite_generator_markdown() -> None:
    """generator.md again from the committed generator.json, without measuring."""
    REPORT_MD.write_text(generator_markdown(json.loads(REPORT_JSON.read_text())))


def write_generator_report(frames: int, n_seeds: int, temperature: float, sweep: list[float], sweep_frames: int,
                           mocap: str | None, models_dir: Path = MODELS_DIR) -> dict:
    """docs/models/generator.{md,json,png}: the main evaluation at `temperature` and a row per sweep temperature."""
    REPORTS_DIR.mkdir(parents=True, exist_ok=True)
    report = evaluate_generator(frames, n_seeds, temperature, mocap, models_dir)
    report["sweep"] = [evaluate_generator(sweep_frames, n_seeds, t, mocap, models_dir, plot=False) for t in sweep]
    REPORT_JSON.write_text(json.dumps(slim_report(report), indent=1) + "\n")
    REPORT_MD.write_text(generator_markdown(report))
    return report
