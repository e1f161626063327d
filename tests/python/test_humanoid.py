"""The humanoid skeleton mapper (training/mocap/humanoid.py, the twin of web/motion/humanoid.ts): its parity fixture
tests/fixtures/humanoid_map.json is what python -m training.fixtures.humanoid_map writes today, and on the corpus's
skeletons (every CMU BVH, the acLSTM Indian dance BVH, Bandai Namco BVHs, one CMU ASF/AMC clip per subject) each
hip, knee, ankle, toe, shoulder, elbow and wrist, the hips, neck base and head land on the joints so named, left
on the left, but for the misses listed (KNOWN_MISSES); with every name replaced by j<index> too, the sides told by
the pose."""
import json
from pathlib import Path

import numpy as np
import pytest

from training.fixtures.humanoid_map_cases import OUT, build
from training.mocap import asf_amc, bvh
from training.mocap.humanoid import CANONICAL_JOINTS, SkeletonMapError, map_humanoid, side_by_names
from conftest import assert_same_json

# Per skeleton kind, the left side's joint at each point, a function naming the right side's, and the midline.
LIMBS = ("LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase", "LeftArm", "LeftForeArm", "LeftHand")
KINDS = {
    "CMU BVH": (("LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase", "LeftArm", "LeftForeArm", "LeftHand"),
                lambda n: n.replace("Left", "Right"), {"Hips": "Hips", "Neck": "Spine1", "Head": "Head"}),
    "Indian dance BVH": (("LeftHip", "LeftKnee", "LeftAnkle", "LeftToe", "LeftShoulder", "LeftElbow", "LeftWrist"),
                         lambda n: n.replace("Left", "Right"), {"Hips": "Hips", "Neck": "Chest2", "Head": "Head"}),
    "Bandai Namco BVH": (("UpperLeg_L", "LowerLeg_L", "Foot_L", "Toes_L", "UpperArm_L", "LowerArm_L", "Hand_L"),
                         lambda n: n.replace("_L", "_R"), {"Hips": "Hips", "Neck": "Neck", "Head": "Head"}),
    "CMU ASF": (("lhipjoint", "lfemur", "ltibia", "lfoot", "lclavicle", "lhumerus", "lradius"),
                lambda n: "r" + n[1:], {"Hips": "root", "Neck": "thorax", "Head": "upperneck"}),
}
BANDAI_FILES = ["dataset-2_run_active_001", "dataset-2_walk_elderly_003", "dataset-2_walk-turn-left_feminine_010",
                "dataset-2_walk-turn-right_masculine_020", "dataset-2_run_exhausted_030", "dataset-2_walk_youthful_005"]


def test_humanoid_map_fixture_is_current():
    committed = json.loads(OUT.read_text())
    fresh = json.loads(json.dumps(build()))
    assert_same_json(fresh, committed)


def bvh_as_imported(path: Path) -> tuple[list[str], list[int], np.ndarray]:
    """Names, parents and positions of a BVH file's joints as the page's importer keeps them: the root, joints with
    a non-zero OFFSET or position channels of their own, and End Sites (`<joint>_end`); a dropped joint's children
    hang from its nearest kept ancestor."""
    clip = bvh.load_bvh(path)
    _, positions = bvh.global_transforms(clip)
    keep = [i for i, j in enumerate(clip.joints) if j.parent < 0 or np.any(j.offset != 0)
            or any(c.endswith("position") for c in j.channels)]
    kept = {old: new for new, old in enumerate(keep)}
    parents = []
    for i in keep:
        p = clip.joints[i].parent
        while p >= 0 and p not in kept:
            p = clip.joints[p].parent
        parents.append(kept.get(p, -1))
    return [clip.joints[i].name for i in keep], parents, positions[:, keep]


def asf_amc_clip(mocap: Path, amc: str) -> tuple[list[str], list[int], np.ndarray]:
    skel = asf_amc.load_asf(mocap / "cmu" / "asf" / f"{amc.split('_')[0]}.asf")
    names, positions = asf_amc.positions(skel, asf_amc.load_amc(mocap / "cmu" / "amc" / f"{amc}.amc.gz", skel))
    return names, [-1] + [names.index(skel.parent[b]) for b in names[1:]], positions


def corpus_clips(mocap: Path):
    """(what, kind, names, parents, positions) per corpus clip checked."""
    for path in sorted((mocap / "cmu" / "bvh").glob("*.bvh.gz")):
        yield path.name, "CMU BVH", *bvh_as_imported(path)
    yield "94_01 (Indian dance)", "Indian dance BVH", *bvh_as_imported(mocap / "aclstm-extra" / "indian" / "94_01.bvh.gz")
    for name in BANDAI_FILES:
        yield name, "Bandai Namco BVH", *bvh_as_imported(mocap / "bandai" / "bvh" / f"{name}.bvh.gz")
    subjects = sorted({p.name.split("_")[0] for p in (mocap / "cmu" / "amc").glob("*.amc.gz")})
    for subject in subjects:
        first = sorted((mocap / "cmu" / "amc").glob(f"{subject}_*.amc.gz"))[0].name.removesuffix(".amc.gz")
        yield f"{first} (ASF/AMC)", "CMU ASF", *asf_amc_clip(mocap, first)


@pytest.fixture(scope="module")
def clips(mocap):
    out = list(corpus_clips(mocap))
    assert len(out) >= 16 + 1 + len(BANDAI_FILES) + 15
    return out


def wrong_points(kind: str, names: list[str], source: list[int]) -> list[str]:
    """The checked points that are not on the joint so named: 'point=joint found'."""
    left, right_of, midline = KINDS[kind]
    want = dict(zip(LIMBS, left)) | {p.replace("Left", "Right"): right_of(n) for p, n in zip(LIMBS, left)} | midline
    found = {p: names[source[CANONICAL_JOINTS.index(p)]] if source[CANONICAL_JOINTS.index(p)] >= 0 else "-" for p in want}
    return [f"{p}={found[p]}" for p, n in want.items() if found[p] != n]


# The mapper's misses on the corpus today, each a real error (the rest of the points checked are right, and no side is
# ever swapped). Fix them in web/motion/humanoid.ts and here alike, then delete them from this table. Only anonymous
# ASF skeletons remain (an ASF file always names its bones, so a user never meets them):
# - the wrist goes one bone on, to lwrist (2 cm), where the thumb branches off: the mapper takes a joint where several
#   bones start for the likelier wrist, which is right for CMU BVH, Mixamo and the 3ds Max conversion;
# - subject 39's neck base goes one up, to lowerneck: its shoulders stand more than half a shoulder width above the
#   thorax along the torso.
KNOWN_MISSES = {
    "05_01 (ASF/AMC) (anonymous)": "LeftHand=lwrist RightHand=rwrist",
    "06_01 (ASF/AMC) (anonymous)": "RightHand=rwrist",
    "32_01 (ASF/AMC) (anonymous)": "LeftHand=lwrist RightHand=rwrist",
    "38_01 (ASF/AMC) (anonymous)": "LeftHand=lwrist RightHand=rwrist",
    "39_01 (ASF/AMC) (anonymous)": "Neck=lowerneck",
    "43_01 (ASF/AMC) (anonymous)": "LeftHand=lwrist",
    "55_01 (ASF/AMC) (anonymous)": "RightHand=rwrist",
}


def misses(clips, anonymous: bool) -> dict[str, str]:
    """Per clip whose checked points are not all on the joints so named: 'point=joint found' for each, or how its
    sides were told when not as expected (by names; by the pose for anonymous names)."""
    out = {}
    for what, kind, names, parents, positions in clips:
        m = map_humanoid([f"j{j}" for j in range(len(names))] if anonymous else names, parents, positions)
        wrong = wrong_points(kind, names, m.source)
        if m.sides_by != ("pose" if anonymous else "names") or (m.scheme == "") != anonymous:
            wrong.append(f"sides_by={m.sides_by} scheme={m.scheme!r}")
        if wrong:
            out[what + (" (anonymous)" if anonymous else "")] = " ".join(wrong)
    return out


def test_the_corpus_skeletons_map_to_the_joints_so_named(clips):
    known = {k: v for k, v in KNOWN_MISSES.items() if not k.endswith("(anonymous)")}
    assert misses(clips, anonymous=False) == known


def test_anonymous_corpus_skeletons_map_the_same_with_the_sides_by_the_pose(clips):
    """Names are hints only: with j<index> names the points land on the same joints, left still left."""
    known = {k: v for k, v in KNOWN_MISSES.items() if k.endswith("(anonymous)")}
    assert misses(clips, anonymous=True) == known


def test_side_words():
    assert side_by_names("LeftUpLeg", "RightUpLeg") == 1
    assert side_by_names("UpperLeg_R", "UpperLeg_L") == -1
    assert side_by_names("lfemur", "rfemur") == 1
    assert side_by_names("mixamorig:LeftArm", "mixamorig:RightArm") == 1
    assert side_by_names("Bip01 L Thigh", "Bip01 R Thigh") == 1
    assert side_by_names("thigh_l", "thigh_r") == 1
    assert side_by_names("CC_Base_L_Thigh", "CC_Base_R_Thigh") == 1
    assert side_by_names("lThigh", "rThigh") == 1
    assert side_by_names("Leg1", "Leg2") == 0
    assert side_by_names("j3", "j9") == 0
    assert side_by_names("LeftArm", "RightLeg") == 0  # two tokens differ


def test_refuses_what_is_not_a_humanoid_with_a_message():
    chain = np.array([[[0.0, 0.3 * j, 0.0] for j in range(6)]])
    with pytest.raises(SkeletonMapError, match="no two legs"):
        map_humanoid([f"bone{j}" for j in range(6)], [-1, 0, 1, 2, 3, 4], chain)
    with pytest.raises(SkeletonMapError, match="it has 2 joints"):
        map_humanoid(["a", "b"], [-1, 0], chain[:, :2])
    with pytest.raises(ValueError, match=r"positions must be \(frames, 3, 3\)"):
        map_humanoid(["a", "b", "c"], [-1, 0, 1], chain)
    with pytest.raises(ValueError, match=r"joint 1 \(b\) has parent 2: each parent must be listed before its children"):
        map_humanoid(["a", "b", "c"], [-1, 2, 0], chain[:, :3])
    with pytest.raises(ValueError, match="finite"):
        map_humanoid(["a", "b", "c"], [-1, 0, 1], chain[:, :3] * np.nan)
