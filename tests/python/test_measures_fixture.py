"""tests/fixtures/measures_parity.json is what python -m training.fixtures.measures writes today (under a second)."""
import json

from training.fixtures.measures_parity import OUT, build
from conftest import assert_same_json



def test_measures_fixture_is_current(mocap):
    committed = json.loads(OUT.read_text())
    fresh = json.loads(json.dumps(build(mocap)))
    assert_same_json(fresh, committed, abs_tol=1e-15)
