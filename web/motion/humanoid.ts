// The humanoid skeleton mapper: which joint of any humanoid skeleton is the hips, each spine, neck and head point,
// and each point of the arm and leg chains of the canonical skeleton (training/mocap/canonical_skeleton.json).
// Python twin: training/mocap/humanoid.py (parity fixture tests/fixtures/humanoid_map.json).
//
// It works from the tree and the bone lengths, with the pose only for heights and sides and names only as hints:
//   1. the feet: the lowest leaf, and the lowest leaf far from it along the tree (a second leg, not a second toe);
//      the legs hang from their lowest common ancestor;
//   2. the hands: the two leaves of the upper body farthest apart along the tree (the arm span); the arms hang from
//      theirs (the chest);
//   3. the hips: the common ancestor of the legs and the chest; the head: where the upper body's remaining leaves meet;
//   4. along each limb, from its ancestor to its farthest leaf (the toe or finger tip, not a heel or a twist bone), the
//      joints whose bone lengths fit human proportions best: thigh ≈ shin, upper arm ≈ 1.25 × forearm, the foot or
//      hand beyond (Winter's segment table), with a joint named as a naming scheme names that point preferred (taken
//      outright for the toe base and hand end) and a helper joint (twist, roll, share bones) avoided. Joints of
//      (almost) no length count as one point;
//   5. the neck base: the joint from the chest up that the naming scheme names so, else the one nearest the
//      shoulders; the spine points between;
//   6. left and right: from names that differ only by a side word (Left/Right, L/R, _l/_r, lThigh/rThigh …), else
//      from the pose: the toes point forward and the left side is at up × forward.
// Points a skeleton lacks but that lie between or beyond points it has (extra spine and neck points, toe and hand
// tips, the toes of a skeleton without any) are derived by skeletonMap.toCanonical; the rest are required, and a
// skeleton without them is refused with a SkeletonMapError naming what is missing.

/** The canonical skeleton's points, in its order (parents: CANONICAL_PARENTS). */
export const CANONICAL_JOINTS = [
  'Hips', 'LeftUpLeg', 'LeftLeg', 'LeftFoot', 'LeftToeBase', 'LeftToeBase_end',
  'RightUpLeg', 'RightLeg', 'RightFoot', 'RightToeBase', 'RightToeBase_end',
  'Spine', 'Spine1', 'Neck', 'Neck1', 'Head', 'Head_end',
  'LeftArm', 'LeftForeArm', 'LeftHand', 'LeftHand_end',
  'RightArm', 'RightForeArm', 'RightHand', 'RightHand_end',
] as const;
export type CanonicalJoint = (typeof CANONICAL_JOINTS)[number];
export const CANONICAL_PARENTS = [-1, 0, 1, 2, 3, 4, 0, 6, 7, 8, 9, 0, 11, 12, 13, 14, 15, 13, 17, 18, 19, 13, 21, 22, 23];

/** What a person calls each required point, for messages. */
export const DESCRIPTIONS: Partial<Record<CanonicalJoint, string>> = {
  Hips: 'hips', LeftUpLeg: 'left hip', LeftLeg: 'left knee', LeftFoot: 'left ankle', LeftToeBase: 'left toe',
  RightUpLeg: 'right hip', RightLeg: 'right knee', RightFoot: 'right ankle', RightToeBase: 'right toe',
  Neck: 'neck base', Head: 'head', LeftArm: 'left shoulder', LeftForeArm: 'left elbow', LeftHand: 'left wrist',
  RightArm: 'right shoulder', RightForeArm: 'right elbow', RightHand: 'right wrist',
};

/** Raised when a skeleton cannot be mapped; the message names what is missing. */
export class SkeletonMapError extends Error {
  constructor(message: string) {
    super(message);
    this.name = 'SkeletonMapError';
  }
}

/** Per scheme, per canonical point, the (normalised, see normaliseName) joint names found there, best first. */
export type Scheme = { name: string; points: Partial<Record<CanonicalJoint, string[]>> };

/** Both sides of a scheme from its left-side names: `L` in a name becomes the side's word. */
function sided(left: Partial<Record<string, string[]>>, words: [string, string]): Partial<Record<CanonicalJoint, string[]>> {
  const out: Partial<Record<CanonicalJoint, string[]>> = {};
  for (const [point, names] of Object.entries(left)) {
    out[point as CanonicalJoint] = names!.map((n) => n.replace('L', words[0]));
    out[point.replace('Left', 'Right') as CanonicalJoint] = names!.map((n) => n.replace('L', words[1]));
  }
  return out;
}

/**
 * Naming schemes: hints only. A skeleton's names are matched against each scheme on its own (names clash across
 * schemes: ASF's "lfoot" is the toe base, a Biped's "L Foot" the ankle), and the scheme that places the most points
 * gives the hints.
 */
export const NAME_SCHEMES: Scheme[] = [
  {
    name: 'CMU ASF',
    points: {
      Hips: ['root'], Spine: ['lowerback'], Spine1: ['upperback'], Neck: ['thorax'], Neck1: ['lowerneck'], Head: ['upperneck'], Head_end: ['head'],
      ...sided({ LeftUpLeg: ['Lhipjoint'], LeftLeg: ['Lfemur'], LeftFoot: ['Ltibia'], LeftToeBase: ['Lfoot'], LeftToeBase_end: ['Ltoes'],
        LeftArm: ['Lclavicle'], LeftForeArm: ['Lhumerus'], LeftHand: ['Lradius'], LeftHand_end: ['Lwrist'] }, ['l', 'r']),
    },
  },
  {
    name: 'CMU BVH',
    points: {
      Hips: ['hips'], Spine: ['spine'], Spine1: ['spine1'], Neck: ['neck'], Neck1: ['neck1'], Head: ['head'], Head_end: ['headend'],
      ...sided({ LeftUpLeg: ['Lupleg'], LeftLeg: ['Lleg'], LeftFoot: ['Lfoot'], LeftToeBase: ['Ltoebase'], LeftToeBase_end: ['Ltoebaseend'],
        LeftArm: ['Larm'], LeftForeArm: ['Lforearm'], LeftHand: ['Lhand'], LeftHand_end: ['Lfingerbase', 'Lhandend'] }, ['left', 'right']),
    },
  },
  {
    name: 'CMU BVH (3ds Max)',
    points: {
      Hips: ['hips'], Spine: ['chest'], Spine1: ['chest2'], Neck: ['lowerneck'], Neck1: ['neck'], Head: ['head'], Head_end: ['headend'],
      ...sided({ LeftUpLeg: ['Lhip'], LeftLeg: ['Lknee'], LeftFoot: ['Lankle'], LeftToeBase: ['Ltoe'], LeftToeBase_end: ['Ltoeend'],
        LeftArm: ['Lshoulder'], LeftForeArm: ['Lelbow'], LeftHand: ['Lwrist'], LeftHand_end: ['Lfingers'] }, ['left', 'right']),
    },
  },
  {
    name: 'Mixamo',
    points: {
      Hips: ['hips'], Spine: ['spine1'], Spine1: ['spine2'], Neck: ['neck'], Head: ['head'], Head_end: ['headtopend'],
      ...sided({ LeftUpLeg: ['Lupleg'], LeftLeg: ['Lleg'], LeftFoot: ['Lfoot'], LeftToeBase: ['Ltoebase'], LeftToeBase_end: ['Ltoeend'],
        LeftArm: ['Larm'], LeftForeArm: ['Lforearm'], LeftHand: ['Lhand'], LeftHand_end: ['Lhandmiddle1'] }, ['left', 'right']),
    },
  },
  {
    name: '3ds Max Biped',
    points: {
      Hips: ['pelvis', ''], Spine: ['spine1', 'spine'], Spine1: ['spine2'], Neck: ['neck'], Head: ['head'], Head_end: ['headnub'],
      ...sided({ LeftUpLeg: ['Lthigh'], LeftLeg: ['Lcalf'], LeftFoot: ['Lfoot'], LeftToeBase: ['Ltoe0'], LeftToeBase_end: ['Ltoe0nub'],
        LeftArm: ['Lupperarm'], LeftForeArm: ['Lforearm'], LeftHand: ['Lhand'], LeftHand_end: ['Lfinger2', 'Lfinger1'] }, ['l', 'r']),
    },
  },
  {
    name: 'Daz',
    points: {
      Hips: ['hip', 'pelvis'], Spine: ['abdomenlower', 'abdomen'], Spine1: ['chestlower', 'chest'], Neck: ['necklower', 'neck'], Neck1: ['neckupper'], Head: ['head'],
      ...sided({ LeftUpLeg: ['Lthighbend', 'Lthigh'], LeftLeg: ['Lshin'], LeftFoot: ['Lfoot'], LeftToeBase: ['Ltoe', 'Lmetatarsals'],
        LeftArm: ['Lshldrbend', 'Lshldr'], LeftForeArm: ['Lforearmbend', 'Lforearm'], LeftHand: ['Lhand'], LeftHand_end: ['Lmid1'] }, ['l', 'r']),
    },
  },
  {
    name: 'Unreal',
    points: {
      Hips: ['pelvis'], Spine: ['spine01'], Spine1: ['spine02', 'spine03'], Neck: ['neck01'], Neck1: ['neck02'], Head: ['head'], Head_end: ['headleaf', 'headend'],
      ...sided({ LeftUpLeg: ['thighL'], LeftLeg: ['calfL'], LeftFoot: ['footL'], LeftToeBase: ['ballL'], LeftToeBase_end: ['ballleafL', 'ballendL'],
        LeftArm: ['upperarmL'], LeftForeArm: ['lowerarmL'], LeftHand: ['handL'], LeftHand_end: ['middle02L', 'middle01L'] }, ['l', 'r']),
    },
  },
  {
    name: 'VRM',
    points: {
      Hips: ['hips'], Spine: ['spine'], Spine1: ['chest'], Neck: ['neck'], Head: ['head'],
      ...sided({ LeftUpLeg: ['Lupperleg'], LeftLeg: ['Llowerleg'], LeftFoot: ['Lfoot'], LeftToeBase: ['Ltoes'],
        LeftArm: ['Lupperarm'], LeftForeArm: ['Llowerarm'], LeftHand: ['Lhand'], LeftHand_end: ['Lmiddleintermediate', 'Lmiddleproximal'] }, ['left', 'right']),
    },
  },
  {
    name: 'Bandai Namco',
    points: {
      Hips: ['hips'], Spine: ['spine'], Spine1: ['chest'], Neck: ['neck'], Head: ['head'],
      ...sided({ LeftUpLeg: ['upperlegL'], LeftLeg: ['lowerlegL'], LeftFoot: ['footL'], LeftToeBase: ['toesL'],
        LeftArm: ['upperarmL'], LeftForeArm: ['lowerarmL'], LeftHand: ['handL'] }, ['l', 'r']),
    },
  },
  {
    name: 'iClone',
    points: {
      Hips: ['ccbasehip'], Spine: ['ccbasewaist'], Spine1: ['ccbasespine01', 'ccbasespine02'], Neck: ['ccbasenecktwist01'], Neck1: ['ccbasenecktwist02'], Head: ['ccbasehead'],
      ...sided({ LeftUpLeg: ['ccbaseLthigh'], LeftLeg: ['ccbaseLcalf'], LeftFoot: ['ccbaseLfoot'], LeftToeBase: ['ccbaseLtoebase'],
        LeftArm: ['ccbaseLupperarm'], LeftForeArm: ['ccbaseLforearm'], LeftHand: ['ccbaseLhand'], LeftHand_end: ['ccbaseLmid2', 'ccbaseLmid1'] }, ['l', 'r']),
    },
  },
];

/** A joint name without namespace (`mixamorig:`), Biped prefix (`Bip01 `), case, spaces, `_`, `-` or `.`. */
export function normaliseName(name: string): string {
  return name
    .slice(name.lastIndexOf(':') + 1)
    .toLowerCase()
    .replace(/^bip0*1(?=$|[\s_.-])/, '')
    .replace(/[\s_.-]/g, '');
}

/** Per naming scheme (NAME_SCHEMES order), the joint it places at each canonical point (CANONICAL_JOINTS order; -1: none). */
export function matchSchemes(joints: readonly string[]): Array<{ scheme: string; source: number[] }> {
  const index = new Map<string, number>();
  joints.forEach((name, j) => {
    const n = normaliseName(name);
    if (!index.has(n)) index.set(n, j);
  });
  return NAME_SCHEMES.map((scheme) => ({
    scheme: scheme.name,
    source: CANONICAL_JOINTS.map((point) => {
      for (const n of scheme.points[point] ?? []) {
        const j = index.get(n);
        if (j !== undefined) return j;
      }
      return -1;
    }),
  }));
}

/** A skeleton with one or more poses: world positions, frames × joints × 3, any unit, y up. */
export interface PosedSkeleton {
  joints: readonly string[];
  parents: readonly number[];
  frames: number;
  positions: ArrayLike<number>;
}

/** Where a humanoid's canonical points are. */
export interface HumanoidMap {
  /** Per canonical point (CANONICAL_JOINTS order): the joint there, or -1 where the point is derived. */
  source: number[];
  /** The naming scheme whose names gave the hints ('' when none matched more than a few points). */
  scheme: string;
  /** Which way the figure faces (unit, on the ground: x, z), from the toes, else the knees, else +z. */
  facing: [number, number];
  /** How the sides were told: by names that differ only in a side word, or by the pose. */
  sidesBy: 'names' | 'pose';
  /** The figure's height (its tallest extent over the frames looked at), in the skeleton's units. */
  height: number;
}

/** Frames looked at: up to this many, evenly spread. */
const SAMPLED_FRAMES = 48;
/** A bone shorter than this share of the figure's height counts as no bone (helper and zero-length joints). */
const COINCIDENT = 0.003;
/** Human proportions (Winter, Biomechanics and Motor Control of Human Movement, segment lengths ÷ height). */
const UPPER_ARM_TO_FOREARM = 0.186 / 0.146;
/**
 * Upper arm ÷ forearm ratios found in real skeletons: from about 1.0 (Bandai Namco) to 2.2 (CMU subjects whose
 * radius is short); within this range the ratio costs only a tie-breaking WEAK share of its squared log distance
 * from Winter's, outside it the full squared log distance to the range.
 */
const UPPER_ARM_RANGE: readonly [number, number] = [0.95, 2.3];
const WEAK = 0.1;
const HAND_TO_FOREARM = 0.7;
const FOOT_TO_LEG = 0.26;
/**
 * Costs (squared log ratios): a limb without a foot or hand beyond; a joint the naming scheme names for the point
 * (enough to outweigh any proportion: names are hints, but a scheme that matched is rarely wrong); a helper joint.
 */
const NO_FOOT = 0.15;
const NO_HAND = 0.1;
/** A wrist candidate where several bones start (thumb and fingers) gains this much (CMU's short hands). */
const BRANCHING_WRIST = NO_HAND / 2;
const NAME_HINT = 1;
const HELPER = 0.2;
/**
 * How much longer (log ratio) a foot or hand may be than the proportion at no cost. Shorter costs nothing: rigs cut
 * hands at the palm and feet at the ball (CMU's hands are a fifth of the forearm).
 */
const EXTREMITY_SLACK = 0.7;
/** How far (half shoulder widths) the shoulders may stand above the neck base along the torso. */
const NECK_BELOW = 0.5;
const HELPER_NAME = /twist|roll|share|helper|corrective|jiggle|adjust|pole|target|ctrl|control/i;
/** Inverse-kinematics bones (Unreal's ik_foot_l, ik_hand_gun …): targets at a hand's or foot's place, not limbs. */
const IK_NAME = /(^|[^a-z])ik([^a-z]|$)/i;

interface Tree {
  parents: readonly number[];
  children: number[][];
  depth: number[];
  /** Median bone length (to the parent), per joint. */
  bone: Float64Array;
  /** Arc length from the root along the bones. */
  arc: Float64Array;
  /** Mean height above the frame's lowest joint. */
  lift: Float64Array;
  height: number;
  frames: number[];
  at: (f: number, j: number) => [number, number, number];
}

function sampled(frames: number): number[] {
  const n = Math.min(frames, SAMPLED_FRAMES);
  return Array.from({ length: n }, (_, i) => Math.round((i * (frames - 1)) / Math.max(1, n - 1)));
}

function median(values: number[]): number {
  const s = [...values].sort((a, b) => a - b);
  return s.length ? s[Math.floor(s.length / 2)] : 0;
}

function treeOf(sk: PosedSkeleton): Tree {
  const J = sk.joints.length;
  const at = (f: number, j: number): [number, number, number] => {
    const o = (f * J + j) * 3;
    return [sk.positions[o], sk.positions[o + 1], sk.positions[o + 2]];
  };
  const frames = sampled(sk.frames);
  const children = sk.parents.map(() => [] as number[]);
  sk.parents.forEach((p, j) => p >= 0 && children[p].push(j));
  const depth = new Array<number>(J).fill(0);
  const bone = new Float64Array(J);
  const arc = new Float64Array(J);
  const lift = new Float64Array(J);
  for (let j = 0; j < J; j++) {
    const p = sk.parents[j];
    if (p < 0) continue;
    depth[j] = depth[p] + 1;
    bone[j] = median(frames.map((f) => dist(at(f, j), at(f, p))));
    arc[j] = arc[p] + bone[j];
  }
  const heights: number[] = [];
  for (const f of frames) {
    let lo = Infinity, hi = -Infinity;
    for (let j = 0; j < J; j++) {
      lo = Math.min(lo, at(f, j)[1]);
      hi = Math.max(hi, at(f, j)[1]);
    }
    heights.push(hi - lo);
    for (let j = 0; j < J; j++) lift[j] += (at(f, j)[1] - lo) / frames.length;
  }
  return { parents: sk.parents, children, depth, bone, arc, lift, height: Math.max(...heights), frames, at };
}

function dist(a: readonly number[], b: readonly number[]): number {
  return Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

/** The root of the tree with the most bone length (a file may hold props or a second figure beside the body). */
function mainTreeRoot(t: Tree): number {
  const total = new Float64Array(t.parents.length);
  for (let j = t.parents.length - 1; j >= 0; j--) if (t.parents[j] >= 0) total[t.parents[j]] += total[j] + t.bone[j];
  let best = -1;
  t.parents.forEach((p, j) => {
    if (p < 0 && (best < 0 || total[j] > total[best] + 1e-12)) best = j;
  });
  return best;
}

function lca(t: Tree, a: number, b: number): number {
  while (t.depth[a] > t.depth[b]) a = t.parents[a];
  while (t.depth[b] > t.depth[a]) b = t.parents[b];
  while (a !== b) {
    a = t.parents[a];
    b = t.parents[b];
  }
  return a;
}

const treeDistance = (t: Tree, a: number, b: number) => t.arc[a] + t.arc[b] - 2 * t.arc[lca(t, a, b)];

function isBelow(t: Tree, j: number, ancestor: number): boolean {
  for (let k = j; k >= 0; k = t.parents[k]) if (k === ancestor) return true;
  return false;
}

/** The joints from `top` (excluded) down to `bottom` (included), top first. */
function pathDown(t: Tree, top: number, bottom: number): number[] {
  const out: number[] = [];
  for (let k = bottom; k !== top && k >= 0; k = t.parents[k]) out.push(k);
  return out.reverse();
}

/** The child of `ancestor` on the way down to `j`. */
function childToward(t: Tree, ancestor: number, j: number): number {
  let k = j;
  while (t.parents[k] !== ancestor) k = t.parents[k];
  return k;
}

function leavesUnder(t: Tree, j: number): number[] {
  const out: number[] = [];
  const stack = [j];
  while (stack.length) {
    const k = stack.pop()!;
    if (t.children[k].length === 0) out.push(k);
    else stack.push(...t.children[k]);
  }
  return out;
}

/**
 * A limb's distinct points from `top` (excluded) to `tip`: runs of joints of (almost) no length count as one point,
 * represented by a joint the naming scheme names (CMU's LeftHand, not the LeftFingerBase at its place), else the
 * deepest joint that is not a helper; points at the top's own place are dropped.
 */
function limbPoints(t: Tree, top: number, tip: number, names: readonly string[], namedAny: (j: number) => boolean): number[] {
  const eps = COINCIDENT * t.height;
  const groups: number[][] = [];
  for (const j of pathDown(t, top, tip)) {
    if (t.arc[j] - t.arc[top] < eps) continue;
    if (groups.length && t.bone[j] < eps) groups[groups.length - 1].push(j);
    else groups.push([j]);
  }
  return groups.map((g) => g.find(namedAny) ?? [...g].reverse().find((j) => !HELPER_NAME.test(names[j])) ?? g[g.length - 1]);
}

type Hint = (j: number, point: CanonicalJoint) => number;
type Hints = { hint: Hint; named: (j: number, point: CanonicalJoint) => boolean; namedAny: (j: number) => boolean };

/**
 * The naming scheme that places the most points (when it places at least 6), whether it names joint j as a point,
 * and the cost of a name for a point: a scheme's name for it lowers it, a helper's name raises it.
 */
function hintsFor(names: readonly string[]): Hints & { scheme: string } {
  let best = { scheme: '', placed: 0, source: [] as number[] };
  for (const m of matchSchemes(names)) {
    const placed = m.source.filter((j) => j >= 0).length;
    if (placed > best.placed) best = { ...m, placed };
  }
  const useful = best.placed >= 6;
  const named = (j: number, point: CanonicalJoint) => useful && best.source[CANONICAL_JOINTS.indexOf(point)] === j;
  const hint: Hint = (j, point) => (named(j, point) ? -NAME_HINT : 0) + (HELPER_NAME.test(names[j]) ? HELPER : 0);
  const namedAny = (j: number) => useful && best.source.includes(j);
  return { hint, named, namedAny, scheme: useful ? best.scheme : '' };
}

const sq = (x: number) => x * x;
const slack = (x: number) => sq(Math.max(0, x - EXTREMITY_SLACK));

/** A leg's points (socket, knee, ankle, toe base?, toe end?) below `pelvis` down to its farthest leaf. */
function fitLeg(t: Tree, pelvis: number, legRoot: number, { hint, named, namedAny }: Hints, side: 'Left' | 'Right', names: readonly string[]) {
  const tip = farthestLeaf(t, legRoot, pelvis);
  const pts = limbPoints(t, pelvis, tip, names, namedAny);
  if (pts.length < 3) return undefined;
  const arc = (a: number, b: number) => t.arc[b] - t.arc[a];
  // The hip socket: the first point below the legs' branch, or a later one the naming scheme names so (the Daz
  // skeleton of the acLSTM set has a buttock joint above its thigh).
  const socketAt = Math.max(0, pts.findIndex((j, i) => i < pts.length - 2 && named(j, `${side}UpLeg`)));
  const socket = pts[socketAt];
  let best: { cost: number; knee: number; ankle: number } | undefined;
  for (let i = socketAt + 1; i < pts.length - 1; i++) {
    for (let k = i + 1; k < pts.length; k++) {
      const thigh = arc(socket, pts[i]), shin = arc(pts[i], pts[k]);
      const foot = arc(pts[k], tip);
      let cost = sq(Math.log(thigh / shin)) + (k === pts.length - 1 ? NO_FOOT : slack(Math.log(foot / (FOOT_TO_LEG * (thigh + shin)))));
      cost += hint(socket, `${side}UpLeg`) + hint(pts[i], `${side}Leg`) + hint(pts[k], `${side}Foot`);
      if (!best || cost < best.cost - 1e-12) best = { cost, knee: i, ankle: k };
    }
  }
  if (!best) return undefined;
  const toes = pts.slice(best.ankle + 1);
  const ankle = pts[best.ankle];
  let toeBase = -1, toeEnd = -1;
  if (toes.length === 1) toeBase = toes[0];
  else if (toes.length > 1) {
    toeEnd = toes[toes.length - 1];
    const want = (2 / 3) * arc(ankle, toeEnd);
    const candidates = toes.slice(0, -1);
    toeBase = candidates.find((j) => named(j, `${side}ToeBase`)) ?? nearest(candidates, (j) => Math.abs(arc(ankle, j) - want));
  }
  return { UpLeg: socket, Leg: pts[best.knee], Foot: ankle, ToeBase: toeBase, ToeBase_end: toeEnd };
}

/** An arm's points (shoulder, elbow, wrist, hand end?) below `chest` down to its farthest leaf. */
function fitArm(t: Tree, chest: number, armRoot: number, { hint, named, namedAny }: Hints, side: 'Left' | 'Right', names: readonly string[]) {
  const tip = farthestLeaf(t, armRoot, chest);
  const pts = limbPoints(t, chest, tip, names, namedAny);
  if (pts.length < 3) return undefined;
  const arc = (a: number, b: number) => t.arc[b] - t.arc[a];
  let best: { cost: number; s: number; e: number; w: number } | undefined;
  for (let s = 0; s < pts.length - 2; s++) {
    for (let e = s + 1; e < pts.length - 1; e++) {
      for (let w = e + 1; w < pts.length; w++) {
        const upper = arc(pts[s], pts[e]), fore = arc(pts[e], pts[w]);
        const hand = arc(pts[w], tip);
        const clavicle = t.arc[pts[s]] - t.arc[chest];
        const ratio = upper / fore;
        let cost = WEAK * sq(Math.log(ratio / UPPER_ARM_TO_FOREARM)) + sq(Math.log(Math.max(1, UPPER_ARM_RANGE[0] / ratio, ratio / UPPER_ARM_RANGE[1])));
        // The hand: a wrist with nothing beyond costs NO_HAND; a hand much longer than the forearm allows costs
        // fully, any other length weakly against the typical one, and never as much as no hand at all.
        cost += w === pts.length - 1 ? NO_HAND : slack(Math.log(hand / (HAND_TO_FOREARM * fore))) + Math.min(WEAK * sq(Math.log(hand / (HAND_TO_FOREARM * fore))), NO_HAND / 2);
        // A wrist is where the thumb and fingers part: a joint with several children is the likelier wrist.
        if (t.children[pts[w]].length >= 2) cost -= BRANCHING_WRIST;
        // From the chest's branch to the shoulder is about a forearm long (the canonical clavicle); weakly.
        cost += WEAK * sq(Math.log(Math.max(clavicle, 1e-9 * t.height) / fore));
        if (clavicle > upper) cost += sq(Math.log(clavicle / upper));
        cost += hint(pts[s], `${side}Arm`) + hint(pts[e], `${side}ForeArm`) + hint(pts[w], `${side}Hand`);
        if (!best || cost < best.cost - 1e-12) best = { cost, s, e, w };
      }
    }
  }
  if (!best) return undefined;
  const wrist = pts[best.w];
  const fore = arc(pts[best.e], wrist);
  const beyond = pts.slice(best.w + 1);
  const handEnd = beyond.length ? (beyond.find((j) => named(j, `${side}Hand_end`)) ?? nearest(beyond, (j) => Math.abs(arc(wrist, j) - HAND_TO_FOREARM * fore))) : -1;
  return { Arm: pts[best.s], ForeArm: pts[best.e], Hand: wrist, Hand_end: handEnd };
}

function nearest(candidates: number[], cost: (j: number) => number): number {
  let best = candidates[0];
  for (const j of candidates) if (cost(j) < cost(best) - 1e-12) best = j;
  return best;
}

/** The leaf under `root` (inclusive) farthest along the tree from `from`: a toe or finger tip. */
function farthestLeaf(t: Tree, root: number, from: number): number {
  return leavesUnder(t, root).reduce((a, b) => (t.arc[b] - t.arc[from] > t.arc[a] - t.arc[from] + 1e-12 ? b : a));
}

/** Words that name a side, as a name's whole token or its first letter glued to the rest (lThigh, lfemur). */
const LEFT_WORDS = new Set(['l', 'left']);
const RIGHT_WORDS = new Set(['r', 'right']);

function tokens(name: string): string[] {
  return name
    .slice(name.lastIndexOf(':') + 1)
    .replace(/([a-z0-9])([A-Z])/g, '$1 $2')
    .replace(/([A-Z])([A-Z][a-z])/g, '$1 $2')
    .toLowerCase()
    .split(/[\s_.\-:]+/)
    .filter(Boolean);
}

/** +1 when `a` is named the left and `b` the right of one joint, -1 the other way round, 0 when the names don't tell. */
export function sideByNames(a: string, b: string): number {
  const ta = tokens(a), tb = tokens(b);
  if (ta.length !== tb.length) return 0;
  const diff = ta.flatMap((x, i) => (x === tb[i] ? [] : [i]));
  if (diff.length !== 1) return 0;
  let x = ta[diff[0]], y = tb[diff[0]];
  // One token differing by its first letter only: "lfemur" / "rfemur", "lthigh" / "rthigh".
  if (x.length > 1 && y.length > 1 && x.slice(1) === y.slice(1)) {
    x = x[0];
    y = y[0];
  }
  if (LEFT_WORDS.has(x) && RIGHT_WORDS.has(y)) return 1;
  if (RIGHT_WORDS.has(x) && LEFT_WORDS.has(y)) return -1;
  return 0;
}

/** The figure's facing (unit, x z) over the frames: where the toes point from the ankles, else the knees bend. */
function facingOf(t: Tree, legs: Array<{ Leg: number; Foot: number; ToeBase: number; UpLeg: number }>): [number, number] {
  let x = 0, z = 0;
  for (const f of t.frames) {
    for (const leg of legs) {
      const ankle = t.at(f, leg.Foot);
      if (leg.ToeBase >= 0) {
        const toe = t.at(f, leg.ToeBase);
        x += toe[0] - ankle[0];
        z += toe[2] - ankle[2];
      } else {
        // Knees bend forward: the knee lies ahead of the hip-to-ankle line.
        const hip = t.at(f, leg.UpLeg), knee = t.at(f, leg.Leg);
        x += knee[0] - (hip[0] + ankle[0]) / 2;
        z += knee[2] - (hip[2] + ankle[2]) / 2;
      }
    }
  }
  const n = Math.hypot(x, z);
  return n > 1e-9 * t.height ? [x / n, z / n] : [0, 1];
}

/** Mean over the frames of how far joint `a` lies left of joint `b` (facing `facing`; left = up × forward). */
function leftOf(t: Tree, a: number, b: number, facing: [number, number]): number {
  let s = 0;
  for (const f of t.frames) {
    const pa = t.at(f, a), pb = t.at(f, b);
    s += (pa[0] - pb[0]) * facing[1] - (pa[2] - pb[2]) * facing[0];
  }
  return s;
}

function refuse(missing: string): never {
  throw new SkeletonMapError(`this skeleton is not a humanoid the playground can map: ${missing}`);
}

/**
 * The canonical points of a humanoid skeleton (see the header). Throws a SkeletonMapError naming what is missing for
 * a skeleton without two legs, two arms or a head.
 */
export function mapHumanoid(sk: PosedSkeleton): HumanoidMap {
  const J = sk.joints.length;
  if (J < 3 || sk.frames < 1) refuse(`it has ${J} joint${J === 1 ? '' : 's'}, not legs, arms and a head`);
  if (sk.parents.some((p, j) => p >= j)) throw new SkeletonMapError('the skeleton\'s parents must come before their children');
  const t = treeOf(sk);
  if (!(t.height > 0)) refuse('its joints all lie at one height, so no legs can be told');
  const names = sk.joints;
  const hints = hintsFor(names);
  const { named, scheme } = hints;
  // Extremities are leaves of the main tree (the one with the most bone length: a prop beside the figure is not a
  // foot), neither helpers themselves (a twist bone's end) nor below an IK bone (an IK hand sits where the hand is;
  // a helper inside a limb, such as an inline twist bone, leaves the limb's end an extremity).
  const mainRoot = mainTreeRoot(t);
  const belowIK = new Array<boolean>(J).fill(false);
  for (let j = 0; j < J; j++) belowIK[j] = IK_NAME.test(names[j]) || (sk.parents[j] >= 0 && belowIK[sk.parents[j]]);
  const leaves = t.children.flatMap((c, j) => (c.length === 0 && !belowIK[j] && !HELPER_NAME.test(names[j]) && isBelow(t, j, mainRoot) ? [j] : []));
  if (leaves.length === 0) refuse('no two legs (no second foot near the floor)');
  const lowest = (set: number[]) => set.reduce((a, b) => (t.lift[b] < t.lift[a] - 1e-12 ? b : a));

  // 1. Feet: the lowest leaf, and the lowest leaf a leg's length away along the tree.
  const footA = lowest(leaves);
  const others = leaves.filter((l) => treeDistance(t, footA, l) > 0.5 * t.height && t.lift[l] < 0.3 * t.height);
  if (others.length === 0) refuse('no two legs (no second foot near the floor)');
  const footB = lowest(others);
  const pelvis = lca(t, footA, footB);
  const legRoots = [childToward(t, pelvis, footA), childToward(t, pelvis, footB)];
  const inLegs = (j: number) => legRoots.some((r) => isBelow(t, j, r));

  // 2. Hands: the two leaves of the rest of the body farthest apart along the tree.
  const upper = leaves.filter((l) => !inLegs(l));
  let hands: [number, number] | undefined, span = 0;
  for (let i = 0; i < upper.length; i++) {
    for (let k = i + 1; k < upper.length; k++) {
      const d = treeDistance(t, upper[i], upper[k]);
      if (d > span + 1e-12) [span, hands] = [d, [upper[i], upper[k]]];
    }
  }
  if (!hands || span < 0.5 * t.height) refuse('no two arms (no two hands an arm span apart)');
  const chest = lca(t, hands[0], hands[1]);
  if (inLegs(chest)) refuse('no two arms (the hands found hang from a leg)');
  const armRoots = [childToward(t, chest, hands[0]), childToward(t, chest, hands[1])];
  const inArms = (j: number) => armRoots.some((r) => isBelow(t, j, r));

  // 3. Head: where the remaining leaves of the upper body meet, above the chest.
  // Leaves above the chest on average; when none is (a dancer bowing through the frames looked at), any beside the arms.
  const besideArms = upper.filter((l) => !inArms(l) && isBelow(t, l, chest) && l !== chest);
  const raised = besideArms.filter((l) => t.lift[l] > t.lift[chest]);
  const headLeaves = raised.length ? raised : besideArms;
  if (headLeaves.length === 0) refuse('no head (nothing above the shoulders)');
  let skull = headLeaves.reduce((a, b) => lca(t, a, b));
  let headEnd = -1;
  if (t.children[skull].length === 0) {
    // One chain: its last bone is a head-top end when named so, or when long against the neck and not named the
    // head; else the leaf is the head joint itself.
    const parent = t.parents[skull];
    const long = t.bone[skull] >= 0.3 * (t.arc[skull] - t.arc[chest]);
    if (parent !== chest && (named(skull, 'Head_end') || (long && !named(skull, 'Head')))) [headEnd, skull] = [skull, parent];
  }
  const hips = (() => {
    const top = lca(t, pelvis, chest);
    const found = Math.abs(t.lift[top] - t.lift[pelvis]) <= 0.1 * t.height ? top : pelvis;
    // A joint the scheme names the hips, above the one found and near it (a Biped's thighs hang from its spine).
    for (let k = found; k >= 0; k = t.parents[k]) if (named(k, 'Hips') && Math.abs(t.lift[k] - t.lift[found]) <= 0.15 * t.height) return k;
    return found;
  })();

  // 4. Limbs, sides still unknown (A, B).
  const legs = legRoots.map((r) => fitLeg(t, pelvis, r, hints, 'Left', names));
  const legsOther = legRoots.map((r) => fitLeg(t, pelvis, r, hints, 'Right', names));
  if (!legs[0] || !legs[1]) refuse(`no ${!legs[0] && !legs[1] ? 'knees or ankles' : 'knee or ankle on one leg'} (a leg needs a hip, knee and ankle joint)`);
  const arms = armRoots.map((r) => fitArm(t, chest, r, hints, 'Left', names));
  const armsOther = armRoots.map((r) => fitArm(t, chest, r, hints, 'Right', names));
  if (!arms[0] || !arms[1]) refuse('no elbow or wrist on an arm (an arm needs a shoulder, elbow and wrist joint)');

  // 6. Sides: names first, else the pose. Each limb is fitted again with the other side's hints when it is the right.
  const facing = facingOf(t, [legs[0]!, legs[1]!]);
  const vote = (a: Record<string, number>, b: Record<string, number>) =>
    Object.keys(a).reduce((s, k) => s + (a[k] >= 0 && b[k] >= 0 ? sideByNames(names[a[k]], names[b[k]]) : 0), 0);
  const legVote = vote(legs[0]!, legs[1]!);
  const armVote = vote(arms[0]!, arms[1]!);
  const sidesBy = legVote !== 0 && armVote !== 0 ? 'names' : 'pose';
  const legAisLeft = legVote !== 0 ? legVote > 0 : leftOf(t, legs[0]!.UpLeg, legs[1]!.UpLeg, facing) > 0;
  const armAisLeft = armVote !== 0 ? armVote > 0 : leftOf(t, arms[0]!.Arm, arms[1]!.Arm, facing) > 0;
  const left = { leg: legAisLeft ? legs[0]! : legs[1]!, arm: armAisLeft ? arms[0]! : arms[1]! };
  const right = { leg: legAisLeft ? legsOther[1]! : legsOther[0]!, arm: armAisLeft ? armsOther[1]! : armsOther[0]! };

  // 5. The neck base: the joint from the chest up that the naming scheme names so; else the first one (from the
  // chest's branch up) that the shoulders do not stand well above: the shoulders' midpoint at most NECK_BELOW
  // half shoulder widths above it along the torso (hips → head). CMU's thorax lies 0.3–0.45 below its shoulders
  // and its next neck joint 0.1–0.16 above them; Bandai's chest 1.3 below, its neck 0.36 above.
  const shoulders = [left.arm.Arm, right.arm.Arm];
  const neckPath = [chest, ...pathDown(t, chest, skull).filter((j) => j !== skull)];
  const shouldersAbove = (j: number) =>
    median(t.frames.map((f) => {
      const hipsAt = t.at(f, hips), headAt = t.at(f, skull), l = t.at(f, shoulders[0]), r = t.at(f, shoulders[1]), at = t.at(f, j);
      const up = [0, 1, 2].map((a) => headAt[a] - hipsAt[a]);
      const n = Math.hypot(up[0], up[1], up[2]) || 1;
      const rise = [0, 1, 2].reduce((sum, a) => sum + ((l[a] + r[a]) / 2 - at[a]) * (up[a] / n), 0);
      return rise / (dist(l, r) / 2 || 1);
    }));
  const unnamedElse = neckPath.filter((j) => !named(j, 'Neck1') && !named(j, 'Head'));
  const neck = neckPath.find((j) => named(j, 'Neck')) ?? unnamedElse.find((j) => shouldersAbove(j) <= NECK_BELOW) ?? unnamedElse[unnamedElse.length - 1] ?? chest;

  const source = CANONICAL_JOINTS.map(() => -1);
  const put = (point: CanonicalJoint, j: number) => (source[CANONICAL_JOINTS.indexOf(point)] = j);
  put('Hips', hips);
  for (const [side, limbs] of [['Left', left], ['Right', right]] as const) {
    for (const [k, j] of Object.entries(limbs.leg)) put(`${side}${k}` as CanonicalJoint, j);
    for (const [k, j] of Object.entries(limbs.arm)) put(`${side}${k}` as CanonicalJoint, j);
  }
  put('Neck', neck);
  put('Head', skull);
  put('Head_end', headEnd);
  // Spine points between the hips and the neck base, and Neck1 between the neck base and the head, by arc fraction.
  const between = (from: number, to: number) => pathDown(t, from, to).filter((j) => j !== to && t.bone[j] >= COINCIDENT * t.height);
  // A joint the naming scheme names for the point is taken first.
  const byFraction = (from: number, to: number, points: Array<[CanonicalJoint, number]>, window: number) => {
    const candidates = between(from, to);
    const total = t.arc[to] - t.arc[from];
    const taken = new Set<number>();
    const pick = (point: CanonicalJoint, q: number) => {
      const free = candidates.filter((j) => !taken.has(j));
      if (!free.length || total <= 0) return -1;
      const j = free.find((c) => named(c, point)) ?? nearest(free, (c) => Math.abs((t.arc[c] - t.arc[from]) / total - q));
      if (!named(j, point) && Math.abs((t.arc[j] - t.arc[from]) / total - q) > window) return -1;
      taken.add(j);
      return j;
    };
    const named1 = points.map(([point]) => candidates.some((c) => named(c, point)));
    // Named points first, so that a nameless one does not take a joint the scheme names.
    const out = new Map<CanonicalJoint, number>();
    points.forEach(([point, q], i) => named1[i] && out.set(point, pick(point, q)));
    points.forEach(([point, q], i) => !named1[i] && out.set(point, pick(point, q)));
    for (const [point, j] of out) put(point, j);
  };
  if (isBelow(t, neck, hips)) byFraction(hips, neck, [['Spine', 1 / 3], ['Spine1', 2 / 3]], 0.17);
  if (isBelow(t, skull, neck)) byFraction(neck, skull, [['Neck1', 0.5]], 0.25);
  return { source, scheme, facing, sidesBy, height: t.height };
}
