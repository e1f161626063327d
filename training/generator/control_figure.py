"""Draw docs/models/control.png, the figure of docs/models/control.md, from docs/models/control.json.

    python -m training.generator.control_figure

scripts/evaluate-control.mjs (npm run evaluate:control, and its --from-json) runs this after writing the report;
the drawing is training/generator/control_drawing.py.
"""
from __future__ import annotations

import argparse

from .control_drawing import CONTROL_JSON, write_control_figure


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.parse_args(argv)
    path = write_control_figure()
    print(f"wrote {path} from {CONTROL_JSON.name}")


if __name__ == "__main__":
    main()
