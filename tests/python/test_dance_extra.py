"""The two CMU trials of ../shared/mocap/aclstm-extra/ on the acLSTM standard skeleton (training/data/dance_extra.py)."""
import numpy as np
import pytest

from training.data import dance
from training.data.dance_extra import EXTRA_FILES, correspondence, read_source, to_standard

FRAMES = {"indian": 3602, "martial": 5202}  # the source files' frames (README: acLSTM's indian 01 and martial 02)


@pytest.fixture(scope="module")
def converted(mocap):
    skel = dance.load_skeleton(mocap)
    out = {}
    for style, motion, skeleton in EXTRA_FILES:
        src = read_source(mocap, motion, skeleton)
        out[style] = (src, dance.on_floor(to_standard(src, skel.names, skel.parents, skel.offsets)))
    return skel, out


def test_one_frame_per_source_frame_on_the_standard_bone_lengths(converted):
    skel, clips = converted
    for style, (src, pos) in clips.items():
        assert len(src.positions) == FRAMES[style]
        assert pos.shape == (FRAMES[style], 57, 3) and np.isfinite(pos).all()
        got = np.linalg.norm(pos[:, 1:] - pos[:, skel.parents[1:]], axis=-1)
        np.testing.assert_allclose(got, np.broadcast_to(skel.bone_lengths()[1:], got.shape), atol=1e-9)


def test_feet_on_the_floor_and_a_standing_root_height(converted):
    skel, clips = converted
    feet = [skel.names.index(n) for n in ("lFoot", "rFoot", "lFoot_end", "rFoot_end")]
    for style, (_, pos) in clips.items():
        lowest = pos[..., 1].min(axis=1)
        assert abs(np.percentile(lowest, 10)) < 1e-9, style
        # Something touches the floor in most frames, and it is a foot (not a hand or the hips).
        assert 0.0 <= np.median(lowest) < 0.05, style
        assert np.mean(np.isin(pos[..., 1].argmin(axis=1), feet)) > 0.97, style
        # The acLSTM clips of the same subjects stand with the hips 0.57-0.76 m up (median per clip).
        assert 0.55 < np.median(pos[:, 0, 1]) < 0.8, style
        head = pos[:, skel.names.index("head"), 1] - pos[:, 0, 1]
        assert np.median(head) > 0.5, style  # upright: the head 0.6 m above the hips, as in the acLSTM clips


def test_limbs_point_where_the_source_limbs_point(converted, mocap):
    """Thighs and upper arms lie along the source's bones (the retarget's direction rule), in every frame."""
    skel, clips = converted
    for style, (src, pos) in clips.items():
        pairs = correspondence(src, skel.names, skel.parents, skel.offsets)
        for side in ("Left", "Right"):
            for upper, lower in (("UpLeg", "Leg"), ("Arm", "ForeArm")):
                (a, sa), (b, sb) = pairs[side + upper], pairs[side + lower]
                mine = pos[:, b] - pos[:, a]
                theirs = src.positions[:, sb] - src.positions[:, sa]
                cos = (mine * theirs).sum(-1) / np.linalg.norm(mine, axis=-1) / np.linalg.norm(theirs, axis=-1)
                assert cos.min() > 1 - 1e-9, (style, side, upper)
        # Left is left: the standard's lThigh sits at the source's left hip socket side.
        left, right = pos[:, skel.names.index("lThigh")], pos[:, skel.names.index("rThigh")]
        s_left, s_right = src.positions[:, pairs["LeftUpLeg"][1]], src.positions[:, pairs["RightUpLeg"][1]]
        assert ((left - right) * (s_left - s_right)).sum(-1).min() > 0, style


def test_extra_clips_are_training_clips_behind_an_option(tmp_path, monkeypatch):
    """load_clips(extra=True) reads its own cache; the converted trials are never held out, the set's stay as
    HELD_OUT says; the default reads the usual cache."""
    names = ["hip", "abdomen"]
    cache = tmp_path / "extra.npz"
    files = ["aclstm/indian/15.bvh.gz", "aclstm/indian/04.bvh.gz", "aclstm-extra/indian/94_01.bvh.gz",
             "aclstm-extra/martial/135_02.amc.gz"]
    np.savez(cache, positions=np.zeros((8, 2, 3), np.float32), style=["indian", "indian", "indian", "martial"],
             files=files, start=[0, 2, 4, 6], frames=[2, 2, 2, 2], names=names, parents=[-1, 0],
             offsets=np.zeros((2, 3)))
    monkeypatch.setattr(dance, "EXTRA_CACHE", cache)
    monkeypatch.setattr(dance, "CACHE", tmp_path / "absent.npz")
    monkeypatch.setattr(dance, "build_cache", lambda *a, **k: pytest.fail("the default cache was asked for"))
    _, clips = dance.load_clips(extra=True)
    assert [(c.file, c.held_out, c.fps) for c in clips] == [
        (files[0], True, 120.0), (files[1], False, 120.0), (files[2], False, 120.0), (files[3], False, 120.0)]
    with pytest.raises(pytest.fail.Exception):
        dance.load_clips()


def test_cmu_t_pose_lands_on_the_standard_t_pose(converted, mocap):
    """CMU's rest pose (135.asf, a T-pose) converted: the upper body lands on the standard's T-pose (the acLSTM files'
    frame 0) to within 5 cm, so the pelvis, chest, head and arm frames need no other rest correction."""
    from training.data.dance_extra import rest_positions
    from training.data.dance_extra_check import rest_source
    skel, clips = converted
    _, motion, skeleton = next(f for f in EXTRA_FILES if f[2])
    src, rest = rest_source(mocap, motion, skeleton)
    pairs = correspondence(src, skel.names, skel.parents, skel.offsets)
    got = to_standard(rest, skel.names, skel.parents, skel.offsets, pairs)[0]
    want = rest_positions(skel.parents, skel.offsets)
    d = np.linalg.norm((got - got[0]) - (want - want[0]), axis=-1)
    upper = [i for i, n in enumerate(skel.names) if not any(k in n for k in ("Thigh", "Shin", "Foot"))]
    assert d[upper].max() < 0.05
    for side in "lr":  # the hands at the T-pose's span, not folded down
        hand = skel.names.index(f"{side}Hand")
        assert abs(got[hand, 1] - got[skel.names.index(f"{side}Shldr"), 1]) < 0.05
