"""The latent ERD's control signal (training/control.py): tests/fixtures/control_signal.json is what
python -m training.fixtures.control_signal writes today (under a second), its closed-loop runs are well
conditioned (so the page's 1e-6 check cannot be upset by the last bit of a sin or atan2), and integrate_control
inverts control_from_trajectory."""
import json
import math

import numpy as np
import pytest

from training import control
from training.fixtures.control_signal_parity import FPS, OUT, PATHS, build, follow, made_up_trajectory
from conftest import assert_same_json



def test_control_signal_fixture_is_current():
    committed = json.loads(OUT.read_text())
    fresh = json.loads(json.dumps(build()))
    assert_same_json(fresh, committed)


@pytest.mark.parametrize("case", PATHS, ids=[p[0] for p in PATHS])
def test_closed_loop_runs_are_well_conditioned(case):
    # Moving the start by 1e-10 m moves no frame's state, signal or progress by more than 1e-8: far from a branch
    # (a flipped clamp, projection or stop) that rounding could take the other way.
    name, points, x, z, heading, speed, frames = case
    path = control.PolylinePath(np.array(points, np.float64))
    base = follow(path, x, z, heading, speed, frames)
    for dx, dz, dh in ((1e-10, 0, 0), (0, -1e-10, 0), (0, 0, 1e-10)):
        moved = follow(path, x + dx, z + dz, heading + dh, speed, frames)
        for key in ("states", "control", "progress"):
            assert np.abs(np.subtract(moved[key], base[key])).max() < 1e-8, (name, key, dx, dz, dh)


def test_integrate_control_inverts_control_from_trajectory():
    xz, heading = made_up_trajectory()
    back_xz, back_heading = control.integrate_control(control.control_from_trajectory(xz, heading, FPS), FPS,
                                                      xz[0], heading[0])
    np.testing.assert_allclose(back_xz, xz, atol=1e-12)
    assert np.abs(control.wrap(back_heading - heading)).max() < 1e-12
    # And back: a random signal's trajectory gives the signal again (all but the last frame, which is not used).
    signal = control.random_control(5, 200, FPS)
    signal[:, 1] = 0.3 * np.sin(np.arange(200) / 9)  # some sideways motion too
    traced = control.integrate_control(signal, FPS, (2.0, -1.0), 3.0)
    np.testing.assert_allclose(control.control_from_trajectory(*traced, FPS)[:-1], signal[:-1], atol=1e-9)


def test_frame_conventions():
    # Heading 0 faces +z, pi/2 faces +x; sideways is +x at heading 0; a positive turn goes from +z towards +x.
    xz, h = control.integrate_control(np.array([[3.0, 0, 0], [0, 0, 0]]), 3.0, (0, 0), math.pi / 2)
    np.testing.assert_allclose(xz[1], [1, 0], atol=1e-15)
    xz, h = control.integrate_control(np.array([[0, 3.0, 0], [0, 0, 0]]), 3.0)
    np.testing.assert_allclose(xz[1], [1, 0])
    assert control.control_toward_heading(0.0, 0.5, 1.0)[2] > 0
    assert control.control_toward_heading(3.0, -3.0, 1.0)[2] > 0  # across ±pi, the short way
    assert control.wrap(math.pi) == -math.pi and control.wrap(-7.0) == pytest.approx(-7.0 + 2 * math.pi)
