"""docs/models/control.png, the figure of docs/models/control.md (the generator steered by the MAP optimiser),
drawn from the numbers stored in docs/models/control.json (npm run evaluate:control writes both; its report
writer is JavaScript, so the figure is drawn here: python -m training.generator.control_figure)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..paths import REPORTS_DIR

CONTROL_JSON = REPORTS_DIR / "control.json"
FIGURE = "control.png"
GAITS = {"walk": "C0", "run": "C1"}


def _dots(ax, x, values, colour) -> None:
    """One dot per seed, spread a little sideways so equal values stay apart."""
    spread = np.linspace(-0.08, 0.08, len(values)) if len(values) > 1 else [0.0]
    ax.plot(x + np.asarray(spread), values, "o", color=colour, mec="k", mew=0.5, ms=5)


def plot_control(r: dict, path: Path = REPORTS_DIR / FIGURE) -> None:
    """Path error per benchmark path and gait against the targets; the heading response of each turn against its
    limit; the speed error 1 s after each change of speed against its target. Bars are the seeds' mean, dots the
    seeds."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    T = r["targets"]
    fig, axes = plt.subplots(1, 3, figsize=(16, 4), gridspec_kw={"width_ratios": [2, 1, 1.2]})
    names = list(dict.fromkeys(p["path"] for p in r["paths"]))
    x = np.arange(len(names))
    ax = axes[0]
    for offset, (gait, colour) in zip((-0.2, 0.2), GAITS.items()):
        rows = [[p for p in r["paths"] if p["gait"] == gait and p["path"] == name] for name in names]
        ax.bar(x + offset, [np.mean([p["meanError"] for p in g]) if g else np.nan for g in rows], 0.4, color=colour, alpha=0.7,
               label=f"{gait}: mean error" + ("" if gait == "walk" else " (not a target)"))
        ax.plot(x + offset, [max(p["maxError"] for p in g) if g else np.nan for g in rows], "_", color=colour, ms=18, mew=2,
                label=f"{gait}: worst run's max error")
        for k, g in enumerate(rows):
            _dots(ax, x[k] + offset, [p["meanError"] for p in g], colour)
    ax.axhline(T["meanError"], color="k", ls="--", lw=1, label=f"target: mean ≤ {T['meanError']} m (walk)")
    ax.axhline(T["maxError"], color="k", ls=":", lw=1, label=f"target: max ≤ {T['maxError']} m (walk)")
    ax.set(title="benchmark paths: distance from the root to the path", xticks=x, xticklabels=names,
           xlabel=f"benchmark path (bars: mean of {r['seeds']} seeds, dots: each seed)", ylabel="error (m)", ylim=(0, 1.45 * T["maxError"]))
    ax.legend(fontsize=7, ncol=3, loc="upper left")

    ax = axes[1]
    turns = list(dict.fromkeys(c["scenario"] for c in r["control"] if c["kind"] == "heading"))
    for k, name in enumerate(turns):
        g = [c for c in r["control"] if c["scenario"] == name]
        ax.bar(k, np.mean([c["headingResponse"] for c in g]), 0.5, color="C2", alpha=0.7, label="mean of the seeds" if k == 0 else None)
        _dots(ax, k, [c["headingResponse"] for c in g], "C2")
        ax.hlines(g[0]["limit"], k - 0.35, k + 0.35, color="k", ls="--", lw=1, label="limit" if k == 0 else None)
    ax.set(title="live control: turn response", xticks=range(len(turns)), xticklabels=turns, xlim=(-0.6, len(turns) - 0.4),
           xlabel="scenario (change at 3 s)",
           ylabel="seconds until heading within 15° (s)", ylim=(0, 1.3 * max(c["limit"] for c in r["control"] if c["kind"] == "heading")))
    ax.legend(fontsize=7, loc="upper left")

    ax = axes[2]
    speeds = list(dict.fromkeys(c["scenario"] for c in r["control"] if c["kind"] == "speed"))
    for k, name in enumerate(speeds):
        g = [c for c in r["control"] if c["scenario"] == name]
        colour = GAITS["run"] if name.startswith("run") else GAITS["walk"]
        ax.bar(k, np.mean([c["speedError"] for c in g]), 0.5, color=colour, alpha=0.7,
               label=("walking" if colour == GAITS["walk"] else "running (not a target)") if name in (speeds[0], speeds[-1]) else None)
        _dots(ax, k, [c["speedError"] for c in g], colour)
    ax.axhline(T["speedError"], color="k", ls="--", lw=1, label=f"target ≤ {T['speedError']} m/s (walk)")
    ax.set(title="live control: speed 1 s after the change", xticks=range(len(speeds)),
           xticklabels=[("walk " + s.removeprefix("speed ") if s.startswith("speed") else s).replace(" m/s", "").replace(" → ", "→") for s in speeds],
           xlabel="change of target speed (m/s)", ylabel="|speed − target| (m/s)", ylim=(0, 1.4 * T["speedError"]))
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def write_control_figure(source: Path = CONTROL_JSON, path: Path = REPORTS_DIR / FIGURE) -> Path:
    """control.png from the stored control.json, measuring nothing."""
    plot_control(json.loads(source.read_text()), path)
    return path
