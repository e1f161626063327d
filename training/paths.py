"""Where the corpus and caches live. The corpus path comes from --mocap, then $MOCAP_DIR, then ../shared/mocap."""
from __future__ import annotations

import argparse
import os
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parent.parent
DEFAULT_MOCAP = REPO_ROOT.parent / "shared" / "mocap"
DEFAULT_CACHE = REPO_ROOT / "cache"
MODELS_DIR = REPO_ROOT / "public" / "models"  # the shipped models the page loads
REPORTS_DIR = REPO_ROOT / "docs" / "models"  # the model reports
ENV_VAR = "MOCAP_DIR"


def add_mocap_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--mocap", default=None,
                        help=f"corpus directory (default: ${ENV_VAR}, else {DEFAULT_MOCAP})")


def resolve_mocap_dir(flag: str | None = None) -> Path:
    """The corpus directory; exits with a one-line message when it is missing."""
    if flag:
        path, how = Path(flag), "--mocap"
    elif os.environ.get(ENV_VAR):
        path, how = Path(os.environ[ENV_VAR]), f"${ENV_VAR}"
    else:
        path, how = DEFAULT_MOCAP, "the default location"
    if not (path / "cmu" / "index.tsv").is_file():
        raise SystemExit(
            f"error: no mocap corpus at {path.resolve()} (from {how}; expected cmu/index.tsv there); "
            f"pass --mocap DIR or set {ENV_VAR}=DIR")
    return path
