"""The Bandai Namco set on the canonical skeleton (training/data/bandai.py): a few clips read and mapped (not the whole
set: python -m training.data.build_bandai does that), their skeleton, rate, floor and contacts, the labels, the
held-out rule, and mirroring as augmentation (data/features.py mirror_clip, as CMU's training clips get)."""
import numpy as np
import pytest

from conftest import MOCAP
from training.data.bandai import (CONTENTS, STYLES, BandaiClip, BandaiReader, as_locomotion_clip, is_held_out, ranks,
                                  read_index)
from training.data.locomotion import is_validation
from training.data.features import heading_of, mirror_clip, wrap_angle
from training.mocap.rotations import quat_to_matrix
from training.mocap.skeleton import GROUND_POINTS, canonical_skeleton, forward_kinematics

SKEL = canonical_skeleton()
FILES = ["dataset-2_walk_normal_001.bvh.gz", "dataset-2_walk-turn-left_elderly_003.bvh.gz",
         "dataset-2_walk-turn-right_feminine_010.bvh.gz", "dataset-2_run_exhausted_005.bvh.gz"]


@pytest.fixture(scope="module")
def index():
    return read_index(MOCAP)


@pytest.fixture(scope="module")
def clips(index):
    reader = BandaiReader(MOCAP)
    by_file = {i.file: i for i in index}
    return {f: (by_file[f], reader.load(by_file[f])) for f in FILES}


def net_turn(rotations: np.ndarray) -> float:
    """The heading's total change over a clip (rad; + turns from +z towards +x, the figure's left)."""
    return float(wrap_angle(np.diff(heading_of(quat_to_matrix(rotations[:, 0])))).sum())


def test_the_index_labels_every_clip(index):
    assert len(index) == 962
    assert {i.content for i in index} == set(CONTENTS) and {i.style for i in index} == set(STYLES)
    for i in index:
        assert i.file == f"dataset-2_{i.content}_{i.style}_{i.file.rsplit('_', 1)[1]}" and i.fps == 30


def test_held_out_is_every_eighth_clip_of_each_content_and_style(index):
    rank = ranks(index)
    for content in CONTENTS:
        for style in STYLES:
            group = sorted(i.file for i in index if i.content == content and i.style == style)
            held = [f for f in group if is_held_out(rank[f])]
            assert held == group[3::8], (content, style)
            assert len(held) >= 1, (content, style)  # every style keeps clips of every content for validation
            # The locomotion Corpus, given the clips, holds out the same ones.
            for f in group:
                empty = np.zeros((2, 3))
                clip = as_locomotion_clip(BandaiClip(f, content, style, rank[f], empty, empty, empty, empty))
                assert is_validation(clip) == (f in held)


def test_clips_are_on_the_canonical_skeleton_at_30_fps(clips):
    for info, clip in clips.values():
        assert clip.frames == info.frames  # 30 fps in, 30 fps out
        assert clip.positions.shape == (info.frames, len(SKEL.joints), 3)
        # Positions are the FK of the rotations on the canonical skeleton: its bone lengths exactly.
        assert np.abs(forward_kinematics(SKEL, clip.root, clip.rotations) - clip.positions).max() < 1e-6
        hips = clip.root[:, 1].mean()
        assert 0.85 < hips < 1.1, info.file  # the canonical skeleton's standing hip height, not twice it


def test_feet_are_on_the_floor(clips):
    feet = [SKEL.index(n) for n in GROUND_POINTS]  # ankles, toe bases and toe tips
    for info, clip in clips.values():
        lowest = clip.positions[:, feet, 1].min(axis=1)
        assert np.abs(np.percentile(lowest, 10)) < 0.03, info.file
        assert lowest.min() > -0.05, info.file


def test_contacts_are_plausible(clips):
    toe = [SKEL.index("LeftToeBase"), SKEL.index("RightToeBase")]
    for info, clip in clips.values():
        fraction = clip.contacts.mean(axis=0)
        touch_downs = (np.diff(clip.contacts.astype(int), axis=0) == 1).sum(axis=0)
        if info.content == "run":
            assert np.all((fraction > 0.05) & (fraction < 0.5)), (info.file, fraction)
        else:
            assert np.all((fraction > 0.35) & (fraction < 0.8)), (info.file, fraction)
        assert np.all(touch_downs >= 1), info.file
        # A planted toe barely moves: the feet do not slide under the body (the figure's travel is the root's).
        for side in (0, 1):
            planted = clip.contacts[1:, side].astype(bool) & clip.contacts[:-1, side].astype(bool)
            speed = np.linalg.norm(np.diff(clip.positions[:, toe[side], [0, 2]], axis=0), axis=-1) * 30
            assert np.median(speed[planted]) < 0.3, (info.file, side)


def test_speeds_and_turns_match_the_labels(clips):
    for info, clip in clips.values():
        travel = np.linalg.norm(np.diff(clip.root[:, [0, 2]], axis=0), axis=-1).sum() / (clip.frames / 30)
        lo, hi = (1.2, 6.0) if info.content == "run" else (0.3, 2.0)  # an exhausted run: 1.8 m/s
        assert lo < travel < hi, (info.file, travel)
    assert net_turn(clips[FILES[1]][1].rotations) > 0.5  # walk-turn-left turns left (towards +x from +z)
    assert net_turn(clips[FILES[2]][1].rotations) < -0.5  # walk-turn-right turns right


def test_mirroring_a_bandai_clip(clips):
    _, clip = clips[FILES[1]]  # a left turn
    root, rot, con = mirror_clip(clip.root, clip.rotations, clip.contacts)
    # The mirror image: FK of the mirrored clip is the positions mirrored in x with sides swapped.
    expected = clip.positions[:, SKEL.mirror_map] * [-1, 1, 1]
    assert np.abs(forward_kinematics(SKEL, root, rot) - expected).max() < 1e-6
    assert np.array_equal(con, clip.contacts[:, ::-1])
    # A mirrored left turn turns right, by as much.
    assert net_turn(rot) == pytest.approx(-net_turn(clip.rotations), abs=1e-6)
    assert net_turn(rot) < -0.5
    # Mirrored twice, the clip comes back.
    root2, rot2, con2 = mirror_clip(root, rot, con)
    assert np.abs(root2 - clip.root).max() < 1e-12
    assert np.abs(rot2 - clip.rotations).max() < 1e-12
    assert np.array_equal(con2, clip.contacts)
