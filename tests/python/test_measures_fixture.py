"""tests/fixtures/measures_parity.json is what python -m training.fixtures.measures writes today (under a second)."""
import json
import math

from training.fixtures.measures_parity import OUT, build


def _same(a, b, where="") -> None:
    if isinstance(a, dict):
        assert a.keys() == b.keys(), where
        for k in a:
            _same(a[k], b[k], f"{where}.{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{where}[{i}]")
    elif isinstance(a, float) and isinstance(b, (int, float)):
        # measures may differ in the last bits between machines (numpy's summation order)
        assert math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-15), f"{where}: {a} != {b}"
    else:
        assert a == b, f"{where}: {a!r} != {b!r}"


def test_measures_fixture_is_current(mocap):
    committed = json.loads(OUT.read_text())
    fresh = json.loads(json.dumps(build(mocap)))
    _same(fresh, committed)
