// Joint-name heuristics (web/viewer/naming.ts): which side a joint is on, where the head is.
import { describe, expect, it } from 'vitest';
import { findHead, sideOf } from '../../web/viewer/naming';

describe('sideOf', () => {
  it('recognises left, right and centre joints across naming schemes', () => {
    const left = ['LeftUpLeg', 'LHipJoint', 'lfemur', 'ltibia', 'lThigh', 'LThumb_end', 'hand_l', 'Foot.L', 'left_foot'];
    const right = ['RightFoot', 'RHipJoint', 'rhumerus', 'rShin', 'RThumb_end', 'hand_r', 'right_hand', 'rMid1', 'rIndex2_end'];
    const centre = ['Hips', 'root', 'lowerback', 'LowerBack', 'Spine1', 'head', 'Head_end', 'Neck1', 'thorax', 'rib'];
    for (const n of left) expect(sideOf(n), n).toBe('left');
    for (const n of right) expect(sideOf(n), n).toBe('right');
    for (const n of centre) expect(sideOf(n), n).toBeNull();
  });
});

describe('findHead', () => {
  it('prefers a joint named exactly "head", else one containing it that is not an end site', () => {
    expect(findHead(['root', 'upperneck', 'head'])).toBe(2);
    expect(findHead(['Hips', 'Head', 'Head_end'])).toBe(1);
    expect(findHead(['Hips', 'Head_end', 'HeadTop'])).toBe(-1);
  });
});
