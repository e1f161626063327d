"""docs/models/latent-erd.png, the report's figure, drawn from the numbers stored in latent-erd.json (the page's
runs from its `browser` part, latent-erd-browser.json): nothing here measures, so writing the report from the
JSON draws it too."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..paths import REPORTS_DIR
from .measures import FREEZE_FRACTION, HORIZONS

FIGURE = "latent-erd.png"
COLOURS = {"latent ERD": "C0", "pose-space ERD": "C1", "generator (free-running)": "C2"}


def plot_latent_erd(r: dict, path: Path = REPORTS_DIR / FIGURE) -> None:
    """Joint error over the prediction horizon (with the root, and relative to it) for every model in the
    report; the page's long random-control runs second by second against the real median and the freeze line;
    pose change by forward speed against the real clips."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pred, lr = r["prediction"], r["long_runs"]
    fps = r["fps"]
    fig, axes = plt.subplots(1, 4, figsize=(20, 4))
    for ax, kind, what in ((axes[0], "with_root_cm", "with the root"), (axes[1], "relative_cm", "relative to the root")):
        for k, (name, errors) in enumerate(pred["rows"].items()):
            ax.plot(HORIZONS, [errors[kind][h] for h in HORIZONS], "o-", color=COLOURS.get(name, f"C{k + 3}"), label=name)
        ax.set(title=f"prediction from held-out seeds:\njoint error {what}", xlabel=f"frames predicted ({fps} fps)",
               ylabel="mean joint error (cm)", xticks=HORIZONS, ylim=(0, None))
        ax.legend(fontsize=7)
    axes[1].text(0.02, 0.04, f"{pred['windows']} windows; every model sees only the past", transform=axes[1].transAxes, fontsize=7)

    median = lr["real_median_pose_change"]
    runs = r.get("browser", {}).get("randomControl") or []
    for k, run in enumerate(runs):
        axes[2].plot(run["poseChange"]["perSecond"], color=f"C{k}", lw=0.6, alpha=0.8, label=f"seed {run['seed']}")
    axes[2].axhline(median, color="k", lw=1, label="real median")
    axes[2].axhline(FREEZE_FRACTION * median, color="k", ls="--", lw=1, label=f"freeze line ({FREEZE_FRACTION:.0%} of real median)")
    frames = runs[0]["frames"] if runs else lr["runs"][0]["frames"]
    axes[2].set(title=f"{len(runs)} × {frames:,}-frame random-control runs\nin the page (fitted to the skeleton, foot-locked)",
                xlabel="second of generation", ylabel="pose change per second (m/s)", yscale="log", ylim=(0.01, 3))
    axes[2].legend(fontsize=6, ncol=4, loc="lower center")

    erd, real = lr["by_speed"]["latent ERD"], lr["by_speed"]["real clips"]
    x = np.arange(len(erd))
    for offset, rows, name, colour in ((-0.2, real, "real clips", "k"), (0.2, erd, "latent ERD", COLOURS["latent ERD"])):
        axes[3].bar(x + offset, [b["mean_share_of_median"] or 0 for b in rows], 0.4, color=colour, alpha=0.35 if colour == "k" else 0.8,
                    label=f"{name}: mean second")
        axes[3].plot(x + offset, [np.nan if b["lowest_share_of_median"] is None else b["lowest_share_of_median"] for b in rows],
                     "v", color=colour, mec="w" if colour == "k" else "k", ms=7, label=f"{name}: lowest second")
    axes[3].axhline(FREEZE_FRACTION, color="k", ls="--", lw=1, label="freeze line")
    axes[3].set(title="pose change by forward speed\n(Python long runs against the real clips)", xlabel="forward speed (m/s)",
                ylabel="pose change / real median (×)", xticks=x, xticklabels=[f"{b['band'][0]}–{b['band'][1]}" for b in erd])
    axes[3].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)
