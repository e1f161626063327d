"""Every clip in the corpus on the canonical skeleton: loads, keeps its shape, stands on the floor."""
import numpy as np
import pytest

from training.data.cmu import load_clip, read_index
from training.mocap.resample import resample
from training.mocap.retarget import RIGID_BONES, retarget, source_from_amc
from training.mocap.skeleton import GROUND_POINTS, canonical_skeleton, forward_kinematics
from training.mocap import asf_amc

SKEL = canonical_skeleton()
GROUND = [SKEL.index(n) for n in GROUND_POINTS]
TOLERANCE = 0.03  # metres


def window_lows(positions, fps):
    """Lowest foot point in each one-second window: in any second of locomotion a foot touches the floor."""
    low = positions[:, GROUND, 1].min(axis=1)
    step = int(round(fps))
    return np.array([low[a:a + step].min() for a in range(0, len(low), step)])


def test_canonical_skeleton_is_symmetric_and_human_sized():
    offsets = SKEL.offsets
    mirrored = offsets[SKEL.mirror_map] * [-1, 1, 1]
    assert np.allclose(offsets, mirrored, atol=1e-6)
    assert 0.75 < SKEL.leg_length < 1.0
    rest = forward_kinematics(SKEL, np.zeros((1, 3)), np.tile([0, 0, 0, 1.0], (1, len(SKEL.joints), 1)))[0]
    assert 1.5 < rest[:, 1].max() - rest[:, 1].min() < 1.9


@pytest.fixture(scope="module")
def all_clips(mocap):
    return [(info, load_clip(mocap, info)) for info in read_index(mocap)]


def test_every_clip_loads_with_canonical_bone_lengths(all_clips):
    assert len(all_clips) == 256
    lengths = np.linalg.norm(SKEL.offsets[1:], axis=-1)
    for info, clip in all_clips:
        assert np.isfinite(clip.positions).all(), info.file
        p = clip.positions
        got = np.linalg.norm(p[:, 1:] - p[:, SKEL.parents[1:]], axis=-1)
        assert np.abs(got - lengths).max() < 1e-6, info.file


def test_every_clip_has_its_feet_on_the_floor(all_clips):
    """Per clip, most (60%) of its one-second windows have their lowest foot point within 3 cm of y = 0
    (a sloped or offset floor fails this), and over the corpus at least 95% do (docs/data.md)."""
    total, close = 0, 0
    for info, clip in all_clips:
        lows = window_lows(clip.positions, clip.fps)
        ok = np.abs(lows) < TOLERANCE
        assert ok.mean() >= 0.6, (info.file, np.round(lows, 3))
        total += len(ok)
        close += ok.sum()
    assert close / total >= 0.95


def test_retarget_keeps_every_bone_direction(mocap):
    skel_src = asf_amc.load_asf(mocap / "cmu/asf/16.asf")
    motion = asf_amc.load_amc(mocap / "cmu/amc/16_11.amc.gz", skel_src)
    names, src = asf_amc.positions(skel_src, motion)
    clip = retarget(source_from_amc(mocap / "cmu/asf/16.asf", mocap / "cmu/amc/16_11.amc.gz"))
    for j, bones in enumerate(SKEL.source_bones):
        if not bones or bones[0] in RIGID_BONES:  # kept in their rest pose on purpose
            continue
        b = bones[0]
        parent = skel_src.parent[b]
        d_src = src[:, names.index(b)] - src[:, names.index(parent)]
        d_dst = clip.positions[:, j] - clip.positions[:, SKEL.parents[j]]
        cos = np.sum(d_src * d_dst, -1) / np.linalg.norm(d_src, axis=-1) / np.linalg.norm(d_dst, axis=-1)
        assert cos.min() > 1 - 1e-9, SKEL.joints[j]


def test_root_travel_is_scaled_by_leg_length(mocap):
    src = source_from_amc(mocap / "cmu/asf/16.asf", mocap / "cmu/amc/16_11.amc.gz")
    clip = retarget(src)
    travel_src = np.linalg.norm(src.root[-1, [0, 2]] - src.root[0, [0, 2]])
    travel_dst = np.linalg.norm(clip.root[-1, [0, 2]] - clip.root[0, [0, 2]])
    assert travel_dst / travel_src == pytest.approx(SKEL.leg_length / src.leg_length, rel=1e-6)


def test_cmu_bvh_placeholder_frames_are_dropped(mocap):
    info = next(i for i in read_index(mocap) if i.file.endswith("07_12.bvh.gz"))
    clip = load_clip(mocap, info)
    assert clip.frames == info_frames(mocap, info) - 2
    assert np.abs(np.diff(clip.root, axis=0)).max() < 0.05  # no jump from a T-pose at the origin


def info_frames(mocap, info):
    import csv
    with open(mocap / "cmu/index.tsv") as f:
        return next(int(r["frames"]) for r in csv.DictReader(f, delimiter="\t") if r["file"] == info.file)


def test_resample_to_30_fps_picks_every_fourth_frame(mocap):
    info = next(i for i in read_index(mocap) if i.file.endswith("16_11.amc.gz"))
    full = load_clip(mocap, info)
    low = resample(full, 30)
    assert low.fps == 30 and low.frames == (full.frames - 1) // 4 + 1
    assert np.allclose(low.positions, full.positions[::4], atol=1e-9)


def test_resample_interpolates_between_frames(mocap):
    info = next(i for i in read_index(mocap) if i.file.endswith("16_11.amc.gz"))
    full = load_clip(mocap, info)
    sixty = resample(full, 48)  # 2.5 source frames apart: in-between poses
    assert sixty.frames == int((full.frames - 1) / 2.5) + 1
    mid = sixty.positions[1]  # source time 2.5
    assert np.linalg.norm(mid - full.positions[2], axis=-1).max() < 0.05
    assert not np.allclose(mid, full.positions[2])
