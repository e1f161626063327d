"""tests/fixtures/feature_encoding.json is what python -m training.fixtures.feature_encoding writes today: the
Python side of the feature-encoding parity (training/data/features.py = web/model/featureEncode.ts)."""
import json

import numpy as np

from training.data.features import heading_of
from training.fixtures.feature_encoding_cases import OUT, build, shipped_codec
from training.mocap.rotations import quat_to_matrix
from conftest import assert_same_json


def test_feature_encoding_fixture_is_current(mocap):
    committed = json.loads(OUT.read_text())
    fresh = json.loads(json.dumps(build(mocap)))
    assert_same_json(fresh, committed, abs_tol=1e-12)


def test_the_stored_rows_decode_to_the_stored_positions():
    """The stored rows are generator features of the stored frames: decoded from the frame before them, with
    generator.json's references, they give back the stored positions (the root within 1e-9 m, every joint 1e-6 m)."""
    codec = shipped_codec()
    data = json.loads(OUT.read_text())
    for case in data["cases"]:
        positions = np.array(case["positions"]).reshape(case["frames"], -1, 3)
        rows = np.array(case["features"]).reshape(case["frames"] - 1, data["dim"])
        world = np.array(case["world_rotations"]).reshape(case["frames"], -1, 4)
        heading = float(heading_of(quat_to_matrix(world[0, 0])))  # frame 0's: the rows start from it
        decoded = codec.positions(rows, start_xz=(positions[0, 0, 0], positions[0, 0, 2]), start_heading=heading)
        assert np.abs(decoded[:, 0] - positions[1:, 0]).max() < 1e-9, case["name"]
        assert np.abs(decoded - positions[1:]).max() < 1e-6, case["name"]
