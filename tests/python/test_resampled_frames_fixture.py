"""tests/fixtures/resampled_frames.json is what python -m training.fixtures.resampled_frames writes today, and
training/mocap/resample.py resample gives a clip exactly the stored number of frames: the Python side of the frame
count parity (training/mocap/resample.py = web/motion/resample.ts resampledFrames)."""
import json

import numpy as np

from training.fixtures.resampled_frames_cases import OUT, build
from training.mocap.resample import resample
from training.mocap.retarget import CanonicalClip
from training.mocap.skeleton import canonical_skeleton
from conftest import assert_same_json

LONGEST_CLIP_RESAMPLED = 5000  # frames; the longer made-up cases are checked through the fixture's rebuild only


def still_clip(frames: int, fps: float) -> CanonicalClip:
    joints = len(canonical_skeleton().joints)
    rotations = np.zeros((frames, joints, 4))
    rotations[..., 3] = 1.0
    return CanonicalClip("still", fps, np.zeros((frames, 3)), rotations, np.zeros((frames, joints, 3)))


def test_resampled_frames_fixture_is_current(mocap):
    committed = json.loads(OUT.read_text())
    fresh = json.loads(json.dumps(build(mocap)))
    assert_same_json(fresh, committed)


def test_resample_gives_a_clip_the_stored_frame_count():
    cases = [c for c in json.loads(OUT.read_text())["cases"] if c["frames"] <= LONGEST_CLIP_RESAMPLED]
    assert len(cases) > 200
    wrong = [c for c in cases if resample(still_clip(c["frames"], c["fps_in"]), c["fps_out"]).frames != c["count"]]
    assert wrong == []
