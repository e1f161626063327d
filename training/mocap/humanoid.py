"""The humanoid skeleton mapper: which joint of any humanoid skeleton is the hips, each spine, neck and head point,
and each point of the arm and leg chains of the canonical skeleton (canonical_skeleton.json).

The Python twin of web/motion/humanoid.ts, step by step: the same constants, naming schemes, loops and tie-breaking
(a later candidate wins only when better by more than 1e-12; medians are sorted[n // 2]; the frames looked at are
rounded half up, as JavaScript's Math.round). tests/fixtures/humanoid_map.json (python -m
training.fixtures.humanoid_map) holds this module's answers for made-up skeletons, and
tests/unit/humanoidParity.test.ts checks that the page gives the same.

It works from the tree and the bone lengths, with the pose only for heights and sides and names only as hints:
  1. the feet: the lowest leaf, and the lowest leaf far from it along the tree (a second leg, not a second toe);
     the legs hang from their lowest common ancestor;
  2. the hands: the two leaves of the upper body farthest apart along the tree (the arm span); the arms hang from
     theirs (the chest);
  3. the hips: the common ancestor of the legs and the chest; the head: where the upper body's remaining leaves meet;
  4. along each limb, from its ancestor to its farthest leaf (the toe or finger tip, not a heel or a twist bone), the
     joints whose bone lengths fit human proportions best: thigh ≈ shin, upper arm ≈ 1.25 × forearm, the foot or
     hand beyond (Winter's segment table), with a joint named as a naming scheme names that point preferred (taken
     outright for the toe base and hand end) and a helper joint (twist, roll, share bones) avoided. Joints of
     (almost) no length count as one point;
  5. the neck base: the joint from the chest up that the naming scheme names so, else the one nearest the
     shoulders; the spine points between;
  6. left and right: from names that differ only by a side word (Left/Right, L/R, _l/_r, lThigh/rThigh …), else
     from the pose: the toes point forward and the left side is at up × forward.
Points a skeleton lacks but that lie between or beyond points it has (extra spine and neck points, toe and hand
tips, the toes of a skeleton without any) are left at -1, for the caller to derive; the rest are required, and a
skeleton without them is refused with a SkeletonMapError naming what is missing.
"""
from __future__ import annotations

import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

# The canonical skeleton's points, in its order (parents: CANONICAL_PARENTS); canonical_skeleton.json's joints.
CANONICAL_JOINTS = [
    "Hips", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase", "LeftToeBase_end",
    "RightUpLeg", "RightLeg", "RightFoot", "RightToeBase", "RightToeBase_end",
    "Spine", "Spine1", "Neck", "Neck1", "Head", "Head_end",
    "LeftArm", "LeftForeArm", "LeftHand", "LeftHand_end",
    "RightArm", "RightForeArm", "RightHand", "RightHand_end",
]
CANONICAL_PARENTS = [-1, 0, 1, 2, 3, 4, 0, 6, 7, 8, 9, 0, 11, 12, 13, 14, 15, 13, 17, 18, 19, 13, 21, 22, 23]


class SkeletonMapError(ValueError):
    """Raised when a skeleton cannot be mapped; the message names what is missing."""


def _sided(left: dict[str, list[str]], words: tuple[str, str]) -> dict[str, list[str]]:
    """Both sides of a scheme from its left-side names: the first `L` in a name becomes the side's word."""
    out: dict[str, list[str]] = {}
    for point, names in left.items():
        out[point] = [n.replace("L", words[0], 1) for n in names]
        out[point.replace("Left", "Right", 1)] = [n.replace("L", words[1], 1) for n in names]
    return out


@dataclass(frozen=True)
class Scheme:
    """Per canonical point, the (normalised, see normalise_name) joint names found there, best first."""
    name: str
    points: dict[str, list[str]]


# Naming schemes: hints only. A skeleton's names are matched against each scheme on its own (names clash across
# schemes: ASF's "lfoot" is the toe base, a Biped's "L Foot" the ankle), and the scheme that places the most points
# gives the hints.
NAME_SCHEMES: list[Scheme] = [
    Scheme("CMU ASF", {
        "Hips": ["root"], "Spine": ["lowerback"], "Spine1": ["upperback"], "Neck": ["thorax"], "Neck1": ["lowerneck"],
        "Head": ["upperneck"], "Head_end": ["head"],
        **_sided({"LeftUpLeg": ["Lhipjoint"], "LeftLeg": ["Lfemur"], "LeftFoot": ["Ltibia"], "LeftToeBase": ["Lfoot"],
                  "LeftToeBase_end": ["Ltoes"], "LeftArm": ["Lclavicle"], "LeftForeArm": ["Lhumerus"],
                  "LeftHand": ["Lradius"], "LeftHand_end": ["Lwrist"]}, ("l", "r")),
    }),
    Scheme("CMU BVH", {
        "Hips": ["hips"], "Spine": ["spine"], "Spine1": ["spine1"], "Neck": ["neck"], "Neck1": ["neck1"],
        "Head": ["head"], "Head_end": ["headend"],
        **_sided({"LeftUpLeg": ["Lupleg"], "LeftLeg": ["Lleg"], "LeftFoot": ["Lfoot"], "LeftToeBase": ["Ltoebase"],
                  "LeftToeBase_end": ["Ltoebaseend"], "LeftArm": ["Larm"], "LeftForeArm": ["Lforearm"],
                  "LeftHand": ["Lhand"], "LeftHand_end": ["Lfingerbase", "Lhandend"]}, ("left", "right")),
    }),
    Scheme("CMU BVH (3ds Max)", {
        "Hips": ["hips"], "Spine": ["chest"], "Spine1": ["chest2"], "Neck": ["lowerneck"], "Neck1": ["neck"],
        "Head": ["head"], "Head_end": ["headend"],
        **_sided({"LeftUpLeg": ["Lhip"], "LeftLeg": ["Lknee"], "LeftFoot": ["Lankle"], "LeftToeBase": ["Ltoe"],
                  "LeftToeBase_end": ["Ltoeend"], "LeftArm": ["Lshoulder"], "LeftForeArm": ["Lelbow"],
                  "LeftHand": ["Lwrist"], "LeftHand_end": ["Lfingers"]}, ("left", "right")),
    }),
    Scheme("Mixamo", {
        "Hips": ["hips"], "Spine": ["spine1"], "Spine1": ["spine2"], "Neck": ["neck"], "Head": ["head"],
        "Head_end": ["headtopend"],
        **_sided({"LeftUpLeg": ["Lupleg"], "LeftLeg": ["Lleg"], "LeftFoot": ["Lfoot"], "LeftToeBase": ["Ltoebase"],
                  "LeftToeBase_end": ["Ltoeend"], "LeftArm": ["Larm"], "LeftForeArm": ["Lforearm"],
                  "LeftHand": ["Lhand"], "LeftHand_end": ["Lhandmiddle1"]}, ("left", "right")),
    }),
    Scheme("3ds Max Biped", {
        "Hips": ["pelvis", ""], "Spine": ["spine1", "spine"], "Spine1": ["spine2"], "Neck": ["neck"], "Head": ["head"],
        "Head_end": ["headnub"],
        **_sided({"LeftUpLeg": ["Lthigh"], "LeftLeg": ["Lcalf"], "LeftFoot": ["Lfoot"], "LeftToeBase": ["Ltoe0"],
                  "LeftToeBase_end": ["Ltoe0nub"], "LeftArm": ["Lupperarm"], "LeftForeArm": ["Lforearm"],
                  "LeftHand": ["Lhand"], "LeftHand_end": ["Lfinger2", "Lfinger1"]}, ("l", "r")),
    }),
    Scheme("Daz", {
        "Hips": ["hip", "pelvis"], "Spine": ["abdomenlower", "abdomen"], "Spine1": ["chestlower", "chest"],
        "Neck": ["necklower", "neck"], "Neck1": ["neckupper"], "Head": ["head"],
        **_sided({"LeftUpLeg": ["Lthighbend", "Lthigh"], "LeftLeg": ["Lshin"], "LeftFoot": ["Lfoot"],
                  "LeftToeBase": ["Ltoe", "Lmetatarsals"], "LeftArm": ["Lshldrbend", "Lshldr"],
                  "LeftForeArm": ["Lforearmbend", "Lforearm"], "LeftHand": ["Lhand"], "LeftHand_end": ["Lmid1"]},
                 ("l", "r")),
    }),
    Scheme("Unreal", {
        "Hips": ["pelvis"], "Spine": ["spine01"], "Spine1": ["spine02", "spine03"], "Neck": ["neck01"],
        "Neck1": ["neck02"], "Head": ["head"], "Head_end": ["headleaf", "headend"],
        **_sided({"LeftUpLeg": ["thighL"], "LeftLeg": ["calfL"], "LeftFoot": ["footL"], "LeftToeBase": ["ballL"],
                  "LeftToeBase_end": ["ballleafL", "ballendL"], "LeftArm": ["upperarmL"],
                  "LeftForeArm": ["lowerarmL"], "LeftHand": ["handL"], "LeftHand_end": ["middle02L", "middle01L"]},
                 ("l", "r")),
    }),
    Scheme("VRM", {
        "Hips": ["hips"], "Spine": ["spine"], "Spine1": ["chest"], "Neck": ["neck"], "Head": ["head"],
        **_sided({"LeftUpLeg": ["Lupperleg"], "LeftLeg": ["Llowerleg"], "LeftFoot": ["Lfoot"], "LeftToeBase": ["Ltoes"],
                  "LeftArm": ["Lupperarm"], "LeftForeArm": ["Llowerarm"], "LeftHand": ["Lhand"],
                  "LeftHand_end": ["Lmiddleintermediate", "Lmiddleproximal"]}, ("left", "right")),
    }),
    Scheme("Bandai Namco", {
        "Hips": ["hips"], "Spine": ["spine"], "Spine1": ["chest"], "Neck": ["neck"], "Head": ["head"],
        **_sided({"LeftUpLeg": ["upperlegL"], "LeftLeg": ["lowerlegL"], "LeftFoot": ["footL"], "LeftToeBase": ["toesL"],
                  "LeftArm": ["upperarmL"], "LeftForeArm": ["lowerarmL"], "LeftHand": ["handL"]}, ("l", "r")),
    }),
    Scheme("iClone", {
        "Hips": ["ccbasehip"], "Spine": ["ccbasewaist"], "Spine1": ["ccbasespine01", "ccbasespine02"],
        "Neck": ["ccbasenecktwist01"], "Neck1": ["ccbasenecktwist02"], "Head": ["ccbasehead"],
        **_sided({"LeftUpLeg": ["ccbaseLthigh"], "LeftLeg": ["ccbaseLcalf"], "LeftFoot": ["ccbaseLfoot"],
                  "LeftToeBase": ["ccbaseLtoebase"], "LeftArm": ["ccbaseLupperarm"], "LeftForeArm": ["ccbaseLforearm"],
                  "LeftHand": ["ccbaseLhand"], "LeftHand_end": ["ccbaseLmid2", "ccbaseLmid1"]}, ("l", "r")),
    }),
]

_BIPED_PREFIX = re.compile(r"^bip0*1(?=$|[\s_.-])")
_SEPARATORS = re.compile(r"[\s_.-]")


def normalise_name(name: str) -> str:
    """A joint name without namespace (`mixamorig:`), Biped prefix (`Bip01 `), case, spaces, `_`, `-` or `.`."""
    bare = _BIPED_PREFIX.sub("", name[name.rfind(":") + 1:].lower(), count=1)
    return _SEPARATORS.sub("", bare)


def match_schemes(joints: Sequence[str]) -> list[tuple[str, list[int]]]:
    """Per naming scheme (NAME_SCHEMES order), its name and the joint it places at each canonical point
    (CANONICAL_JOINTS order; -1: none)."""
    index: dict[str, int] = {}
    for j, name in enumerate(joints):
        index.setdefault(normalise_name(name), j)
    out = []
    for scheme in NAME_SCHEMES:
        source = []
        for point in CANONICAL_JOINTS:
            source.append(next((index[n] for n in scheme.points.get(point, []) if n in index), -1))
        out.append((scheme.name, source))
    return out


@dataclass(frozen=True)
class HumanoidMap:
    """Where a humanoid's canonical points are."""
    source: list[int]  # per canonical point (CANONICAL_JOINTS order): the joint there, or -1 where it is derived
    scheme: str  # the naming scheme whose names gave the hints ('' when none matched more than a few points)
    facing: tuple[float, float]  # which way the figure faces (unit, on the ground: x, z), from the toes, else the knees
    sides_by: str  # 'names' (names that differ only in a side word) or 'pose'
    height: float  # the figure's tallest extent over the frames looked at, in the skeleton's units


# Frames looked at: up to this many, evenly spread.
SAMPLED_FRAMES = 48
# A bone shorter than this share of the figure's height counts as no bone (helper and zero-length joints).
COINCIDENT = 0.003
# Human proportions (Winter, Biomechanics and Motor Control of Human Movement, segment lengths ÷ height).
UPPER_ARM_TO_FOREARM = 0.186 / 0.146
# Upper arm ÷ forearm ratios found in real skeletons: from about 1.0 (Bandai Namco) to 2.2 (CMU subjects whose radius
# is short); within this range the ratio costs only a tie-breaking WEAK share of its squared log distance from
# Winter's, outside it the full squared log distance to the range.
UPPER_ARM_RANGE = (0.95, 2.3)
WEAK = 0.1
HAND_TO_FOREARM = 0.7
FOOT_TO_LEG = 0.26
# Costs (squared log ratios): a limb without a foot or hand beyond; a joint the naming scheme names for the point
# (enough to outweigh any proportion: names are hints, but a scheme that matched is rarely wrong); a helper joint.
NO_FOOT = 0.15
NO_HAND = 0.1
# A wrist candidate where several bones start (thumb and fingers) gains this much (CMU's short hands).
BRANCHING_WRIST = NO_HAND / 2
NAME_HINT = 1.0
HELPER = 0.2
# How much longer (log ratio) a foot or hand may be than the proportion at no cost. Shorter costs nothing: rigs cut
# hands at the palm and feet at the ball (CMU's hands are a fifth of the forearm).
EXTREMITY_SLACK = 0.7
# How far (half shoulder widths) the shoulders may stand above the neck base along the torso.
NECK_BELOW = 0.5
HELPER_NAME = re.compile(r"twist|roll|share|helper|corrective|jiggle|adjust|pole|target|ctrl|control", re.IGNORECASE)
# Inverse-kinematics bones (Unreal's ik_foot_l, ik_hand_gun …): targets at a hand's or foot's place, not limbs.
IK_NAME = re.compile(r"(^|[^a-z])ik([^a-z]|$)", re.IGNORECASE)
# A later candidate replaces the best so far only when better by more than this (the page's rule, for equal ties).
TIE = 1e-12

Point = tuple[float, float, float]


def _js_round(x: float) -> int:
    """JavaScript's Math.round: halves round up (Python's round() rounds them to even)."""
    up = math.ceil(x)
    return up - 1 if up - 0.5 > x else up


def _sampled(frames: int) -> list[int]:
    n = min(frames, SAMPLED_FRAMES)
    return [_js_round(i * (frames - 1) / max(1, n - 1)) for i in range(n)]


def _median(values: list[float]) -> float:
    s = sorted(values)
    return s[len(s) // 2] if s else 0.0


def _dist(a: Point, b: Point) -> float:
    return math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _sq(x: float) -> float:
    return x * x


def _slack(x: float) -> float:
    return _sq(max(0.0, x - EXTREMITY_SLACK))


class _Tree:
    """The skeleton's tree with median bone lengths, arc lengths from the root and mean heights over the frames looked at."""

    def __init__(self, parents: Sequence[int], positions: np.ndarray):
        J = len(parents)
        self.parents = list(parents)
        self.frames = _sampled(positions.shape[0])
        # Only the frames looked at, as Python floats: the page's operations in its order (hypot and log may differ
        # from the page's in the last bit, far below the 1e-12 that decides a tie).
        self.pose: dict[int, list[Point]] = {f: [tuple(p) for p in positions[f].tolist()] for f in self.frames}
        self.children: list[list[int]] = [[] for _ in range(J)]
        for j, p in enumerate(self.parents):
            if p >= 0:
                self.children[p].append(j)
        self.depth = [0] * J
        self.bone = [0.0] * J  # median bone length (to the parent), per joint
        self.arc = [0.0] * J  # arc length from the root along the bones
        self.lift = [0.0] * J  # mean height above the frame's lowest joint
        for j in range(J):
            p = self.parents[j]
            if p < 0:
                continue
            self.depth[j] = self.depth[p] + 1
            self.bone[j] = _median([_dist(self.at(f, j), self.at(f, p)) for f in self.frames])
            self.arc[j] = self.arc[p] + self.bone[j]
        heights = []
        for f in self.frames:
            ys = [q[1] for q in self.pose[f]]
            lo, hi = min(ys), max(ys)
            heights.append(hi - lo)
            for j in range(J):
                self.lift[j] += (ys[j] - lo) / len(self.frames)
        self.height = max(heights)

    def at(self, f: int, j: int) -> Point:
        return self.pose[f][j]

    def lca(self, a: int, b: int) -> int:
        """The lowest common ancestor; -1 for joints of separate trees (a skeleton with several roots)."""
        while self.depth[a] > self.depth[b]:
            a = self.parents[a]
        while self.depth[b] > self.depth[a]:
            b = self.parents[b]
        while a != b:
            a, b = self.parents[a], self.parents[b]
        return a

    def tree_distance(self, a: int, b: int) -> float:
        """Along the bones; NaN between separate trees (as the page's arithmetic on a missing ancestor gives), so
        that no comparison picks such a pair."""
        c = self.lca(a, b)
        return self.arc[a] + self.arc[b] - 2 * self.arc[c] if c >= 0 else math.nan

    def is_below(self, j: int, ancestor: int) -> bool:
        k = j
        while k >= 0:
            if k == ancestor:
                return True
            k = self.parents[k]
        return False

    def path_down(self, top: int, bottom: int) -> list[int]:
        """The joints from `top` (excluded) down to `bottom` (included), top first."""
        out = []
        k = bottom
        while k != top and k >= 0:
            out.append(k)
            k = self.parents[k]
        return out[::-1]

    def child_toward(self, ancestor: int, j: int) -> int:
        """The child of `ancestor` on the way down to `j`."""
        k = j
        while self.parents[k] != ancestor:
            k = self.parents[k]
        return k

    def leaves_under(self, j: int) -> list[int]:
        """In the page's order: depth first, the last child first."""
        out = []
        stack = [j]
        while stack:
            k = stack.pop()
            if not self.children[k]:
                out.append(k)
            else:
                stack.extend(self.children[k])
        return out

    def farthest_leaf(self, root: int, start: int) -> int:
        """The leaf under `root` (inclusive) farthest along the tree from `start`: a toe or finger tip."""
        leaves = self.leaves_under(root)
        best = leaves[0]
        for b in leaves[1:]:
            if self.arc[b] - self.arc[start] > self.arc[best] - self.arc[start] + TIE:
                best = b
        return best


def _nearest(candidates: list[int], cost: Callable[[int], float]) -> int:
    best = candidates[0]
    for j in candidates:
        if cost(j) < cost(best) - TIE:
            best = j
    return best


def _limb_points(t: _Tree, top: int, tip: int, names: Sequence[str], named_any: Callable[[int], bool]) -> list[int]:
    """A limb's distinct points from `top` (excluded) to `tip`: runs of joints of (almost) no length count as one
    point, represented by a joint the naming scheme names (CMU's LeftHand, not the LeftFingerBase at its place), else
    the deepest joint that is not a helper; points at the top's own place are dropped."""
    eps = COINCIDENT * t.height
    groups: list[list[int]] = []
    for j in t.path_down(top, tip):
        if t.arc[j] - t.arc[top] < eps:
            continue
        if groups and t.bone[j] < eps:
            groups[-1].append(j)
        else:
            groups.append([j])
    return [next((j for j in g if named_any(j)), None)
            if any(named_any(j) for j in g) else next((j for j in reversed(g) if not HELPER_NAME.search(names[j])), g[-1])
            for g in groups]


class _Hints:
    """The naming scheme that places the most points (when it places at least 6), whether it names joint j as a
    point, and the cost of a name for a point: a scheme's name for it lowers it, a helper's name raises it."""

    def __init__(self, names: Sequence[str]):
        self.names = names
        best_scheme, best_source, best_placed = "", [], 0
        for scheme, source in match_schemes(names):
            placed = sum(1 for j in source if j >= 0)
            if placed > best_placed:
                best_scheme, best_source, best_placed = scheme, source, placed
        self.useful = best_placed >= 6
        self.source = best_source
        self.scheme = best_scheme if self.useful else ""

    def named(self, j: int, point: str) -> bool:
        return self.useful and self.source[CANONICAL_JOINTS.index(point)] == j

    def named_any(self, j: int) -> bool:
        return self.useful and j in self.source

    def hint(self, j: int, point: str) -> float:
        return (-NAME_HINT if self.named(j, point) else 0.0) + (HELPER if HELPER_NAME.search(self.names[j]) else 0.0)


def _named_or_nearest(candidates: list[int], hints: _Hints, point: str, cost: Callable[[int], float]) -> int:
    """The first candidate the naming scheme names as `point`, else the one of least cost."""
    named = next((j for j in candidates if hints.named(j, point)), None)
    return named if named is not None else _nearest(candidates, cost)


def _fit_leg(t: _Tree, pelvis: int, leg_root: int, hints: _Hints, side: str, names: Sequence[str]) -> dict[str, int] | None:
    """A leg's points (socket, knee, ankle, toe base?, toe end?) below `pelvis` down to its farthest leaf."""
    tip = t.farthest_leaf(leg_root, pelvis)
    pts = _limb_points(t, pelvis, tip, names, hints.named_any)
    if len(pts) < 3:
        return None

    def arc(a: int, b: int) -> float:
        return t.arc[b] - t.arc[a]

    hint = hints.hint
    # The hip socket: the first point below the legs' branch, or a later one the naming scheme names so (the Daz
    # skeleton of the acLSTM set has a buttock joint above its thigh).
    socket_at = next((i for i, j in enumerate(pts) if i < len(pts) - 2 and hints.named(j, f"{side}UpLeg")), 0)
    socket = pts[socket_at]
    best: tuple[float, int, int] | None = None  # cost, knee, ankle
    for i in range(socket_at + 1, len(pts) - 1):
        for k in range(i + 1, len(pts)):
            thigh, shin = arc(socket, pts[i]), arc(pts[i], pts[k])
            foot = arc(pts[k], tip)
            cost = _sq(math.log(thigh / shin)) + (
                NO_FOOT if k == len(pts) - 1 else _slack(math.log(foot / (FOOT_TO_LEG * (thigh + shin)))))
            cost += hint(socket, f"{side}UpLeg") + hint(pts[i], f"{side}Leg") + hint(pts[k], f"{side}Foot")
            if best is None or cost < best[0] - TIE:
                best = (cost, i, k)
    if best is None:
        return None
    _, knee, ankle_at = best
    toes = pts[ankle_at + 1:]
    ankle = pts[ankle_at]
    toe_base, toe_end = -1, -1
    if len(toes) == 1:
        toe_base = toes[0]
    elif len(toes) > 1:
        toe_end = toes[-1]
        want = (2 / 3) * arc(ankle, toe_end)
        candidates = toes[:-1]
        toe_base = _named_or_nearest(candidates, hints, f"{side}ToeBase", lambda j: abs(arc(ankle, j) - want))
    return {"UpLeg": socket, "Leg": pts[knee], "Foot": ankle, "ToeBase": toe_base, "ToeBase_end": toe_end}


def _fit_arm(t: _Tree, chest: int, arm_root: int, hints: _Hints, side: str, names: Sequence[str]) -> dict[str, int] | None:
    """An arm's points (shoulder, elbow, wrist, hand end?) below `chest` down to its farthest leaf."""
    tip = t.farthest_leaf(arm_root, chest)
    pts = _limb_points(t, chest, tip, names, hints.named_any)
    if len(pts) < 3:
        return None

    def arc(a: int, b: int) -> float:
        return t.arc[b] - t.arc[a]

    hint = hints.hint
    best: tuple[float, int, int, int] | None = None  # cost, shoulder, elbow, wrist
    for s in range(len(pts) - 2):
        for e in range(s + 1, len(pts) - 1):
            for w in range(e + 1, len(pts)):
                upper, fore = arc(pts[s], pts[e]), arc(pts[e], pts[w])
                hand = arc(pts[w], tip)
                clavicle = t.arc[pts[s]] - t.arc[chest]
                ratio = upper / fore
                cost = WEAK * _sq(math.log(ratio / UPPER_ARM_TO_FOREARM)) + _sq(
                    math.log(max(1.0, UPPER_ARM_RANGE[0] / ratio, ratio / UPPER_ARM_RANGE[1])))
                # The hand: a wrist with nothing beyond costs NO_HAND; a hand much longer than the forearm allows
                # costs fully, any other length weakly against the typical one, and never as much as no hand at all.
                cost += NO_HAND if w == len(pts) - 1 else (
                    _slack(math.log(hand / (HAND_TO_FOREARM * fore)))
                    + min(WEAK * _sq(math.log(hand / (HAND_TO_FOREARM * fore))), NO_HAND / 2))
                # A wrist is where the thumb and fingers part: a joint with several children is the likelier wrist.
                if len(t.children[pts[w]]) >= 2:
                    cost -= BRANCHING_WRIST
                # From the chest's branch to the shoulder is about a forearm long (the canonical clavicle); weakly.
                cost += WEAK * _sq(math.log(max(clavicle, 1e-9 * t.height) / fore))
                if clavicle > upper:
                    cost += _sq(math.log(clavicle / upper))
                cost += hint(pts[s], f"{side}Arm") + hint(pts[e], f"{side}ForeArm") + hint(pts[w], f"{side}Hand")
                if best is None or cost < best[0] - TIE:
                    best = (cost, s, e, w)
    if best is None:
        return None
    _, s, e, w = best
    wrist = pts[w]
    fore = arc(pts[e], wrist)
    beyond = pts[w + 1:]
    hand_end = _named_or_nearest(beyond, hints, f"{side}Hand_end", lambda j: abs(arc(wrist, j) - HAND_TO_FOREARM * fore)) \
        if beyond else -1
    return {"Arm": pts[s], "ForeArm": pts[e], "Hand": wrist, "Hand_end": hand_end}


# Words that name a side, as a name's whole token or its first letter glued to the rest (lThigh, lfemur).
LEFT_WORDS = {"l", "left"}
RIGHT_WORDS = {"r", "right"}
_LOWER_THEN_UPPER = re.compile(r"([a-z0-9])([A-Z])")
_UPPER_THEN_WORD = re.compile(r"([A-Z])([A-Z][a-z])")
_TOKEN_SEPARATORS = re.compile(r"[\s_.\-:]+")


def _tokens(name: str) -> list[str]:
    spaced = _UPPER_THEN_WORD.sub(r"\1 \2", _LOWER_THEN_UPPER.sub(r"\1 \2", name[name.rfind(":") + 1:]))
    return [w for w in _TOKEN_SEPARATORS.split(spaced.lower()) if w]


def side_by_names(a: str, b: str) -> int:
    """+1 when `a` is named the left and `b` the right of one joint, -1 the other way round, 0 when the names don't tell."""
    ta, tb = _tokens(a), _tokens(b)
    if len(ta) != len(tb):
        return 0
    diff = [i for i, (x, y) in enumerate(zip(ta, tb)) if x != y]
    if len(diff) != 1:
        return 0
    x, y = ta[diff[0]], tb[diff[0]]
    # One token differing by its first letter only: "lfemur" / "rfemur", "lthigh" / "rthigh".
    if len(x) > 1 and len(y) > 1 and x[1:] == y[1:]:
        x, y = x[0], y[0]
    if x in LEFT_WORDS and y in RIGHT_WORDS:
        return 1
    if x in RIGHT_WORDS and y in LEFT_WORDS:
        return -1
    return 0


def _facing_of(t: _Tree, legs: list[dict[str, int]]) -> tuple[float, float]:
    """The figure's facing (unit, x z) over the frames: where the toes point from the ankles, else the knees bend."""
    x = z = 0.0
    for f in t.frames:
        for leg in legs:
            ankle = t.at(f, leg["Foot"])
            if leg["ToeBase"] >= 0:
                toe = t.at(f, leg["ToeBase"])
                x += toe[0] - ankle[0]
                z += toe[2] - ankle[2]
            else:
                # Knees bend forward: the knee lies ahead of the hip-to-ankle line.
                hip, knee = t.at(f, leg["UpLeg"]), t.at(f, leg["Leg"])
                x += knee[0] - (hip[0] + ankle[0]) / 2
                z += knee[2] - (hip[2] + ankle[2]) / 2
    n = math.hypot(x, z)
    return (x / n, z / n) if n > 1e-9 * t.height else (0.0, 1.0)


def _left_of(t: _Tree, a: int, b: int, facing: tuple[float, float]) -> float:
    """Summed over the frames: how far joint `a` lies left of joint `b` (facing `facing`; left = up × forward)."""
    s = 0.0
    for f in t.frames:
        pa, pb = t.at(f, a), t.at(f, b)
        s += (pa[0] - pb[0]) * facing[1] - (pa[2] - pb[2]) * facing[0]
    return s


def _refuse(missing: str) -> SkeletonMapError:
    return SkeletonMapError(f"this skeleton is not a humanoid the playground can map: {missing}")


def _main_tree_root(t: _Tree) -> int:
    """The root of the tree with the most bone length (a file may hold props or a second figure beside the body)."""
    total = [0.0] * len(t.parents)
    for j in range(len(t.parents) - 1, -1, -1):
        if t.parents[j] >= 0:
            total[t.parents[j]] += total[j] + t.bone[j]
    best = -1
    for j, p in enumerate(t.parents):
        if p < 0 and (best < 0 or total[j] > total[best] + TIE):
            best = j
    return best


def map_humanoid(joints: Sequence[str], parents: Sequence[int], positions: np.ndarray) -> HumanoidMap:
    """The canonical points of a humanoid skeleton: `joints` (names), `parents` (-1 for a root, each parent listed
    before its children; joints of a second tree are never taken for a limb's) and world `positions` (frames, joints,
    3), any unit, y up. Raises a SkeletonMapError naming what is missing for a skeleton without two legs, two arms or
    a head, a ValueError for inconsistent input."""
    positions = np.asarray(positions, dtype=np.float64)
    J = len(joints)
    if len(parents) != J or positions.ndim != 3 or positions.shape[1:] != (J, 3):
        raise ValueError(f"positions must be (frames, {J}, 3) for {J} joints and {len(parents)} parents, "
                         f"found {positions.shape}")
    # The page walks the joints in order and needs each parent before its children, as every reader lists them.
    misplaced = next((j for j, p in enumerate(parents) if not -1 <= p < j), None)
    if misplaced is not None:
        raise ValueError(f"joint {misplaced} ({joints[misplaced]}) has parent {parents[misplaced]}: each parent must "
                         "be listed before its children (or be -1 for a root)")
    if not np.isfinite(positions).all():
        raise ValueError("positions must be finite numbers")
    if J < 3 or positions.shape[0] < 1:
        raise _refuse(f"it has {J} joint{'' if J == 1 else 's'}, not legs, arms and a head")
    t = _Tree(parents, positions)
    if not t.height > 0:
        raise _refuse("its joints all lie at one height, so no legs can be told")
    names = joints
    hints = _Hints(names)
    named = hints.named
    # Extremities are leaves of the main tree (the one with the most bone length: a prop beside the figure is not a
    # foot), neither helpers themselves (a twist bone's end) nor below an IK bone (an IK hand sits where the hand is;
    # a helper inside a limb, such as an inline twist bone, leaves the limb's end an extremity).
    main_root = _main_tree_root(t)
    below_ik = [False] * J
    for j in range(J):
        below_ik[j] = bool(IK_NAME.search(names[j])) or (parents[j] >= 0 and below_ik[parents[j]])
    leaves = [j for j, c in enumerate(t.children)
              if not c and not below_ik[j] and not HELPER_NAME.search(names[j]) and t.is_below(j, main_root)]
    if not leaves:
        raise _refuse("no two legs (no second foot near the floor)")

    def lowest(candidates: list[int]) -> int:
        best = candidates[0]
        for b in candidates[1:]:
            if t.lift[b] < t.lift[best] - TIE:
                best = b
        return best

    # 1. Feet: the lowest leaf, and the lowest leaf a leg's length away along the tree.
    foot_a = lowest(leaves)
    others = [l for l in leaves if t.tree_distance(foot_a, l) > 0.5 * t.height and t.lift[l] < 0.3 * t.height]
    if not others:
        raise _refuse("no two legs (no second foot near the floor)")
    foot_b = lowest(others)
    pelvis = t.lca(foot_a, foot_b)
    leg_roots = [t.child_toward(pelvis, foot_a), t.child_toward(pelvis, foot_b)]

    def in_legs(j: int) -> bool:
        return any(t.is_below(j, r) for r in leg_roots)

    # 2. Hands: the two leaves of the rest of the body farthest apart along the tree.
    upper = [l for l in leaves if not in_legs(l)]
    hands: tuple[int, int] | None = None
    span = 0.0
    for i in range(len(upper)):
        for k in range(i + 1, len(upper)):
            d = t.tree_distance(upper[i], upper[k])
            if d > span + TIE:
                span, hands = d, (upper[i], upper[k])
    if hands is None or span < 0.5 * t.height:
        raise _refuse("no two arms (no two hands an arm span apart)")
    chest = t.lca(hands[0], hands[1])
    if in_legs(chest):
        raise _refuse("no two arms (the hands found hang from a leg)")
    arm_roots = [t.child_toward(chest, hands[0]), t.child_toward(chest, hands[1])]

    def in_arms(j: int) -> bool:
        return any(t.is_below(j, r) for r in arm_roots)

    # 3. Head: where the remaining leaves of the upper body meet, above the chest.
    # Leaves above the chest on average; when none is (a dancer bowing through the frames looked at), any beside the arms.
    beside_arms = [l for l in upper if not in_arms(l) and t.is_below(l, chest) and l != chest]
    raised = [l for l in beside_arms if t.lift[l] > t.lift[chest]]
    head_leaves = raised or beside_arms
    if not head_leaves:
        raise _refuse("no head (nothing above the shoulders)")
    skull = head_leaves[0]
    for l in head_leaves[1:]:
        skull = t.lca(skull, l)
    head_end = -1
    if not t.children[skull]:
        # One chain: its last bone is a head-top end when named so, or when long against the neck and not named the
        # head; else the leaf is the head joint itself.
        parent = t.parents[skull]
        long = t.bone[skull] >= 0.3 * (t.arc[skull] - t.arc[chest])
        if parent != chest and (named(skull, "Head_end") or (long and not named(skull, "Head"))):
            head_end, skull = skull, parent
    top = t.lca(pelvis, chest)
    hips = top if abs(t.lift[top] - t.lift[pelvis]) <= 0.1 * t.height else pelvis
    # A joint the scheme names the hips, above the one found and near it (a Biped's thighs hang from its spine).
    k = hips
    while k >= 0:
        if named(k, "Hips") and abs(t.lift[k] - t.lift[hips]) <= 0.15 * t.height:
            hips = k
            break
        k = t.parents[k]

    # 4. Limbs, sides still unknown (A, B).
    legs = [_fit_leg(t, pelvis, r, hints, "Left", names) for r in leg_roots]
    legs_other = [_fit_leg(t, pelvis, r, hints, "Right", names) for r in leg_roots]
    if legs[0] is None or legs[1] is None:
        which = "knees or ankles" if legs[0] is None and legs[1] is None else "knee or ankle on one leg"
        raise _refuse(f"no {which} (a leg needs a hip, knee and ankle joint)")
    arms = [_fit_arm(t, chest, r, hints, "Left", names) for r in arm_roots]
    arms_other = [_fit_arm(t, chest, r, hints, "Right", names) for r in arm_roots]
    if arms[0] is None or arms[1] is None:
        raise _refuse("no elbow or wrist on an arm (an arm needs a shoulder, elbow and wrist joint)")

    # 6. Sides: names first, else the pose. Each limb is fitted again with the other side's hints when it is the right.
    facing = _facing_of(t, legs)

    def vote(a: dict[str, int], b: dict[str, int]) -> int:
        return sum(side_by_names(names[a[k]], names[b[k]]) for k in a if a[k] >= 0 and b[k] >= 0)

    leg_vote, arm_vote = vote(legs[0], legs[1]), vote(arms[0], arms[1])
    sides_by = "names" if leg_vote != 0 and arm_vote != 0 else "pose"
    leg_a_is_left = leg_vote > 0 if leg_vote != 0 else _left_of(t, legs[0]["UpLeg"], legs[1]["UpLeg"], facing) > 0
    arm_a_is_left = arm_vote > 0 if arm_vote != 0 else _left_of(t, arms[0]["Arm"], arms[1]["Arm"], facing) > 0
    left = {"leg": legs[0] if leg_a_is_left else legs[1], "arm": arms[0] if arm_a_is_left else arms[1]}
    right = {"leg": legs_other[1] if leg_a_is_left else legs_other[0],
             "arm": arms_other[1] if arm_a_is_left else arms_other[0]}

    # 5. The neck base: the joint from the chest up that the naming scheme names so; else the first one (from the
    # chest's branch up) that the shoulders do not stand well above: the shoulders' midpoint at most NECK_BELOW half
    # shoulder widths above it along the torso (hips → head). CMU's thorax lies 0.3–0.45 below its shoulders and its
    # next neck joint 0.1–0.16 above them; Bandai's chest 1.3 below, its neck 0.36 above.
    shoulders = [left["arm"]["Arm"], right["arm"]["Arm"]]
    neck_path = [chest] + [j for j in t.path_down(chest, skull) if j != skull]

    def shoulders_above(j: int) -> float:
        values = []
        for f in t.frames:
            hips_at, head_at, l, r, at = t.at(f, hips), t.at(f, skull), t.at(f, shoulders[0]), t.at(f, shoulders[1]), t.at(f, j)
            up = [head_at[a] - hips_at[a] for a in range(3)]
            n = math.hypot(up[0], up[1], up[2]) or 1.0
            rise = 0.0
            for a in range(3):
                rise += ((l[a] + r[a]) / 2 - at[a]) * (up[a] / n)
            values.append(rise / (_dist(l, r) / 2 or 1.0))
        return _median(values)

    unnamed_else = [j for j in neck_path if not named(j, "Neck1") and not named(j, "Head")]
    neck = next((j for j in neck_path if named(j, "Neck")), None)
    if neck is None:
        neck = next((j for j in unnamed_else if shoulders_above(j) <= NECK_BELOW), None)
    if neck is None:
        neck = unnamed_else[-1] if unnamed_else else chest

    source = [-1] * len(CANONICAL_JOINTS)

    def put(point: str, j: int) -> None:
        source[CANONICAL_JOINTS.index(point)] = j

    put("Hips", hips)
    for side, limbs in (("Left", left), ("Right", right)):
        for k, j in limbs["leg"].items():
            put(f"{side}{k}", j)
        for k, j in limbs["arm"].items():
            put(f"{side}{k}", j)
    put("Neck", neck)
    put("Head", skull)
    put("Head_end", head_end)

    # Spine points between the hips and the neck base, and Neck1 between the neck base and the head, by arc fraction.
    # A joint the naming scheme names for the point is taken first.
    def by_fraction(start: int, end: int, points: list[tuple[str, float]], window: float) -> None:
        candidates = [j for j in t.path_down(start, end) if j != end and t.bone[j] >= COINCIDENT * t.height]
        total = t.arc[end] - t.arc[start]
        taken: set[int] = set()

        def fraction(j: int) -> float:
            return (t.arc[j] - t.arc[start]) / total

        def pick(point: str, q: float) -> int:
            free = [j for j in candidates if j not in taken]
            if not free or total <= 0:
                return -1
            j = next((c for c in free if named(c, point)), None)
            if j is None:
                j = _nearest(free, lambda c: abs(fraction(c) - q))
            if not named(j, point) and abs(fraction(j) - q) > window:
                return -1
            taken.add(j)
            return j

        is_named = [any(named(c, point) for c in candidates) for point, _ in points]
        # Named points first, so that a nameless one does not take a joint the scheme names.
        out: dict[str, int] = {}
        for first in (True, False):
            for (point, q), n in zip(points, is_named):
                if n == first:
                    out[point] = pick(point, q)
        for point, j in out.items():
            put(point, j)

    if t.is_below(neck, hips):
        by_fraction(hips, neck, [("Spine", 1 / 3), ("Spine1", 2 / 3)], 0.17)
    if t.is_below(skull, neck):
        by_fraction(neck, skull, [("Neck1", 0.5)], 0.25)
    return HumanoidMap(source, hints.scheme, facing, sides_by, t.height)
