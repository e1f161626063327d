"""The model reports in docs/models: each opens with its title and a five-line summary for a student (what the model
does, how the page uses it, two lines of headline numbers against real held-out clips, what is not met), then its
figure, then the tables, with no paragraph in a table cell. Where a report's writer can write it again from the
numbers stored beside it (docs/models/*.json), doing so gives the committed file exactly: a hand edit fails here."""
import json
import re
import shutil
import subprocess

import pytest

from conftest import REPO

MODELS = REPO / "docs" / "models"
REPORTS = ["generator", "refiner", "aclstm", "latent-erd", "vae-lstm", "control", "cleanup"]
# Every report's figure, as its Markdown links it (relative to docs/models): each drawn by the report's writer, control.png
# by training/generator/control_figure.py from control.json; cleanup.md shows a screenshot of the page's panel.
FIGURES = {"generator": "generator.png", "refiner": "refiner.png", "aclstm": "aclstm.png", "latent-erd": "latent-erd.png",
           "vae-lstm": "vae-lstm-variations.png", "control": "control.png", "cleanup": "../cleanup.png"}
# The other pages in docs/models are not reports of a model, so they need no summary (their table cells are checked):
# refiner-notes.md and refiner-browser.md are parts of refiner.md, which its writer copies in; aclstm-pilots.md is the
# acLSTM's pilot runs (history, linked from aclstm.md, written by training/aclstm/pilots.py); weights.md measures how
# every model's weights are stored (linked from the generator and acLSTM reports); retarget.md measures retargeting onto
# characters' own rigs (web/motion/retarget.ts, no model; written by npm run evaluate:retarget); style-generator.md is
# the style-conditioned generator's pilots (issue 39, not shipped; from python -m training.style_generator.pilot's JSON).
NOT_REPORTS = ["refiner-notes", "refiner-browser", "aclstm-pilots", "weights", "retarget", "style-generator",
               "style-generator-shipped", "style-generator-full-c", "aclstm-before-lead-in-fix"]  # measured tables linked from a report
SUMMARY_LABELS = ["What it does", "In the page", None, None, "Not met"]
LONGEST_CELL = 200


def report_lines(name: str) -> list[str]:
    return (MODELS / f"{name}.md").read_text().split("\n")


def table_cells(text: str) -> list[str]:
    return [cell.strip() for line in text.split("\n") if line.startswith("|") for cell in line.strip().strip("|").split("|")]


@pytest.mark.parametrize("name", REPORTS)
def test_a_report_opens_with_its_title_and_five_summary_lines(name):
    lines = report_lines(name)
    assert lines[0].startswith("# ") and lines[1] == "", f"{name}.md: a title, then a blank line"
    summary = lines[2:7]
    assert all(line.startswith("- **") for line in summary), f"{name}.md: five summary lines, each '- **label:** ...'"
    assert lines[7] == "", f"{name}.md: the summary has exactly five lines"
    for line, label in zip(summary, SUMMARY_LABELS):
        if label:
            assert line.startswith(f"- **{label}:**"), f"{name}.md: {line[:40]!r} should open with {label!r}"


def test_every_report_has_a_figure():
    assert sorted(FIGURES) == sorted(REPORTS)


@pytest.mark.parametrize("name", REPORTS)
def test_the_figure_comes_right_after_the_summary(name):
    lines = report_lines(name)
    first_table = next((i for i, line in enumerate(lines) if line.startswith("|")), len(lines))
    figure = next((i for i, line in enumerate(lines) if re.match(rf"!\[[^\]]*\]\({re.escape(FIGURES[name])}\)", line)), None)
    assert figure is not None, f"{name}.md shows {FIGURES[name]}"
    assert figure < first_table, f"{name}.md: the figure before the first table"
    assert figure == 8, f"{name}.md: the figure right after the summary"


@pytest.mark.parametrize("name", REPORTS)
def test_the_figure_file_exists(name):
    path = MODELS / FIGURES[name]
    assert path.is_file() and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", f"{name}.md links {FIGURES[name]}, which is not a PNG file"


@pytest.mark.parametrize("path", sorted(MODELS.glob("*.md")), ids=lambda p: p.name)
def test_no_table_cell_is_a_paragraph(path):
    long = [cell[:60] + "…" for cell in table_cells(path.read_text()) if len(cell) > LONGEST_CELL]
    assert long == [], f"{path.name}: table cells over {LONGEST_CELL} characters"


def test_every_page_is_a_report_or_listed_as_not_one():
    assert sorted(path.stem for path in MODELS.glob("*.md")) == sorted(REPORTS + NOT_REPORTS)


def test_the_cell_check_finds_long_cells():
    assert table_cells("text\n| a | b |\n|---|---|\n| x | yy |\n") == ["a", "b", "---", "---", "x", "yy"]


# Writers that write the report again from the stored JSON, measuring nothing.
def written_generator() -> str:
    from training.generator.report import REPORT_JSON, generator_markdown
    return generator_markdown(json.loads(REPORT_JSON.read_text()))


def written_refiner() -> str:
    from training.refiner.report import REPORT_JSON, refiner_markdown
    return refiner_markdown(json.loads(REPORT_JSON.read_text()))


def written_aclstm() -> str:
    from training.aclstm.report import aclstm_markdown, read_report
    return aclstm_markdown(read_report())


def written_latent_erd() -> str:
    from training.latent_erd.report import latent_erd_markdown, read_report
    return latent_erd_markdown(read_report())


def written_vae_lstm() -> str:
    from training.vae_lstm.report import read_report, vae_lstm_markdown
    report, notes = read_report()
    return vae_lstm_markdown(report, notes)


def written_control() -> str:
    if shutil.which("node") is None or not (REPO / "node_modules" / "vite").exists():
        pytest.skip("node or the npm packages are not installed (the script imports the browser helpers)")
    done = subprocess.run(["node", "scripts/evaluate-control.mjs", "--from-json", "--stdout"], cwd=REPO,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return done.stdout


WRITERS = {"generator": written_generator, "refiner": written_refiner, "aclstm": written_aclstm,
           "latent-erd": written_latent_erd, "vae-lstm": written_vae_lstm, "control": written_control}


@pytest.mark.parametrize("name", list(WRITERS))
def test_writing_the_report_again_from_its_json_gives_the_committed_file(name):
    assert WRITERS[name]() == (MODELS / f"{name}.md").read_text(), (
        f"docs/models/{name}.md differs from what its writer makes of {name}.json: edit the writer, not the report")


# cleanup.md is written by hand from cleanup.json (npm run evaluate:cleanup writes only the JSON): its results
# tables must show the stored numbers.
def test_the_cleanup_tables_show_the_numbers_in_cleanup_json():
    stored = json.loads((MODELS / "cleanup.json").read_text())
    text = (MODELS / "cleanup.md").read_text()
    rows = {}
    for line in text.split("\n"):
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if line.startswith("| ") and len(cells) == 8 and cells[0].endswith(" cm") and cells[1] != "method":
            rows[(cells[0], cells[1])] = cells[2:]
    assert len(rows) == len(stored["summary"])
    for s in stored["summary"]:
        shown = rows[(f"{round(100 * s['level'])} cm", s["method"])]
        assert [float(v) for v in shown[:5]] == [s["error_cm"], s["jerk"], s["sliding"], s["contact_f1"], s["bone_change_cm"]]
        assert (shown[5] == "—") if s["x_real_time"] is None else abs(float(shown[5]) - s["x_real_time"]) <= 0.5
    check = {}
    for line in text.split("\n"):
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if line.startswith("| ") and len(cells) == 5 and cells[0].endswith(" cm") and " / " in cells[1]:
            check[cells[0]] = cells[1:]
    methods = ["noisy input", "map", "manifold", "lowpass"]
    for s in stored["check"]["summary"]:
        error, sliding = check[f"{round(100 * s['level'])} cm"][methods.index(s["method"])].split(" / ")
        assert (float(error), float(sliding)) == (s["error_cm"], s["sliding"])
    skeletons = {}
    for line in text.split("\n"):
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if line.startswith("| ") and len(cells) == 5 and cells[1].endswith(" cm") and " / " in cells[2]:
            skeletons[(cells[0], cells[1])] = cells[2:]
    shown_rows = [s for s in stored["skeletons"] if s["method"] != "clean capture"]
    assert len(skeletons) * 3 == len(shown_rows)
    for s in shown_rows:
        error, sliding = skeletons[(s["skeleton"], f"{round(100 * s['level'])} cm")][["noisy input", "map", "lowpass"].index(s["method"])].split(" / ")
        assert (float(error), float(sliding)) == (s["error_cm"], s["sliding"])
    summary = "\n".join(report_lines("cleanup")[2:7])
    by = {(s["method"], s["level"]): s for s in stored["summary"]}
    for method in ("map", "lowpass"):
        errors = " / ".join(f"{by[(method, level)]['error_cm']:.2f}" for level in stored["levels"])
        slidings = " / ".join(f"{by[(method, level)]['sliding']:.3f}" for level in stored["levels"])
        assert errors in summary and slidings in summary, method
