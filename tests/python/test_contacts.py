import numpy as np

from training.mocap.contacts import CONTACT_THRESHOLDS, foot_contacts
from training.data.cmu import clip_contacts, load_clip, read_index


def test_hysteresis_keeps_contact_through_small_rises():
    fps = 30
    t = np.arange(60)
    ankle = np.zeros((60, 3))
    toe = np.zeros((60, 3)) + [0, 0, 0.15]
    # Planted, then raised slowly to 6 cm (above the on-threshold, below the off-threshold), then lifted high.
    ankle[:, 1] = np.where(t < 20, 0.0, np.where(t < 40, np.minimum((t - 20) * 0.006, 0.06), 0.3))
    toe[:, 1] = ankle[:, 1]
    flags = foot_contacts(ankle, toe, fps)
    assert flags[:38].all()  # stays on through the slow rise
    assert not flags[42:].any()
    # The same 6 cm, reached from above, never turns contact on.
    assert CONTACT_THRESHOLDS["ankle_on"] < 0.06 < CONTACT_THRESHOLDS["ankle_off"]
    hover = np.where(t < 10, 0.0, np.where(t < 30, 0.3, 0.06))
    ankle[:, 1], toe[:, 1] = hover, hover
    flags = foot_contacts(ankle, toe, fps)
    assert flags[:8].all() and not flags[12:].any()


def test_sliding_foot_is_not_in_contact():
    fps = 30
    ankle = np.zeros((40, 3))
    ankle[:, 0] = np.arange(40) * 0.05  # 1.5 m/s along the ground
    assert not foot_contacts(ankle, ankle + [0, 0, 0.15], fps).any()


def test_walking_clip_alternates_feet(mocap):
    info = next(i for i in read_index(mocap) if i.file.endswith("16_15.amc.gz"))
    c = clip_contacts(load_clip(mocap, info, 30))
    share = c.mean(axis=0)
    assert ((share > 0.4) & (share < 0.85)).all(), share
    assert c.max(axis=1).mean() > 0.95  # walking: almost always a foot on the ground
    assert (c.sum(axis=1) == 1).mean() > 0.3  # and often just one
    onsets = np.flatnonzero(np.diff(c[:, 0].astype(int)) == 1)
    assert len(onsets) >= 1


def test_running_has_flight_phases(mocap):
    info = next(i for i in read_index(mocap) if i.file.endswith("16_36.amc.gz"))
    c = clip_contacts(load_clip(mocap, info, 30))
    assert c.mean() < 0.45
    assert (c.max(axis=1) == 0).any()  # both feet in the air at some point


def _pose_with_left_foot(height: float, x: float) -> np.ndarray:
    """Canonical rest-like pose: every joint at 1 m except the left foot's three points (lowest at `height`, moved
    `x` along x) and the right foot's (0.5 m up)."""
    from training.mocap.skeleton import canonical_skeleton
    skel = canonical_skeleton()
    p = np.ones((len(skel.joints), 3))
    for k, name in enumerate(("LeftFoot", "LeftToeBase", "LeftToeBase_end")):
        p[skel.index(name)] = [x, height + 0.04 * (2 - k), 0.1 * k]
    for name in ("RightFoot", "RightToeBase", "RightToeBase_end"):
        p[skel.index(name), 1] = 0.5
    return p


def test_shown_motion_labels_combine_the_bit_with_height_and_speed():
    from training.contact_labels import ContactLabeller

    def run(frames):
        lab, x, out = ContactLabeller(fps=30.0), 0.0, []
        for h, v, bit in frames:
            x += v / 30.0
            out.append(int(lab.step(_pose_with_left_foot(h, x), [bit, 0])[0]))
        return out

    assert run([(0.01, 0, 0), (0.01, 0.5, 0), (0.01, 2.5, 0)]) == [1, 1, 0]  # resting, bit off: planted while slow
    assert run([(0.2, 3, 0), (0.03, 3, 0), (0.03, 3, 0)]) == [0, 0, 0]  # a swing skimming the floor
    assert run([(0.01, 0, 0), (0.05, 0, 0), (0.01, 1.2, 0), (0.07, 0, 0)]) == [1, 1, 1, 0]  # hysteresis band
    assert run([(0.05, 0, 0)]) == [0]
    assert run([(0.08, 3, 1)]) == [1] and run([(0.2, 0, 1)]) == [0]  # the bit near the floor, not in the air
