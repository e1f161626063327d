import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))
MOCAP = REPO.parent / "shared" / "mocap"


@pytest.fixture(scope="session")
def mocap() -> Path:
    assert (MOCAP / "cmu" / "index.tsv").is_file(), f"these tests need the corpus at {MOCAP}"
    return MOCAP
