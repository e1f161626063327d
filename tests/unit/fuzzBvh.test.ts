// Seeded fuzzing of the BVH importer (issue 21): real corpus clips truncated, bit-flipped, given junk tokens,
// huge and non-finite numbers, other line endings and absurd frame counts, plus generated deep and wide skeletons.
// Every case must be rejected with a short Error naming BVH or accepted with finite positions, within the
// parse-work budget of checkFuzzCase (tests/unit/fuzz.ts): counted steps, not time.
import { describe, expect, it } from 'vitest';
import { MAX_JOINTS } from '../../web/motion/validate';
import { parseBVH } from '../../web/motion/bvh';
import { readCorpus } from './corpus';
import { generatedBVH } from './bvhText';
import {
  HIERARCHY_SIZES, HUGE_COUNTS, byteFlips, checkFuzzCase, hierarchyParents, hugeNumbers, junkTokens, lineEndings, seededRandom, truncated,
  type FuzzCase, type FuzzOutcome, type HierarchyShape, type Random,
} from './fuzz';

const KINDS = ['BVH'];
const FRAMES = 20;

/** A corpus clip cut to its first FRAMES frames (so hundreds of cases stay quick), "Frames:" adjusted. */
function shortClip(path: string): string {
  const lines = readCorpus(path).split('\n');
  const frameTime = lines.findIndex((l) => l.startsWith('Frame Time'));
  const kept = lines.slice(0, frameTime + 1 + FRAMES);
  return kept.map((l) => (l.startsWith('Frames:') ? `Frames: ${FRAMES}` : l)).join('\n') + '\n';
}

const CLIPS = [
  { name: 'CMU 07_04', text: shortClip('cmu/bvh/07_04.bvh.gz') },
  { name: 'acLSTM salsa 01', text: shortClip('aclstm/salsa/01.bvh.gz') },
];

/** Runs `count` cases made by `make` from each clip (one seeded stream per clip) and tallies the outcomes. */
function fuzzClips(seed: number, count: number, make: (random: Random, text: string) => FuzzCase, check?: (clip: string, c: FuzzCase, outcome: FuzzOutcome) => void) {
  const tally: Record<FuzzOutcome, number> = { accepted: 0, rejected: 0 };
  CLIPS.forEach(({ name, text }, k) => {
    const random = seededRandom(seed + k);
    for (let n = 0; n < count; n++) {
      const c = make(random, text);
      const outcome = checkFuzzCase(`seed ${seed + k} case ${n} (${name}, ${c.what})`, () => parseBVH(c.text), c.text.length, KINDS);
      check?.(text, c, outcome);
      tally[outcome]++;
    }
  });
  return tally;
}

describe('BVH fuzzing (seeded, reproducible)', () => {
  it('truncations at random offsets: rejected unless the cut is inside the last number', () => {
    fuzzClips(2101, 60, truncated, (clip, c, outcome) => {
      // The one undetectable cut (docs/api.md): inside the last number, at the end of the file.
      const lastNumberStart = clip.trimEnd().search(/\S+$/);
      if (outcome === 'accepted') expect(c.text.length, c.what).toBeGreaterThan(lastNumberStart);
    });
  });

  it('bit flips', () => {
    fuzzClips(2111, 60, byteFlips);
  });

  it('junk tokens inserted', () => {
    fuzzClips(2151, 60, junkTokens);
  });

  it('huge, non-finite and non-decimal numbers anywhere in the file: rejected unless all are denormal', () => {
    // Every number in a BVH file is bounded (OFFSETs, channel counts, Frames, Frame Time, channel values),
    // so only a tiny denormal (1e-320, read as a rotation or position of about 0) can be accepted.
    fuzzClips(2121, 60, hugeNumbers, (clip, c, outcome) => {
      const replacements = [...c.what.matchAll(/ → (\S+) at /g)].map((m) => m[1]);
      if (outcome === 'accepted') expect(replacements.every((huge) => huge === '1e-320'), c.what).toBe(true);
    });
  });

  it('line-ending variants read exactly as the original', () => {
    const originals = new Map(CLIPS.map(({ text }) => [text, parseBVH(text)]));
    const tally = fuzzClips(2131, 20, lineEndings, (clip, c, outcome) => {
      expect(outcome, c.what).toBe('accepted');
      expect(parseBVH(c.text).positions, c.what).toEqual(originals.get(clip)!.positions);
    });
    expect(tally.accepted).toBe(40);
  });

  it('huge declared frame counts are rejected (a short BVH message, within the parse-work budget)', () => {
    for (const { name, text } of CLIPS) {
      for (const count of HUGE_COUNTS) {
        const damaged = text.replace(/^Frames:.*$/m, `Frames: ${count}`);
        expect(checkFuzzCase(`${name}, Frames: ${count}`, () => parseBVH(damaged), damaged.length, KINDS)).toBe('rejected');
      }
    }
  });

  it('deep, wide and random skeletons: accepted up to the joint limit, rejected past it, without recursion', () => {
    const random = seededRandom(2141);
    for (const shape of ['chain', 'wide', 'random'] as HierarchyShape[]) {
      for (const joints of HIERARCHY_SIZES) {
        const text = generatedBVH(hierarchyParents(random, shape, joints));
        const outcome = checkFuzzCase(`${shape} skeleton of ${joints} joints`, () => parseBVH(text), text.length, KINDS);
        expect(outcome, `${shape} ${joints}`).toBe(joints <= MAX_JOINTS ? 'accepted' : 'rejected');
      }
    }
  });
});

describe('BVH parse work', () => {
  it('stays within the budget when thousands of zero-offset joints without channels sit above every frame', () => {
    // 3000 nested joints that coincide with the root and have no channels, one End Site, 20,000 frames.
    const depth = 3000;
    const frames = 20_000;
    let text = 'HIERARCHY\nROOT hips\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n';
    for (let j = 0; j < depth; j++) text += `JOINT z${j}\n{\nOFFSET 0 0 0\nCHANNELS 0\n`;
    text += 'End Site\n{\nOFFSET 0 170 0\n}\n' + '}\n'.repeat(depth + 1);
    text += `MOTION\nFrames: ${frames}\nFrame Time: 0.01\n` + '0 0 0\n'.repeat(frames);
    expect(checkFuzzCase('3000 zero-offset joints', () => parseBVH(text), text.length, KINDS)).toBe('accepted');
    expect(parseBVH(text).joints).toEqual(['hips', `z${depth - 1}_end`]);
  });
});
