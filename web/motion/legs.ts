// The leg joints the foot clean-up works on (contact labels, foot lock), for the two skeletons the page
// generates: the canonical 25-joint skeleton of the locomotion models and the dance set's 57-point one.

/** Per leg: hip, knee, ankle, toe, toe end (training/footlock.py LEGS). */
export const LEG_JOINTS = [
  ['LeftUpLeg', 'LeftLeg', 'LeftFoot', 'LeftToeBase', 'LeftToeBase_end'],
  ['RightUpLeg', 'RightLeg', 'RightFoot', 'RightToeBase', 'RightToeBase_end'],
] as const;

/** The dance set's skeleton (acLSTM): hip joint, knee, ankle, toe tip; its feet have no toe segment. */
export const DANCE_LEG_JOINTS = [
  ['lThigh', 'lShin', 'lFoot', 'lFoot_end'],
  ['rThigh', 'rShin', 'rFoot', 'rFoot_end'],
] as const;

/** One leg's joint indices; `toeEnd` is −1 on a skeleton whose feet end at the toe. */
export interface Leg {
  hip: number;
  knee: number;
  ankle: number;
  toe: number;
  toeEnd: number;
}

/** Left and right legs of `joints` (canonical names first, then the dance set's); throws naming the canonical joints missing. */
export function findLegs(joints: readonly string[], user: string): [Leg, Leg] {
  const index = (names: readonly string[]) => names.map((n) => joints.indexOf(n));
  const canonical = LEG_JOINTS.map(index);
  if (canonical.every((leg) => leg.every((j) => j >= 0))) return canonical.map(([hip, knee, ankle, toe, toeEnd]) => ({ hip, knee, ankle, toe, toeEnd })) as [Leg, Leg];
  const dance = DANCE_LEG_JOINTS.map(index);
  if (dance.every((leg) => leg.every((j) => j >= 0))) return dance.map(([hip, knee, ankle, toe]) => ({ hip, knee, ankle, toe, toeEnd: -1 })) as [Leg, Leg];
  const missing = LEG_JOINTS.flat().filter((n) => !joints.includes(n));
  throw new Error(`${user} needs the leg joints ${LEG_JOINTS.map((l) => l.join(', ')).join('; ')}; missing ${missing.join(', ')}`);
}

/** A foot's points the contact rules look at: ankle, toe and, where there is one, toe end. */
export function footPoints(leg: Leg): number[] {
  return leg.toeEnd >= 0 ? [leg.ankle, leg.toe, leg.toeEnd] : [leg.ankle, leg.toe];
}
