// Joint-name heuristics shared by the viewer: which side a joint is on, and where the feet are.
// Works for the CMU ASF names (lfemur, rtibia, lfoot …), the CMU BVH conversion (LeftUpLeg, RightFoot,
// LHipJoint …), the acLSTM skeleton (lThigh, rFoot …) and the usual left_/_l/.L suffix styles.

export type Side = 'left' | 'right' | null;

const PARTS = [
  'hip', 'femur', 'tibia', 'foot', 'toe', 'clavicle', 'humerus', 'radius', 'wrist', 'hand', 'finger',
  'thumb', 'upleg', 'leg', 'arm', 'shoulder', 'shldr', 'forearm', 'collar', 'thigh', 'shin', 'knee',
  'ankle', 'elbow', 'ball', 'buttock', 'uparm', 'lowarm', 'lowleg', 'upperarm', 'lowerarm', 'heel', 'index',
  'pinky', 'ring', 'mid', 'eye', 'ear',
];

export function sideOf(name: string): Side {
  const n = name.toLowerCase();
  if (n.startsWith('left') || n.endsWith('left')) return 'left';
  if (n.startsWith('right') || n.endsWith('right')) return 'right';
  if (/^l[_.\- ]|[_.\- ]l$/.test(n)) return 'left';
  if (/^r[_.\- ]|[_.\- ]r$/.test(n)) return 'right';
  const rest = n.slice(1);
  if (PARTS.some((p) => rest.startsWith(p))) {
    if (n[0] === 'l') return 'left';
    if (n[0] === 'r') return 'right';
  }
  return null;
}

/** Index of the first joint whose name looks like the head, or -1. */
export function findHead(joints: string[]): number {
  const exact = joints.findIndex((n) => /^head$/i.test(n));
  if (exact >= 0) return exact;
  return joints.findIndex((n) => /head/i.test(n) && !/end|site|top/i.test(n));
}
