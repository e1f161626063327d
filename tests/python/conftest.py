import math
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


def assert_same_json(a, b, where: str = "", rel_tol: float = 1e-12, abs_tol: float = 1e-12) -> None:
    """A fixture read back equals the one rebuilt now: same keys, lengths and values, floats within the
    tolerances (libm and numpy may differ in the last bits between machines)."""
    if isinstance(a, dict):
        assert a.keys() == b.keys(), where
        for k in a:
            assert_same_json(a[k], b[k], f"{where}.{k}", rel_tol, abs_tol)
    elif isinstance(a, list):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            assert_same_json(x, y, f"{where}[{i}]", rel_tol, abs_tol)
    elif isinstance(a, float) and isinstance(b, (int, float)):
        assert math.isclose(a, b, rel_tol=rel_tol, abs_tol=abs_tol), f"{where}: {a} != {b}"
    else:
        assert a == b, f"{where}: {a!r} != {b!r}"
