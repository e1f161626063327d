"""Quick measure of a dance-model training run (issue 18's pilots): self-fed rollouts of its checkpoint in torch,
judged by the fairer freeze rule (freeze_rule.py) against each style's real clips, with its validation losses.

Rollouts start from the export's seed motions (exporting.pick_seeds: 10 real frames of held-out clips) and run
`frames` steps per seed for each style; a rollout that leaves the believable range (NaN, a root outside
0.2-1.6 m, or a second whose limb-length error exceeds 25%) counts as diverged, as in the report.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import torch

from .. import metrics
from ..data.dance import LIMB_MIN_LENGTH, MODEL_FPS, STYLES, bone_length_error, decode, load_clips
from ..models.aclstm import draw
from ..data.dance import encode, resample_positions
from .exporting import SEED_FRAMES, load_dance_model, pick_seeds
from .freeze_rule import MEDIAN_FRACTION, jitter_cm, judge, real_jitter_cm, real_reference
from .jitter_filter import lowpass_rows
from .phrase_sampling import PhraseParams, phrase_rollout
from .raised_foot import raised_foot_limit, raised_foot_share, real_raised_foot
from .report import BONE_ERROR_LIMIT, HEIGHT_BAND, per_second


def rollout(model, meta: dict, seed_frames: np.ndarray, styles: list[str], frames: int, feedback_noise: float = 0.0,
            temperature: float = 1.0, draw_rho: float = 0.0) -> np.ndarray:
    """Warm up on the seeds (batch, seed, dim; physical units), then feed outputs back (plus white noise of
    `feedback_noise`, normalised units, seeded): (batch, frames, dim). A Gaussian head's outputs are draws
    (seeded, σ scaled by `temperature`), fed back and returned; with `draw_rho` their normals are AR(1) over the
    frames (each still N(0, 1)), so the draws wander smoothly instead of shaking."""
    mean, std = np.array(meta["mean"], np.float32), np.array(meta["std"], np.float32)
    style = torch.eye(len(meta["styles"]))[[meta["styles"].index(s) for s in styles]]
    x = torch.from_numpy(((seed_frames - mean) / std).astype(np.float32))
    out = np.zeros((len(x), frames, x.shape[-1]), np.float32)
    with torch.no_grad():
        noise = torch.Generator().manual_seed(0)
        draws = torch.Generator().manual_seed(1)
        y, state = model(x, style, sample=True, generator=draws, temperature=temperature)
        y = y[:, -1:]
        wander = torch.randn(y.shape, generator=draws)
        for t in range(frames):
            out[:, t] = y[:, 0].numpy()
            fed = y + feedback_noise * torch.randn(y.shape, generator=noise) if feedback_noise else y
            if draw_rho and model.head == "gauss":
                wander = draw_rho * wander + np.sqrt(1 - draw_rho ** 2) * torch.randn(y.shape, generator=draws)
                mu, log_sigma, state = model.distribution(fed, style, state)
                y = draw(mu, log_sigma, temperature, wander)
            else:
                y, state = model(fed, style, state, sample=True, generator=draws, temperature=temperature)
    return out * std + mean


def judge_rollout(f: np.ndarray, style: str, skel, ref: dict, real_jitter: dict, real_raised: dict | None = None) -> dict:
    """One rollout's features (frames, dim; physical units): divergence (NaN, a root outside HEIGHT_BAND, a second
    over the limb-length limit), jitter against the style's real clips and the freeze rule's verdicts; with
    `real_raised` (raised_foot.real_raised_foot) its raised-foot share beside the real one."""
    finite = bool(np.isfinite(f).all())
    pos = decode(np.nan_to_num(f.astype(np.float64)))
    curve = metrics.pose_change_per_second(pos, MODEL_FPS)
    limb = per_second(bone_length_error(pos, skel, LIMB_MIN_LENGTH), MODEL_FPS)
    height = pos[:, 0, 1]
    diverged = (not finite or float(limb.max()) > BONE_ERROR_LIMIT
                or not (HEIGHT_BAND[0] <= height.min() and height.max() <= HEIGHT_BAND[1]))
    raised = ({"raised_foot_share": raised_foot_share(pos, skel.names), "raised_foot_real": real_raised[style]}
              if real_raised is not None else {})
    return {"style": style, "diverged": diverged, "limb_worst_second": float(limb.max()),
            "jitter_vs_real": jitter_cm(pos) / real_jitter[style], **raised, **judge(curve, ref[style])}


def measure_run(checkpoint: Path, frames: int = 3000, seeds_per_style: int = 3, mocap: str | None = None,
                feedback_noise: float = 0.0, temperature: float = 1.0, draw_rho: float = 0.0,
                phrase: dict[str, PhraseParams] | None = None) -> dict:
    """The pilot measure of one checkpoint (a Gaussian head's draws with σ × `temperature`; an mdn head's by the
    phrase sampler with `phrase`'s parameters per style, default PhraseParams()): per style and seed the
    freeze-rule numbers; validation from the run."""
    skel, clips = load_clips(mocap)
    model, meta, state = load_dance_model(checkpoint)
    ref = real_reference(clips)
    real_jitter = real_jitter_cm(clips)
    chosen = [s for style in STYLES for s in [x for x in pick_seeds(clips) if x["style"] == style][:seeds_per_style]]
    seed_frames, seed_styles = np.array([s["frames"] for s in chosen], np.float32), [s["style"] for s in chosen]
    redraws = None
    if model.head == "mdn":
        phrase = phrase or {}
        feats, redraws = phrase_rollout(model, meta, seed_frames, seed_styles, frames,
                                        [phrase.get(s, PhraseParams()) for s in seed_styles])
    else:
        feats = rollout(model, meta, seed_frames, seed_styles, frames, feedback_noise, temperature, draw_rho)
    runs = []
    for k, (seed, f) in enumerate(zip(chosen, feats)):
        runs.append({"seed": seed["name"], **judge_rollout(f, seed["style"], skel, ref, real_jitter),
                     **({"phrases_per_minute": float(redraws[k]) / (frames / MODEL_FPS / 60)} if redraws is not None else {})})
    per_style = {}
    for style in STYLES:
        mine = [r for r in runs if r["style"] == style]
        per_style[style] = {"passes": sum(r["passes"] and not r["diverged"] for r in mine), "runs": len(mine),
                            "low_share_worst": max(r["low_share"] for r in mine),
                            "longest_low_s_worst": max(r["longest_low_s"] for r in mine),
                            "median_ratio_worst": min(r["median_ratio"] for r in mine),
                            "jitter_vs_real": [min(r["jitter_vs_real"] for r in mine), max(r["jitter_vs_real"] for r in mine)],
                            "diverged": sum(r["diverged"] for r in mine)}
    valid = state.get("valid") or (state.get("history") or [{}])[-1].get("valid") or {}  # best.pt, else the last epoch
    return {"checkpoint": str(checkpoint), "iteration": state.get("iteration"), "frames": frames, "args": meta.get("args", {}),
            "rollout_feedback_noise": feedback_noise, "rollout_temperature": temperature, "rollout_draw_rho": draw_rho,
            **({"phrase": {s: (phrase or {}).get(s, PhraseParams()).to_json() for s in STYLES}} if model.head == "mdn" else {}),
            "valid": {s: valid.get(s) for s in STYLES} if valid else None, "real": ref, "per_style": per_style,
            "passes": sum(p["passes"] for p in per_style.values()), "runs": len(runs), "details": runs}


TUNING_FRACTIONS = (0.55, 0.7, 0.85)  # of each held-out clip: seed windows apart from pick_seeds' (at most 0.34 of a clip)


def tuning_grid(threshold: float = 0.05, rhos: tuple[float, ...] = (0.0, 0.9),
                thresholds: tuple[float, ...] | None = None,
                temperatures: tuple[float, ...] = (0.2, 0.35, 0.5, 0.7)) -> list[PhraseParams]:
    """The phrase sampler's settings tried per style: temperature (the export's: EXPORT_TEMPERATURES), longest hold
    (0.5, 1, 2 s), AR(1) coefficient (the pilot's grid: white and 0.9; the export's: EXPORT_RHOS) and the weight below
    which a held component is redrawn (`threshold`, or each of `thresholds`; the export's: EXPORT_THRESHOLDS)."""
    return [PhraseParams(t, h, r, th) for th in (thresholds or (threshold,))
            for t in temperatures for h in (15, 30, 60) for r in rhos]


# The export's AR(1) coefficients: white noise never came near the jitter budget in the pilot (3-16x, row 7c), and on
# the pilot's tuning windows through the output filter rho 0.95-0.98 brought martial's jitter from 1.54x to 1.42x.
EXPORT_RHOS = (0.9, 0.95, 0.98)
# The export's redraw thresholds: components drawn with a weight under 0.3 are the ones that lift a foot (salsa's
# tuning windows: 64-78% of frames with a raised foot at 0.05, 2-14% at 0.3; the real clips 0.2%).
EXPORT_THRESHOLDS = (0.05, 0.3)
# The export's temperatures. 1.0 was tried beside them for Indian, which takes the highest (0.7) with the 99% cutoff
# and 1.8x real jitter: at 1.0 it took a 97% cutoff and came to 1.30-1.34x, but its limbs were 29-46% off in the worst
# second of every 20,000-frame run (2026-12-05, docs/models/aclstm.md), so it is not in the grid.
EXPORT_TEMPERATURES = (0.2, 0.35, 0.5, 0.7)


def tuning_seeds(clips, style: str, per_style: int = 3) -> np.ndarray:
    """Seed motions for choosing the phrase sampler's parameters: SEED_FRAMES real frames of the style's held-out
    clips, at TUNING_FRACTIONS of each clip, never the windows the judged runs start from (pick_seeds)."""
    held = [c for c in clips if c.style == style and c.held_out]
    out = []
    for k in range(per_style):
        c = held[k % len(held)]
        start = TUNING_FRACTIONS[k % len(TUNING_FRACTIONS)] * c.seconds
        pos = resample_positions(c.positions, c.fps, start, SEED_FRAMES + 1)
        pos[..., [0, 2]] -= pos[-1:, :1, [0, 2]]
        out.append(encode(pos))
    return np.array(out, np.float32)


# The worst second's limb error a tuning run may have, as a share of the report's limit (BONE_ERROR_LIMIT): a
# 20,000-frame run has 6.7 times as many seconds as a 3,000-frame tuning run, so its worst one is worse. Measured on
# 2026-12-05: settings whose tuning runs all kept every second within the limit failed it in 6 of 15 judged runs
# (worst seconds 25.1-27.8%).
LIMB_MARGIN = 0.85
# The median pose change a tuning run must keep, as a multiple of rule (c)'s floor: the page shows the frames fitted
# to the skeleton at exact bone lengths, which takes out the bone-length flicker the raw points count as motion.
# Measured on 2026-12-05: Indian runs at 53-55% of the real median in Python were 47-49% through the page (0.9x).
MEDIAN_MARGIN = 1.12


def tuning_score(runs: list[dict], jitter_limit: float = 1.3) -> tuple:
    """Lower is better: settings whose tuning rollouts all pass (a)–(c) without divergence, keep their median
    MEDIAN_MARGIN above (c)'s floor and their worst second's limb error within LIMB_MARGIN of the limit (where
    measured), have jitter within `jitter_limit` × real and (where measured) raise a foot no more often than
    raised_foot_limit allows come first, closest median to the real one among them; then the fewest failures."""
    median = float(np.median([r["median_ratio"] for r in runs]))
    jitter = max(r["jitter_vs_real"] for r in runs)
    fails = sum(r["diverged"] or not r["passes"] for r in runs)
    raised_excess = max((max(0.0, r["raised_foot_share"] - raised_foot_limit(r["raised_foot_real"]))
                         for r in runs if "raised_foot_share" in r), default=0.0)
    limb_excess = max((max(0.0, r["limb_worst_second"] - LIMB_MARGIN * BONE_ERROR_LIMIT)
                       for r in runs if "limb_worst_second" in r), default=0.0)
    median_short = max(0.0, MEDIAN_MARGIN * MEDIAN_FRACTION - min(r["median_ratio"] for r in runs))
    feasible = fails == 0 and jitter <= jitter_limit and raised_excess == 0 and limb_excess == 0 and median_short == 0
    penalty = (10 * sum(r["diverged"] for r in runs) + fails + max(0.0, jitter - jitter_limit) + 10 * raised_excess
               + 10 * limb_excess + 10 * median_short)
    return (0 if feasible else 1, 0.0 if feasible else penalty, abs(np.log(max(median, 1e-6))))


def tune_phrase(checkpoint: Path, grid: list[PhraseParams], frames: int = 1200, per_style: int = 3,
                mocap: str | None = None, filters: dict[str, tuple[np.ndarray, np.ndarray]] | None = None) -> dict:
    """Every setting of `grid` rolled out `frames` frames from each style's tuning seeds (held-out clips, not the
    judged windows), in one batch; per style the settings ranked by tuning_score and the best one. With `filters`
    (per style the output filter's b, a: training/aclstm/jitter_filter.py) each rollout is judged as shown, through
    its style's filter (started at rest on the seed's last frame); the raw jitter is kept beside it."""
    return tune_phrase_filtered(checkpoint, grid, [filters], frames, per_style, mocap)[0]


def tune_phrase_filtered(checkpoint: Path, grid: list[PhraseParams], filter_sets: list[dict | None], frames: int = 1200,
                         per_style: int = 3, mocap: str | None = None, styles: tuple[str, ...] = STYLES) -> list[dict]:
    """tune_phrase once per entry of `filter_sets` (None: unfiltered), on one set of rollouts: the filter is applied
    after the rollout and never fed back, so the rollouts are the same whatever it is. `styles`: the styles rolled out."""
    skel, clips = load_clips(mocap)
    model, meta, _ = load_dance_model(checkpoint)
    ref, real_jitter, real_raised = real_reference(clips), real_jitter_cm(clips), real_raised_foot(clips, skel.names)
    rows = [(style, p, seed) for style in styles for p in grid for seed in tuning_seeds(clips, style, per_style)]
    drawn, _ = phrase_rollout(model, meta, np.array([r[2] for r in rows]), [r[0] for r in rows], frames, [r[1] for r in rows])
    raw_jitter = [jitter_cm(decode(f.astype(np.float64))) / real_jitter[st] for (st, _, _), f in zip(rows, drawn)]
    results = []
    for filters in filter_sets:
        feats = drawn
        if filters:
            feats = lowpass_rows(drawn, np.array([filters[st][0] for st, _, _ in rows]), np.array([filters[st][1] for st, _, _ in rows]),
                                 np.array([seed[-1] for _, _, seed in rows]))
        out = {}
        for style in styles:
            table = []
            for p in grid:
                mine = [k for k, (st, q, _) in enumerate(rows) if st == style and q == p]
                runs = [judge_rollout(feats[k], style, skel, ref, real_jitter, real_raised) for k in mine]
                table.append({"params": p.to_json(), "score": list(tuning_score(runs)),
                              "passes": sum(r["passes"] and not r["diverged"] for r in runs), "runs": len(runs),
                              "diverged": sum(r["diverged"] for r in runs),
                              "median_ratio": float(np.median([r["median_ratio"] for r in runs])),
                              "jitter_vs_real": max(r["jitter_vs_real"] for r in runs),
                              "jitter_raw_vs_real": max(raw_jitter[k] for k in mine),
                              "raised_foot_share": max(r["raised_foot_share"] for r in runs),
                              "limb_worst_second": max(r["limb_worst_second"] for r in runs),
                              "raised_foot_real": real_raised[style]})
            table.sort(key=lambda t: tuple(t["score"]))
            out[style] = {"best": table[0]["params"], "table": table}
        results.append({"frames": frames, "seeds_per_style": per_style, "fractions": TUNING_FRACTIONS,
                        "filtered": bool(filters), "styles": out})
    return results


SWEEP_HOLDS, SWEEP_RHOS, SWEEP_SHARES = (15, 30), (0.9, 0.95), (0.99, 0.97)


def temperature_sweep(checkpoint: Path, style: str, temperatures: tuple[float, ...], frames: int = 3000,
                      mocap: str | None = None) -> dict:
    """One style's phrase settings at `temperatures` (also above the export's grid), each with holds SWEEP_HOLDS and
    AR(1) coefficients SWEEP_RHOS, judged on the style's tuning runs through its filter at each of SWEEP_SHARES (the
    export's judge, tune_phrase_filtered): per power share, the rows of every setting in grid order."""
    from .jitter_filter import coefficients, style_filters

    clips = load_clips(mocap)[1]
    grid = [PhraseParams(t, h, r, 0.05) for t in temperatures for h in SWEEP_HOLDS for r in SWEEP_RHOS]
    filters = [{style: coefficients(style_filters(clips, (style,), share)[style])} for share in SWEEP_SHARES]
    tuned = tune_phrase_filtered(checkpoint, grid, filters, frames, mocap=mocap, styles=(style,))
    in_grid_order = lambda table: sorted(table, key=lambda r: grid.index(PhraseParams(**r["params"])))  # not by score
    return {"style": style, "frames": frames, "power_shares": list(SWEEP_SHARES),
            "rows": {f"{share:g}": in_grid_order(t["styles"][style]["table"]) for share, t in zip(SWEEP_SHARES, tuned)}}


def tuning_row_text(row: dict) -> str:
    """One row of a tuning table (tune_phrase_filtered) in words, as the export and the sweep print it."""
    return (f"{row['passes']}/{row['runs']} pass, median {row['median_ratio']:.0%}, jitter {row['jitter_vs_real']:.2f}x filtered, "
            f"{row['jitter_raw_vs_real']:.2f}x raw, a foot raised in up to {row['raised_foot_share']:.0%} of frames, "
            f"real {row['raised_foot_real']:.0%}, limbs {row['limb_worst_second']:.1%} off in the worst second")


def summary_line(name: str, m: dict) -> str:
    cells = []
    for style in STYLES:
        p = m["per_style"][style]
        cells.append(f"{style} {p['passes']}/{p['runs']} low {p['low_share_worst']:.0%} "
                     f"longest {p['longest_low_s_worst']} s median {p['median_ratio_worst']:.0%}"
                     + (f" diverged {p['diverged']}" if p["diverged"] else ""))
    ac = "/".join(f"{m['valid'][s]['auto_conditioned']:.3f}" for s in STYLES) if m["valid"] else "-"
    return f"{name} (it {m['iteration']}): {m['passes']}/{m['runs']} pass; " + "; ".join(cells) + f"; valid ac {ac}"


def recipe(args: dict) -> str:
    """A training run's recipe in a few words, from its arguments."""
    parts = [f"{args.get('layers', 3)}x{args.get('hidden', 256)}",
             f"u={args.get('ground_truth', 5)} v={args.get('condition', 5)}"
             + (f"->{args['condition_max']}" if args.get("condition_max") else ""),
             f"lr {args.get('lr', 1e-3):g} x{args.get('decay', 0.95):g}/epoch"]
    if args.get("head", "mean") == "mdn":
        parts.append(f"mdn head K={args.get('components', 10)}, held-component draws fed back"
                     + (f" at σ × {args['draw_temperature']:g}" if args.get("draw_temperature", 1.0) != 1.0 else ""))
    elif args.get("head", "mean") != "mean":
        parts.append(f"{args['head']} head, draws fed back")
    if args.get("feedback_noise"):
        parts.append(f"feedback noise {args['feedback_noise']:g}")
    if args.get("energy"):
        parts.append(f"energy {args['energy']:g}")
    noise = args.get("input_noise") or (0, 0)
    if any(noise):
        parts.append(f"input noise {noise[0]:g}->{noise[1]:g}")
    return ", ".join(parts)


def pilot_markdown(table: dict, sweeps: dict | None = None) -> str:
    """docs/models/aclstm-pilots.md: the real clips' reference, one row per measured run, then the feedback-noise sweeps."""
    if not table:
        return "# acLSTM pilots (issue 18)\n\nNo pilot measured yet.\n" + "\n".join(feedback_markdown(sweeps or {})) + "\n"
    first = next(iter(table.values()))
    lines = ["# acLSTM pilots (issue 18)", "",
             "Written by `python -m training.aclstm.pilot`. Each pilot is a short training run; its checkpoint rolls out "
             f"{first['frames']} self-fed frames in torch from 3 real seed motions per style (held-out clips), judged by the "
             "fairer freeze rule (`training/aclstm/freeze_rule.py`): a *low* second is below 20% of the style's real median "
             "pose change; a run passes when (a) its share of low seconds is at most twice the real clips' share, (b) no low "
             "stretch lasts 5 s or more, and (c) its median is at least 50% of the real median. Each style's cell gives the "
             "passes and, over its seeds, the worst low share, the longest low stretch and the lowest median (share of real). "
             "Rows marked *+noise σ* are rolled out with white noise σ (normalised units) on each fed-back frame; rows "
             "marked *temperature τ* draw a Gaussian head's frames with its σ × τ; rows marked *phrase* draw an mdn head's frames "
             "by the phrase sampler (`training/aclstm/phrase_sampling.py`: a component held for up to *hold* frames or until its "
             "weight falls below 0.05, its σ × τ, AR(1) normals with coefficient ρ), *phrase tuned* with each style's setting "
             "chosen on held-out windows the judged runs do not start from (`aclstm-phrase-tuning.json`). *jitter* (where measured) is the mean "
             "second difference of the joints relative to the root against the real clips' (a shaking dancer also passes "
             "(a)–(c)).",
             "",
             "Real held-out clips, measured the same way (each clip alone): "
             + "; ".join(f"{s} median {r['median']:.3f} m/s, low share {r['low_share']:.1%}, longest low stretch "
                         f"{r['longest_low_s']} s, over {r['seconds']} s" for s, r in first["real"].items()) + ".", "",
             "| run | recipe | iterations | minutes | " + " | ".join(STYLES) + " | held-out loss, self-fed (" + "/".join(STYLES) + ") |",
             "|---|---|---|---|" + "---|" * len(STYLES) + "---|"]
    for name, m in table.items():
        cells = []
        for style in STYLES:
            p = m["per_style"][style]
            cells.append(f"{p['passes']}/{p['runs']}: {p['low_share_worst']:.0%} low, {p['longest_low_s_worst']} s, "
                         f"median {p['median_ratio_worst']:.0%}" + (f", {p['diverged']} diverged" if p["diverged"] else "")
                         + (f", jitter {p['jitter_vs_real'][0]:.1f}–{p['jitter_vs_real'][1]:.1f}×" if "jitter_vs_real" in p else "")
                         + (f"; phrase τ {m['phrase'][style]['temperature']:g}, hold ≤ {m['phrase'][style]['max_hold']} frames, "
                            f"ρ {m['phrase'][style]['rho']:g}" if m.get("phrase") else ""))
        valid = "/".join(f"{m['valid'][s]['auto_conditioned']:.3f}" for s in STYLES) if m.get("valid") else "—"
        minutes = m.get("summary", {}).get("minutes")
        lines.append(f"| {name} | {recipe(m.get('args', {}))} | {m['iteration']} | "
                     f"{'—' if minutes is None else f'{minutes:.0f}'} | " + " | ".join(cells) + f" | {valid} |")
    lines += feedback_markdown(sweeps or {})
    return "\n".join(lines) + "\n"


def feedback_noise_runs(models_dir: Path, model_id: str, frames: int, sigma: float, rho: float = 0.0,
                        pose_only: bool = False, seeds_per_style: int = 5, mocap: str | None = None) -> dict:
    """An inference-time lever on an exported model: Gaussian noise (normalised units; AR(1) with coefficient rho,
    so rho = 0 is white) added to each fed-back frame, on every channel or on the pose channels only (not the root's
    three). The output frames are the network's own predictions; only what it reads next is perturbed. Judged by
    the fairer freeze rule and the report's divergence rules, with the jitter against the real clips'."""
    from .shipped import ShippedDance

    skel, clips = load_clips(mocap)
    ref = real_reference(clips)
    real_jitter = real_jitter_cm(clips)
    model = ShippedDance(models_dir, model_id)
    chosen = [(style, seed) for style in STYLES for seed in model.seeds_of(style)[:seeds_per_style]]
    feats = model.generate(np.array([s["frames"] for _, s in chosen], np.float32), [style for style, _ in chosen], frames,
                           feedback_noise=sigma, rho=rho, pose_only=pose_only)
    runs = []
    for (style_name, s), f in zip(chosen, feats):
        finite = bool(np.isfinite(f).all())
        pos = decode(np.nan_to_num(f.astype(np.float64)))
        limb = per_second(bone_length_error(pos, skel, LIMB_MIN_LENGTH), MODEL_FPS)
        height = pos[:, 0, 1]
        diverged = (not finite or float(limb.max()) > BONE_ERROR_LIMIT
                    or not (HEIGHT_BAND[0] <= height.min() and height.max() <= HEIGHT_BAND[1]))
        runs.append({"style": style_name, "seed": s["name"], "diverged": diverged, "limb_error_worst_second": float(limb.max()),
                     "root_height": [float(height.min()), float(height.max())],
                     "jitter_vs_real": jitter_cm(pos) / real_jitter[style_name],
                     **judge(metrics.pose_change_per_second(pos, MODEL_FPS), ref[style_name])})
    return {"model": model_id, "frames": frames, "sigma": sigma, "rho": rho, "pose_only": pose_only, "real": ref,
            "real_jitter_cm": real_jitter, "runs": runs,
            "passes": sum(r["passes"] and not r["diverged"] for r in runs), "diverged": sum(r["diverged"] for r in runs)}


def feedback_markdown(sweeps: dict) -> list[str]:
    """The feedback-noise table of aclstm-pilots.md."""
    if not sweeps:
        return []
    lines = ["", "## Inference-time lever: noise on the fed-back frame (shipped model, no retraining)", "",
             "Each step the network reads its own last output plus Gaussian noise (normalised units; AR(1) with coefficient "
             "ρ, ρ = 0 white; on every channel, or the pose channels only), and the output frames are its predictions. "
             "Same seeds, rule and divergence checks as the report (limb-length error over 25% in a second, root outside "
             "0.2–1.6 m); jitter is the mean second difference of the joints relative to the root against the real clips'.", "",
             "| model | σ | ρ | channels | frames | pass (a)–(c), no divergence | diverged | " + " | ".join(f"{s}: passes, worst low share, lowest median, jitter × real" for s in STYLES) + " |",
             "|---|---|---|---|---|---|---|" + "---|" * len(STYLES)]
    for key, w in sweeps.items():
        cells = []
        for style in STYLES:
            rs = [r for r in w["runs"] if r["style"] == style]
            cells.append(f"{sum(r['passes'] and not r['diverged'] for r in rs)}/{len(rs)}, {max(r['low_share'] for r in rs):.0%}, "
                         f"{min(r['median_ratio'] for r in rs):.0%}, {min(r['jitter_vs_real'] for r in rs):.1f}–{max(r['jitter_vs_real'] for r in rs):.1f}")
        lines.append(f"| {w['model']} | {w['sigma']:g} | {w['rho']:g} | {'pose' if w['pose_only'] else 'all'} | {w['frames']} | "
                     f"{w['passes']}/{len(w['runs'])} | {w['diverged']} | " + " | ".join(cells) + " |")
    return lines
