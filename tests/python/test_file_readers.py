"""ASF/AMC and BVH readers on real clips, and their errors on bad input."""
import gzip

import numpy as np
import pytest

from training.mocap import asf_amc, bvh
from training.mocap.files import MotionFormatError, read_text


def bone_lengths(names, positions, parents):
    return {n: np.linalg.norm(positions[:, i] - positions[:, parents[i]], axis=-1)
            for i, n in enumerate(names) if parents[i] >= 0}


def test_asf_amc_real_clip(mocap):
    skel = asf_amc.load_asf(mocap / "cmu/asf/16.asf")
    assert abs(skel.metres_per_unit - 0.0254 / 0.45) < 1e-12
    motion = asf_amc.load_amc(mocap / "cmu/amc/16_11.amc.gz", skel)
    names, pos = asf_amc.positions(skel, motion)
    assert pos.shape == (motion.frames, 31, 3) and motion.frames > 400
    height = pos[0, :, 1].max() - pos[0, :, 1].min()
    assert 1.4 < height < 1.9
    parents = [-1] + [names.index(skel.parent[b]) for b in names[1:]]
    for name, lengths in bone_lengths(names, pos, parents).items():
        assert lengths.std() < 1e-9, name
    # The subject walks: the root covers more than two metres.
    assert np.linalg.norm(pos[-1, 0, [0, 2]] - pos[0, 0, [0, 2]]) > 2


def test_bvh_real_clip(mocap):
    clip = bvh.load_bvh(mocap / "cmu/bvh/07_04.bvh.gz")
    assert abs(clip.fps - 120) < 0.01 and clip.motion.shape == (450, 96)
    rots, pos = bvh.global_transforms(clip)
    height = (pos[5, :, 1].max() - pos[5, :, 1].min()) * 0.0254 / 0.45
    assert 1.3 < height < 1.9
    assert np.allclose(rots[5] @ np.swapaxes(rots[5], -1, -2), np.eye(3), atol=1e-9)


def test_plain_and_gzipped_files_read_alike(mocap, tmp_path):
    plain = tmp_path / "16.asf"
    plain.write_text(read_text(mocap / "cmu/asf/16.asf"))
    zipped = tmp_path / "16.asf.gz"
    zipped.write_bytes(gzip.compress(plain.read_bytes()))
    assert read_text(plain) == read_text(zipped)


SMALL_BVH = """HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
  JOINT Knee
  {
    OFFSET 0 -40 0
    CHANNELS 3 Zrotation Yrotation Xrotation
    End Site
    {
      OFFSET 0 -40 0
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.0333333
0 90 0 0 0 0 0 0 0
0 90 0 0 0 0 0 0 90
"""


def test_small_bvh_fk_by_hand():
    clip = bvh.parse_bvh(SMALL_BVH)
    _, pos = bvh.global_transforms(clip)
    assert np.allclose(pos[0, 2], [0, 10, 0])
    # Knee rotated 90 degrees about x: Rx(90) takes the shin (-y) to -z.
    assert np.allclose(pos[1, 2], [0, 50, -40])


BAD_BVH = {
    "empty": ("", "empty"),
    "binary": ("\x00\x01\x02garbage\x00" * 50, "binary"),
    "no hierarchy": ("hello world", "HIERARCHY"),
    "truncated hierarchy": (SMALL_BVH[:120], "truncated"),
    "short frame": (SMALL_BVH.replace("0 90 0 0 0 0 0 0 90", "0 90 0 0 0 0 0 0"), "expected 9 numbers per frame, found 8"),
    "nan": (SMALL_BVH.replace("0 90 0 0 0 0 0 0 90", "0 90 0 0 0 0 0 0 nan"), "non-finite"),
    "word": (SMALL_BVH.replace("0 90 0 0 0 0 0 0 90", "0 90 0 0 0 0 0 0 abc"), "expected a number"),
    "missing frames": (SMALL_BVH.replace("Frames: 2", "Frames: 5"), "declares 5 frames but has 2"),
    "absurd frames": (SMALL_BVH.replace("Frames: 2", "Frames: 99999999999"), "more than this loader accepts"),
    "bad channel": (SMALL_BVH.replace("Xrotation\n  JOINT", "Wrotation\n  JOINT"), "unknown channel"),
}


@pytest.mark.parametrize("case", sorted(BAD_BVH))
def test_bad_bvh_gives_clear_error(case, tmp_path):
    text, expected = BAD_BVH[case]
    path = tmp_path / "bad.bvh"
    path.write_bytes(text.encode("latin-1"))
    with pytest.raises(MotionFormatError) as err:
        bvh.load_bvh(path)
    assert expected in str(err.value)
    assert str(path) in str(err.value)


def test_bvh_error_names_the_line():
    text = SMALL_BVH.replace("0 90 0 0 0 0 0 0 90", "0 90 0 0 0 0 0 0")
    with pytest.raises(MotionFormatError) as err:
        bvh.parse_bvh(text, "x.bvh")
    assert err.value.line == text.splitlines().index("0 90 0 0 0 0 0 0") + 1


@pytest.fixture(scope="module")
def asf16(mocap):
    return read_text(mocap / "cmu/asf/16.asf")


@pytest.fixture(scope="module")
def amc_head(mocap):
    lines = read_text(mocap / "cmu/amc/16_11.amc.gz").splitlines()
    return "\n".join(lines[:lines.index("4")])  # header and three whole frames


def test_amc_errors(asf16, amc_head):
    skel = asf_amc.parse_asf(asf16, "16.asf")
    cases = {
        "unknown bone 'tail'": amc_head.replace("lowerback", "tail", 1),
        "needs 3 values, found 2": amc_head.replace("lowerback 7.0335 -0.381481 0.539966", "lowerback 7.0335 -0.381481", 1),
        "non-finite": amc_head.replace("lowerback 7.0335", "lowerback nan", 1),
        "no frames": ":FULLY-SPECIFIED\n:DEGREES\n",
        "binary": "\x00\x00\x07" * 100,
        "empty": "   \n",
    }
    for expected, text in cases.items():
        with pytest.raises(MotionFormatError) as err:
            asf_amc.parse_amc(text, skel, "x.amc") if expected not in ("binary", "empty") else _read(text)
        assert expected in str(err.value), (expected, str(err.value))


def _read(text):
    from training.mocap.files import decode_text
    return decode_text(text.encode("latin-1"), "x.amc")


def test_truncated_amc_drops_the_incomplete_last_frame(asf16, amc_head):
    skel = asf_amc.parse_asf(asf16)
    full = asf_amc.parse_amc(amc_head, skel)
    cut = asf_amc.parse_amc(amc_head.rsplit("\n", 3)[0], skel)
    assert cut.frames == full.frames - 1


def test_asf_errors(asf16):
    with pytest.raises(MotionFormatError, match="no :bonedata"):
        asf_amc.parse_asf(":version 1.10\n:name VICON\n")
    with pytest.raises(MotionFormatError, match="truncated :bonedata"):
        asf_amc.parse_asf(asf16[: asf16.index("name lfemur") + 20])
    with pytest.raises(MotionFormatError, match="unknown bone"):
        asf_amc.parse_asf(asf16.replace("root lhipjoint", "root lhipjoint wing"))


def test_every_aclstm_dance_file_loads(mocap):
    """The acLSTM dance set (its own standard skeleton, centimetres): every file parses and FK stays sane."""
    files = sorted((mocap / "aclstm").rglob("*.bvh.gz"))
    assert len(files) == 44  # 28 salsa + 7 indian + 8 martial + standard.bvh
    for path in files:
        clip = bvh.load_bvh(path)
        _, pos = bvh.global_transforms(clip)
        assert np.isfinite(pos).all(), path.name
        height = pos[0, :, 1].max() - pos[0, :, 1].min()
        assert 100 < height < 200, (path.name, height)  # centimetres
