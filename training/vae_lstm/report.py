"""docs/models/vae-lstm.{md,json}: the VAE-LSTM measured as training/vae_lstm/measures.py describes, beside the
latent ERD report's rows on the same windows (docs/models/latent-erd.json) and the page's numbers on the
benchmark paths (docs/models/vae-lstm-browser.json, npm run evaluate:vae-lstm).
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .. import metrics
from ..data.locomotion import load_clips
from ..data.windows import WindowCorpus
from ..latent_erd import measures as erd_measures
from ..paths import MODELS_DIR, REPO_ROOT, REPORTS_DIR
from . import measures as m

REPORT_JSON = REPORTS_DIR / "vae-lstm.json"
BROWSER_JSON = REPORTS_DIR / "vae-lstm-browser.json"
ERD_JSON = REPORTS_DIR / "latent-erd.json"
NOTES_JSON = REPORTS_DIR / "vae-lstm-notes.json"
TRAINING_RUNS = ("vae-lstm", "vae-lstm-e100", "vae-lstm-mix")
LONG_RUN_SEEDS = 5
# The ways of drawing a prior sample compared (generation.py), beside the shipped one (vae-lstm.json's `sampling`).
OTHER_SAMPLINGS = {"a latent per step, rho 0": {"mode": "steps", "rho": 0.0}, "a latent per step, rho 0.9": {"mode": "steps", "rho": 0.9}}


def samplings(shipped: dict) -> dict[str, dict]:
    """The shipped sampling first; for a model trained with z1 in every step (`mix`), also the paper's Algorithm 1
    on it (z1 only the first state); with a z1 prior from training starts (prior_bank.py), also the shipped way with
    z1 from N(0, I); then OTHER_SAMPLINGS."""
    mix = shipped.get("mix", 0.0) if shipped["mode"] == "z1" else 0.0
    prior = shipped.get("z1_prior") if shipped["mode"] == "z1" else None
    where = f"z1 from the posteriors of {prior['starts']} training starts" if prior else "one z1"
    out = {f"{where}, also {mix:.0%} of every step (shipped)" if mix else f"{where} (Algorithm 1, shipped)": shipped}
    if prior:
        normal = {k: v for k, v in shipped.items() if k != "z1_prior"}
        out[f"one z1 from N(0, I), also {mix:.0%} of every step" if mix else "one z1 from N(0, I) (Algorithm 1)"] = normal
    if mix:
        out["one z1 from N(0, I) as Algorithm 1 (only the first state)"] = {"mode": "z1"}
    return out | OTHER_SAMPLINGS


def described(sampling: dict) -> dict:
    """A sampling as the report states it: a z1 prior by where it comes from, not its numbers (vae-lstm.json has them)."""
    prior = sampling.get("z1_prior")
    return sampling | {"z1_prior": {k: prior[k] for k in ("kind", "starts", "seed")}} if prior else sampling


def evaluate(mocap: str | None, previous: dict, models_dir: Path = MODELS_DIR) -> dict:
    corpus = WindowCorpus(load_clips(mocap))
    vae = m.ShippedVae.load(models_dir)
    fps = vae.fps
    report: dict = {"fps": fps, "chunk_frames": vae.info["chunk_steps"] * vae.info["pooling"], "window_frames": vae.info["window"]}

    report["sampling"] = described(vae.info["sampling"])
    windows = erd_measures.prediction_windows(corpus)
    rows = m.prediction_rows(vae, corpus, windows, samplings(vae.info["sampling"]))
    if ERD_JSON.exists():
        erd = json.loads(ERD_JSON.read_text()).get("prediction", {})
        if erd.get("windows") == len(windows):
            rows.update({name: row for name, row in erd["rows"].items()})
    browser = json.loads(BROWSER_JSON.read_text()) if BROWSER_JSON.exists() else {}
    if browser.get("map_prediction", {}).get("followed"):
        mp = browser["map_prediction"]
        rows["generator + MAP optimiser, true root path"] = {"with_root_cm": mp["with_root_cm"], "relative_cm": mp["relative_cm"]}
    report["prediction"] = {"windows": len(windows), "clips": sorted({corpus.valid_clips[w.clip].file for w in windows}),
                            "rows": {name: {kind: {int(k): v for k, v in e.items()} for kind, e in row.items()} for name, row in rows.items()}}

    median = erd_measures.real_pose_change_median(corpus, fps)
    runs, long_outputs = [], []
    for seed in range(LONG_RUN_SEEDS):
        r = m.long_run(vae, seed)
        runs.append({"seed": seed, "frames": len(r["positions"]), "finite": bool(np.isfinite(r["positions"]).all()),
                     **m.freeze_stats(r["positions"], fps, median), "native_seconds": round(r["seconds"], 3),
                     "x_real_time_native": round(len(r["positions"]) / fps / r["seconds"], 1),
                     "seams": m.chunk_seams(r["positions"], report["chunk_frames"])})
        long_outputs.append((r["positions"], r["bits"]))
    report["long_runs"] = {"real_median_pose_change": round(median, 4), "runs": runs,
                           "real_share_below": erd_measures.real_share_below(corpus, fps, median),
                           "real_frame_change_cm": erd_measures.real_frame_change(corpus)}
    report["drawn_long_runs"] = {"runs": {name: [m.drawn_long_run(vae, forward, turn, seed, median) for seed in range(LONG_RUN_SEEDS)]
                                          for name, (forward, turn) in m.DRAWN_LONG_RUNS.items()},
                                 "real_toe_swing": m.real_toe_swing(corpus, fps)}
    report["diversity"] = m.diversity(vae, corpus)
    report["samplings"] = {}
    for name, sampling in samplings(vae.info["sampling"]).items():
        stats = [m.freeze_stats(m.long_run(vae, seed, sampling=sampling)["positions"], fps, median) for seed in range(LONG_RUN_SEEDS)]
        runs_s = m.held_out_control_runs(vae, corpus, sampling)
        report["samplings"][name] = {
            "sampling": described(sampling), "diversity_cm": m.diversity(vae, corpus, sampling=sampling)["prior_samples_cm"],
            "drawn_path_toes_cm": round(float(np.mean([w["toes_cm"] for w in m.drawn_path_diversity(vae, sampling=sampling)])), 2),
            "lowest_second": min(x["lowest_second"] for x in stats), "median_second": round(float(np.mean([x["median_second"] for x in stats])), 3),
            "share_below": round(float(np.mean([x["share_below"] for x in stats])), 4),
            "energy_held_out": round(float(np.mean([metrics.pose_change_per_second(p, fps).mean() for p, _ in runs_s]) / median), 3),
            "jitter_cm": m.jitter_cm([p for p, _ in runs_s]),
            "sliding_held_out_control": m.sliding(runs_s, fps)}
    report["jitter_real_cm"] = m.jitter_cm([c.positions for c in corpus.valid_clips])
    held_out = m.held_out_control_runs(vae, corpus)
    report["energy"] = {"held_out_control": round(float(np.mean([metrics.pose_change_per_second(p, fps).mean() for p, _ in held_out]) / median), 3),
                        "real": round(float(np.mean([metrics.pose_change_per_second(c.positions, fps).mean() for c in corpus.valid_clips]) / median), 3)}
    report["sliding_held_out_control"] = m.sliding(held_out, fps)
    report["sliding_random_control"] = m.sliding(long_outputs, fps)
    report["sliding_real"] = erd_measures.real_sliding(corpus, fps)
    if BROWSER_JSON.exists():
        report["browser"] = json.loads(BROWSER_JSON.read_text())
    report["sizes_bytes"] = {f: (models_dir / f).stat().st_size for f in vae.info["files"].values()}
    report["weights"] = vae.info.get("weights")
    report["training"] = dict(previous.get("training", {}))
    for name in TRAINING_RUNS:
        summary = REPO_ROOT / "runs" / name / "summary.json"
        if summary.exists():
            report["training"][name] = json.loads(summary.read_text())
    return report


def _row(cells) -> str:
    return "| " + " | ".join(str(c) for c in cells) + " |"


def prediction_table(pred: dict, kind: str) -> list[str]:
    horizons = m.HORIZONS
    out = [_row(["model", "initial frames", "control signal", *[f"frame {h}" for h in horizons]]), _row(["---"] * (3 + len(horizons)))]
    seeds = {"VAE-LSTM, 4 initial frames": "4", "latent ERD": "16", "pose-space ERD": "16", "generator (free-running)": "16",
             "generator + MAP optimiser, true root path": "its seed states", m.STILL_MEAN_POSE: "0"}
    for name, row in pred["rows"].items():
        control = "no" if name.startswith("generator (") else "the root path" if "MAP" in name else "yes"
        out.append(_row([name, seeds.get(name, "0" if "prior" in name else "?"), control, *[row[kind].get(h, row[kind].get(str(h))) for h in horizons]]))
    return out


def _coverage(r: dict) -> str:
    return f"{r['leastCoverage'] * 100:.1f}%" if "leastCoverage" in r else "—"


def browser_table(browser: dict) -> list[str]:
    out = [_row(["path", "gait", "model", "mean error (m)", "worst run's mean (m)", "max error (m)", "arc progress (least)",
                 "followed within 0.15 m (least)", "× real time (least)", "sliding after lock (m/s)", "sliding before lock (m/s)"]), _row(["---"] * 11)]
    for r in browser.get("paths", []):
        out.append(_row([r["path"], r["gait"], r["model"], f"{r['meanError']:.3f}", f"{r['worstMeanError']:.3f}", f"{r['maxError']:.3f}",
                         f"{r['leastProgress'] * 100:.1f}%", _coverage(r), f"{r['leastRealTime']:.1f}", f"{r['sliding']:.3f}", f"{r['slidingBeforeLock']:.3f}"]))
    return out


REPORT_MD = REPORTS_DIR / "vae-lstm.md"
PATH_REAL_TIME, PATH_MEAN_ERROR = 100, 0.10  # the targets on the benchmark paths (walk) in the page
DOUBLING_BACK, FOLLOWED_SHARE, FOLLOWED_WITHIN = "back-and-forth", 0.95, 0.15  # issue 43: that path followed 95% within 0.15 m
FOUR_FRAMES = "VAE-LSTM, 4 initial frames"
LATER_FRAMES = (120, 160, 210)


def _span(values, digits: int) -> str:
    lo, hi = min(values), max(values)
    return f"{lo:.{digits}f}" if round(lo, digits) == round(hi, digits) else f"{lo:.{digits}f}–{hi:.{digits}f}"


def _by_gait(verdicts: dict[str, bool]) -> str:
    return ", ".join(f"{gait} {'yes' if ok else 'no'}" for gait, ok in verdicts.items())


def target_rows(r: dict) -> list[tuple[str, str, str, bool]]:
    """The issue's targets against what was measured: (target, measured, met as written, met in full)."""
    rows = []
    paths = [p for p in r.get("browser", {}).get("paths", []) if p["model"] == "vae-lstm"]
    walk = [p for p in paths if p["gait"] == "walk"]
    if walk:
        fast = min(p["leastRealTime"] for p in walk) >= PATH_REAL_TIME
        close = max(p["meanError"] for p in walk) <= PATH_MEAN_ERROR
        b = r["browser"]
        # Timed while the machine had more runnable jobs than cores, × real time measures the machine, not the model.
        loaded = b.get("cores") and b.get("load_before", 0) > b["cores"]
        met = (f"error {'yes' if close else 'no'}; × real time not judged (load {b['load_before']} on {b['cores']} cores)" if loaded and not fast
               else "yes" if fast and close else "no")
        rows.append((f"{len(walk)} benchmark paths in Chromium (walk): ≥ {PATH_REAL_TIME}× real time, mean path error ≤ {PATH_MEAN_ERROR:.2f} m",
                     f"least {min(p['leastRealTime'] for p in walk):.0f}× real time, mean error {_span([p['meanError'] for p in walk], 3)} m",
                     met, fast and close))
    back = [p for p in paths if p["path"] == DOUBLING_BACK and "leastCoverage" in p]
    if back:
        ok = {p["gait"]: p["leastCoverage"] >= FOLLOWED_SHARE for p in back}
        rows.append((f"a path that doubles back ({DOUBLING_BACK}) is followed ≥ {FOLLOWED_SHARE:.0%} of its length within {FOLLOWED_WITHIN} m "
                     "(root, in order: web/motion/pathCoverage.ts)",
                     "; ".join(f"{p['gait']} {p['leastCoverage'] * 100:.1f}% (least of {r['browser'].get('seeds', '?')} seeds), mean error "
                               f"{p['meanError']:.3f} m" for p in back), _by_gait(ok), ok.get("walk", False)))
    real = r["sliding_real"]["low_foot"]
    if paths:
        sliding = {gait: [p["sliding"] for p in paths if p["gait"] == gait] for gait in ("walk", "run")}
        ok = {gait: max(v) <= real for gait, v in sliding.items() if v}
        rows.append(("after the foot lock the body's feet slide no more than real motion's (lowest point, benchmark paths)",
                     "; ".join(f"{gait} {_span(v, 3)} m/s" for gait, v in sliding.items() if v) + f" against real {real}",
                     _by_gait(ok), all(ok.values())))
    d = r["diversity"]
    drawn_paths = d.get("drawn_paths", [])
    if drawn_paths:
        ok = min(w["toes_cm"] for w in drawn_paths) >= d["real_similar_toes_cm"] / 2
        rows.append(("prior samples for the same drawn path differ visibly (toes at least half as far apart as in real windows of similar control)",
                     f"{_span([w['joints_cm'] for w in drawn_paths], 1)} cm, toes {_span([w['toes_cm'] for w in drawn_paths], 1)}; "
                     f"real windows {d['real_similar_cm']}, toes {d['real_similar_toes_cm']}", "yes" if ok else "no", ok))
    lr = r["long_runs"]
    random_ok = all(run["finite"] and run["share_below"] == 0 for run in lr["runs"])
    drawn = r.get("drawn_long_runs", {}).get("runs", {})
    stable = {gait: random_ok if gait == "walk" else True for gait in ("walk", "run")}
    for name, runs in drawn.items():
        gait = name.split(",")[0]
        stable[gait] = stable.get(gait, True) and all(run["share_below"] == 0 for run in runs)
    below = [f"{name}: {max(run['share_below'] for run in runs):.0%}" for name, runs in drawn.items()]
    page = r.get("browser", {}).get("random_control")
    if page:
        # The page's own runs (fitted, feet locked), measured as the issue measured them: none may have a second below the line.
        stable["walk"] = stable["walk"] and min(run["lowest_second"] for run in page["runs"]) >= erd_measures.FREEZE_FRACTION
    in_page = (f" (page: {sum(run['lowest_second'] < erd_measures.FREEZE_FRACTION for run in page['runs'])} of {len(page['runs'])}, "
               f"lowest {min(run['lowest_second'] for run in page['runs']):.2f})" if page else "")
    rows.append((f"stable for {lr['runs'][0]['frames']:,} frames of chained windows (no second below 20% of the real median pose change)",
                 f"random control: {sum(run['share_below'] > 0 for run in lr['runs'])} of {len(lr['runs'])} runs have one" + in_page
                 + (f"; drawn, most seconds below: {'; '.join(below)}" if below else ""),
                 _by_gait(stable), all(stable.values())))
    pred = r["prediction"]["rows"]
    mine = [pred[FOUR_FRAMES]["relative_cm"][h] for h in LATER_FRAMES]
    erds = {name: [pred[name]["relative_cm"][h] for h in LATER_FRAMES] for name in ("latent ERD", "pose-space ERD") if name in pred}
    ok = all(a < b for other in erds.values() for a, b in zip(mine, other))
    rows.append((f"beats both ERDs at {LATER_FRAMES[0]} frames and beyond (relative to the root)",
                 f"{' / '.join(map(str, mine))} cm at {' / '.join(map(str, LATER_FRAMES))} frames against "
                 + " and ".join(f"the {name}'s {' / '.join(map(str, v))}" for name, v in erds.items()),
                 "yes" if ok else "no", ok))
    return rows


def targets_lines(r: dict) -> list[str]:
    return (["## Against the targets", "", "| target | measured | met |", "|---|---|---|"]
            + [f"| {target} | {measured} | {met} |" for target, measured, met, _ in target_rows(r)]
            + ["", "What lies behind each row, and how the targets were reached: [the notes at the end](#notes-on-the-targets)."])


def summary_lines(r: dict) -> list[str]:
    """The five lines the report opens with: what the model does, how the page uses it, the headline numbers
    against real held-out clips, and what is not met (from the targets table's rows)."""
    pred, held, real = r["prediction"], r["sliding_held_out_control"], r["sliding_real"]
    at = LATER_FRAMES[0]
    others = [name for name in ("latent ERD", "pose-space ERD") if name in pred["rows"]]
    unmet = [f"{target} ({met})" for target, _, met, full in target_rows(r) if not full]
    return [
        "- **What it does:** draws walking and running for a whole control signal (a drawn path) in one pass: a "
        "recurrent VAE conditioned on the control signal, sampled from its prior.",
        "- **In the page:** Path mode's VAE-LSTM model: the walk for the whole drawn path appears as soon as it is drawn, "
        "**Vary** draws another prior sample, and **compare** has a second model walk the same path beside it.",
        f"- **Against {pred['windows']} held-out windows of real clips:** joint error relative to the root after {at} frames "
        f"{pred['rows'][FOUR_FRAMES]['relative_cm'][at]} cm from 4 initial frames, against "
        + " and ".join(f"the {name}'s {pred['rows'][name]['relative_cm'][at]}" for name in others) + ".",
        f"- **Foot sliding after the lock (held-out clips' control):** lowest point {held['low_foot_after']} m/s against real "
        f"{real['low_foot']}; contact bits {held['contact_bits_after']} against {real['contact_bits']}.",
        "- **Not met:** " + ("; ".join(unmet) if unmet else "nothing") + ".",
    ]


def vae_lstm_markdown(r: dict, notes: dict) -> str:
    """docs/models/vae-lstm.md from the numbers in vae-lstm.json and the prose in vae-lstm-notes.json; nothing here
    measures."""
    pred = r["prediction"]
    lines = ["# VAE-LSTM (Habibie et al.): motion for a whole control signal in one pass", ""]
    lines += summary_lines(r) + ["", f"![prior samples beside the real window]({VARIATIONS_PNG})", ""]
    lines += notes.get("made_by", []) + [""] + targets_lines(r)
    lines += ["", "## Prediction from held-out clips (the paper's Tables 1 and 2)", "",
              f"{pred['windows']} windows of the held-out clips ({', '.join(pred['clips'])}), the latent ERD report's windows: 16 seed frames, "
              "then the error at predicted frames 70 to 210 (30 fps, so frame 210 is 7 s on). Every model is given the clip's own "
              "control signal except the generator, which has no control input and free-runs from the same 16 frames. The VAE-LSTM's "
              "root moves by that control (as the page moves it by the drawn path's); the ERDs move by their decoded control. "
              "Rows other than the VAE-LSTM's are the latent ERD report's (docs/models/latent-erd.json), measured on the same windows.", "",
              "Table 1 form: mean joint position error in the world (cm).", ""]
    lines += prediction_table(pred, "with_root_cm")
    lines += ["", "Table 2 form: mean joint position error relative to the root (hips), ignoring translation (cm).", ""]
    lines += prediction_table(pred, "relative_cm")
    lines += [""] + notes.get("prediction", [])
    lr = r["long_runs"]
    lines += ["", "## Long runs: 3,000 frames of chained chunks", "",
              f"Random control (`random_control`, new target speed 0.4–2.0 m/s and turn ±1.2 rad/s every 2 s), one prior sample "
              f"per seed, the cell run chunk after chunk ({r['chunk_frames']} frames each, the state carried). The freeze line is 20% of "
              f"the real clips' median pose change ({lr['real_median_pose_change']} m/s); real clips spend {lr['real_share_below'] * 100:.1f}% of their seconds below it. "
              f"Seams: mean joint displacement relative to the hips between consecutive frames across a chunk boundary and elsewhere "
              f"(real held-out clips: {lr['real_frame_change_cm']} cm per frame).", "",
              _row(["seed", "frames", "finite", "lowest second / real median", "median second / real median", "seconds below 20%",
                    "across a chunk boundary (cm)", "elsewhere (cm)", "× real time (native, 1 thread)"]), _row(["---"] * 9)]
    for run in lr["runs"]:
        s = run["seams"]
        lines.append(_row([run["seed"], run["frames"], run["finite"], run["lowest_second"], run["median_second"], f"{run['share_below'] * 100:.1f}%",
                           s["boundary_cm"], s["elsewhere_cm"], run["x_real_time_native"]]))
    if "drawn_long_runs" in r:
        dl = r["drawn_long_runs"]
        real = dl["real_toe_swing"]
        lines += ["", "Drawn paths held for 3,000 frames: a constant control, read with the stride's sway added as the page reads a "
                  f"drawn path (vae-lstm.json `stride`, training/vae_lstm/stride.py), one prior sample per seed. Toe swing: each second's range of the toes' forward offset from the hips (m), the two toes "
                  f"averaged; real held-out clips {real['median_m']} m (median over {real['seconds']} seconds at {real['least_speed']} m/s or faster).", "",
                  _row(["drawn path", "seed", "toe swing, first 2 s (m)", "toe swing, last 10 s (m)", "lowest second / real median",
                        "median second / real median", "seconds below 20%"]), _row(["---"] * 7)]
        for name, runs in dl["runs"].items():
            for run in runs:
                lines.append(_row([name, run["seed"], run["first_2s_swing_m"], run["last_10s_swing_m"], run["lowest_second"],
                                   run["median_second"], f"{run['share_below'] * 100:.1f}%"]))
    d = r["diversity"]
    lines += ["", "## Variations from the prior", "",
              f"For the control signal of each 4 s held-out window, {d['samples']} prior samples: mean pairwise joint distance relative to "
              f"the hips (each in its own facing frame), beside the same between real windows (held-out and training clips) whose mean "
              f"forward speed is within {m.SIMILAR_SPEED} m/s and mean turn within {m.SIMILAR_TURN} rad/s of it.", "",
              "The model reads each clip's control smoothed as in training (10 frames); what is left of the stride's sway in it "
              "still sets the phase of the steps, so the feet of prior samples for a clip's control keep the clip's stride. A drawn "
              "path's control has no sway; the page adds the stride's sway from a phase each seed draws (the second table: constant "
              "controls read so).", "",
              f"Mean over windows: prior samples {d['prior_samples_cm']} cm (toes alone {d.get('prior_toes_cm')} cm); real windows with "
              f"similar control {d['real_similar_cm']} cm (toes {d.get('real_similar_toes_cm')} cm).", "",
              _row(["clip", "start", "forward (m/s)", "turn (rad/s)", "prior samples (cm)", "toes (cm)", "real, similar control (cm)", "toes (cm)", "similar real windows"]),
              _row(["---"] * 9)]
    for w in d["windows"]:
        lines.append(_row([w["clip"], w["start"], w["forward"], w["turn"], w["prior_samples_cm"], w.get("prior_toes_cm"), w["real_similar_cm"],
                           w.get("real_similar_toes_cm"), w["real_similar_windows"]]))
    lines += ["", f"Drawn-path controls (constant; {d['samples']} prior samples each):", "",
              _row(["forward (m/s)", "turn (rad/s)", "all joints (cm)", "all joints, last 2 s (cm)", "toes (cm)", "toes, last 2 s (cm)"]), _row(["---"] * 6)]
    for w in d.get("drawn_paths", []):
        lines.append(_row([w["forward"], w["turn"], w["joints_cm"], w["joints_last_2s_cm"], w["toes_cm"], w["toes_last_2s_cm"]]))
    lines += ["", "The figure at the top: prior samples beside the real window.", ""] + notes.get("diversity", [])
    lines += ["", "### Ways of drawing a prior sample", "",
              "The same measures for each way of drawing a prior sample (generation.py): one z1 and the cell on its own state "
              "(Algorithm 1; for a model trained with z1 in every step's content, `mix`, also that share of each step), or a latent "
              "per step in teacher mode (the paper's other way), independent (rho 0) or correlated "
              f"from step to step (AR(1), rho 0.9). The page uses `{json.dumps(r['sampling'])}` (vae-lstm.json). Jitter: RMS second "
              f"difference of the joints relative to the hips, real held-out clips {r['jitter_real_cm']} cm per frame².", "",
              _row(["prior sample", "diversity (cm)", "toes, drawn paths (cm)", "long runs: lowest second / median", "mean median second / median", "seconds below 20%",
                    "energy, held-out control", "jitter (cm/frame²)", "sliding after lock: contact bits / lowest point (m/s)"]), _row(["---"] * 9)]
    for name, x in r["samplings"].items():
        sl = x["sliding_held_out_control"]
        lines.append(_row([name, x["diversity_cm"], x.get("drawn_path_toes_cm"), x["lowest_second"], x["median_second"], f"{x['share_below'] * 100:.1f}%", x["energy_held_out"],
                           x["jitter_cm"], f"{sl['contact_bits_after']} / {sl['low_foot_after']}"]))
    e = r["energy"]
    lines += ["", "## Foot sliding", "",
              "Two measures, each clip or run on its own: the toe's horizontal speed while its contact bit is on (contact-bit measure) and "
              "the horizontal speed of each foot's lowest point while within 4 cm of the floor (no contact bits needed). After the lock: "
              "contacts labelled on the motion from the decoded channels, then the foot lock (`training/footlock.py` = `web/motion/footLock.ts`), "
              "as the page shows it. The root comes straight from the control signal, not from the body.", "",
              _row(["motion", "contact-bit measure before / after lock (m/s)", "lowest-point measure before / after lock (m/s)"]), _row(["---"] * 3),
              _row(["real held-out clips", r["sliding_real"]["contact_bits"], r["sliding_real"]["low_foot"]])]
    for key, name in (("sliding_held_out_control", "VAE-LSTM, held-out clips' control, prior samples"),
                      ("sliding_random_control", "VAE-LSTM, random control (the long runs)")):
        s = r[key]
        lines.append(_row([name, f"{s['contact_bits_before']} / {s['contact_bits_after']}", f"{s['low_foot_before']} / {s['low_foot_after']}"]))
    lines += ["", f"Motion energy (mean pose change per second against the real median): real held-out clips {e['real']}, the VAE-LSTM driven by their control {e['held_out_control']}."]
    if "browser" in r:
        b = r["browser"]
        lines += ["", "## The benchmark paths in the page", "",
                  f"`npm run evaluate:vae-lstm` ({b.get('date', '?')}, headless Chromium, {b.get('seeds', '?')} seeds per case, cross-origin isolated: "
                  f"{b.get('isolated', '?')}, load average {b.get('load_before', '?')} before). `tests/fixtures/benchmark_paths.json`, each model through "
                  "`playground.followPath` as the page runs it; × real time is the motion's seconds over the seconds it took to compute; followed "
                  "within 0.15 m is the share of the path's length the root passed that near, in the path's order (`web/motion/pathCoverage.ts`)"
                  + "".join(f"; the {model}'s rows are from {date}" for model, date in (b.get("kept") or {}).items())
                  + (f"; timed at a load average of {b['load_before']} on {b['cores']} cores, so × real time is not the model's speed alone"
                     if b.get("cores") and b.get("load_before", 0) > b["cores"] else "") + ".", ""]
        lines += browser_table(b)
        if b.get("random_control"):
            rc = b["random_control"]
            lows = [run["lowest_second"] for run in rc["runs"]]
            lines += ["", f"`generate` with its random control in the page ({rc['frames']:,} frames, seeds 0–{len(rc['runs']) - 1}; the motion as returned, "
                      f"fitted and its feet locked; `web/motion/poseChange.ts` per whole second against the real median {rc['real_median']} m/s): "
                      f"lowest second {_span(lows, 2)} of the real median (least at seed {rc['runs'][int(np.argmin(lows))]['seed']}), median seconds "
                      f"{_span([run['median_second'] for run in rc['runs']], 2)}."]
    lines += ["", "## Model and training", ""] + notes.get("model", [])
    lines += ["", _row(["file", "bytes"]), _row(["---", "---"])] + [_row([f, n]) for f, n in r["sizes_bytes"].items()]
    stored = f", large weights stored as {r['weights']}" if r.get("weights") else ""
    lines += [f"", f"In all {sum(r['sizes_bytes'].values()) / 1e6:.2f} MB{stored}."]
    if r.get("training"):
        lines += ["", _row(["run", "minutes", "iterations", "best held-out error from 4 frames (cm)", "parameters"]), _row(["---"] * 5)]
        for name, t in r["training"].items():
            lines.append(_row([name, round(t["minutes"], 1), t["iterations"], round(t["best_valid_cm"], 2), t["parameters"]]))
    lines += ["", "## Pilots", ""] + notes.get("pilots", [])
    lines += ["", "## Where it falls short", ""] + notes.get("short", [])
    lines += ["", "## Notes on the targets", ""] + [f"- {note}" for note in notes.get("targets", [])]
    return "\n".join(lines) + "\n"


def read_report(path: Path = REPORT_JSON) -> tuple[dict, dict]:
    """vae-lstm.json as the writer had it (JSON keeps the prediction horizons as strings), and the notes."""
    report = json.loads(path.read_text())
    for row in report["prediction"]["rows"].values():
        for kind in ("with_root_cm", "relative_cm"):
            row[kind] = {int(k): v for k, v in row[kind].items()}
    notes = json.loads(NOTES_JSON.read_text()) if NOTES_JSON.exists() else {}
    return report, notes


def rewrite_vae_lstm_markdown() -> None:
    """vae-lstm.md again from the committed vae-lstm.json and notes, without measuring."""
    REPORT_MD.write_text(vae_lstm_markdown(*read_report()))


VARIATIONS_PNG = "vae-lstm-variations.png"
VARIATION_JOINTS = ("RightHand", "RightToeBase")


def variations_figure(models_dir: Path, mocap: str | None, path: Path, samples: int = 4) -> None:
    """Prior samples for one held-out window's control beside the real window (top), and for a drawn straight path at
    1.2 m/s, the page's walk (bottom): the right hand's and right toe's height and forward offset from the hips
    (facing frame) over the 4 s, so the variations are seen, not only counted."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from ..data.windows import JOINTS

    corpus = WindowCorpus(load_clips(mocap))
    vae = m.ShippedVae.load(models_dir)
    window = vae.info["window"]
    clip = corpus.valid_clips[0]
    real = clip.rows[:window]
    cases = ((f"the control of {Path(clip.file).name}, first 4 s", vae.clip_control(clip.rows)[:window], real),
             ("a drawn straight path at 1.2 m/s", m.drawn_control(1.2, 0.0, window), None))
    t = np.arange(window) / vae.fps
    fig, axes = plt.subplots(len(cases), 2 * len(VARIATION_JOINTS), figsize=(16, 3.2 * len(cases)))
    for row, (title, control, real_rows) in enumerate(cases):
        # A drawn path is read with the stride's sway added, as the page reads it; a clip's own control has its own.
        read = (lambda k: control) if real_rows is not None else (lambda k: vae.read_control(control, 1000 + k))
        motions = [m.local_positions(vae.rows(read(k), *vae.prior(1000 + k, window))) for k in range(samples)]
        for col, (name, axis, label) in enumerate((n, a, lab) for n in VARIATION_JOINTS for a, lab in ((1, "height"), (2, "forward"))):
            j = JOINTS.index(name)
            ax = axes[row, col]
            for k, mo in enumerate(motions):
                ax.plot(t, mo[:, j, axis], lw=1, color=f"C{k}", label=f"prior sample {k + 1}")
            if real_rows is not None:
                ax.plot(t, m.local_positions(real_rows)[:, j, axis], lw=2, color="k", ls="--", label="real window")
            ax.set(title=f"{name}: {label} from the hips (m)", xlabel="s")
        axes[row, 0].legend(fontsize=7)
        axes[row, 0].annotate(title, (0, 1.18), xycoords="axes fraction", fontsize=9, weight="bold")
    fig.suptitle("VAE-LSTM prior samples (the shipped sampling, seeds 1000-1003)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def write_report(mocap: str | None, models_dir: Path = MODELS_DIR, out_dir: Path = REPORTS_DIR) -> dict:
    """Measures the export in `models_dir` and writes vae-lstm.{md,json} into `out_dir` (the training rows kept from
    the JSON already there, else from docs/models/vae-lstm.json)."""
    previous_path = out_dir / REPORT_JSON.name if (out_dir / REPORT_JSON.name).exists() else REPORT_JSON
    previous = json.loads(previous_path.read_text()) if previous_path.exists() else {}
    report = evaluate(mocap, previous, models_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / REPORT_JSON.name).write_text(json.dumps(report, indent=1) + "\n")
    variations_figure(models_dir, mocap, out_dir / VARIATIONS_PNG)
    # Written from the JSON just stored (its rows carried from the latent ERD report have their horizons as strings).
    (out_dir / REPORT_MD.name).write_text(vae_lstm_markdown(*read_report(out_dir / REPORT_JSON.name)))
    return report
