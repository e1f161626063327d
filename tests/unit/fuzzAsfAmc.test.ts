// Seeded fuzzing of ASF/AMC import (importMotion, as the page calls it): each case, built from its seed alone,
// is rejected with a short Error naming the file kind or accepted with finite positions, within the parse
// work budget (checkFuzzCase in fuzz.ts). A failure message starts with the seed that reproduces it.
import { describe, expect, it } from 'vitest';
import { importMotion } from '../../web/motion/io';
import { MAX_JOINTS } from '../../web/motion/validate';
import { readCorpus } from './corpus';
import {
  HIERARCHY_SIZES, HUGE_COUNTS, byteFlips, checkFuzzCase, generatedAMC, generatedASF, hierarchyParents, hugeNumbers, junkTokens,
  lineEndings, parentLinks, seededRandom, truncated, type FuzzOutcome, type HierarchyShape, type Random,
} from './fuzz';

const CASES_PER_FORMAT = 300;
const FIRST_SEED = 21_000;

/** Real clips: a skeleton, the whole clip (for truncation) and its first frames (for the other damage). */
const CLIPS = [
  { asf: 'cmu/asf/16.asf', amc: 'cmu/amc/16_11.amc.gz' },
  { asf: 'cmu/asf/35.asf', amc: 'cmu/amc/35_01.amc.gz' },
  { asf: 'cmu/asf/07.asf', amc: 'cmu/amc/07_01.amc.gz' },
].map(({ asf, amc }) => {
  const amcText = readCorpus(amc); // kept as it is (35_01 has CRLF line ends) for truncation
  const lines = amcText.split(/\r?\n/);
  const frameLines = lines.flatMap((line, i) => (/^\d+$/.test(line) ? [i] : [])).slice(0, 5);
  const fourFrames = lines.slice(0, frameLines[4]).join('\n') + '\n';
  return { asf: readCorpus(asf), amc: amcText, fourFrames, frameNumbers: frameLines.slice(0, 4).map((i) => lines[i]) };
});

type Clip = (typeof CLIPS)[number];

/** Each clip's first frames as imported undamaged: what a line-ending variant must read as. */
const REFERENCE = CLIPS.map((clip) => importMotion(clip.fourFrames, 'amc', clip.asf).positions);

/** One case: the skeleton and motion texts to import, what was done to them, and the outcome it must have when known. */
interface AsfAmcCase {
  what: string;
  asf: string;
  amc: string;
  expected?: FuzzOutcome;
}

/** Damage done to a real file; each format's cases take turns with the seed through these and one more kind. */
const DAMAGES = [truncated, byteFlips, hugeNumbers, lineEndings, junkTokens];
/** The damages, then a generated hierarchy (ASF) or a huge frame number (AMC), so every kind (and every hierarchy) is covered. */
const KINDS = DAMAGES.length + 1;
const SHAPES: HierarchyShape[] = ['chain', 'wide', 'random'];

/** One ASF case: the skeleton damaged (or generated) and an AMC to read with it. */
function asfCase(seed: number, random: Random, clip: Clip): AsfAmcCase {
  const kind = seed % KINDS;
  if (kind < DAMAGES.length) {
    const { what, text } = DAMAGES[kind](random, clip.asf);
    return { what, asf: text, amc: clip.fourFrames };
  }
  const turn = Math.floor(seed / KINDS);
  return generatedHierarchy(random, SHAPES[turn % SHAPES.length], HIERARCHY_SIZES[Math.floor(turn / SHAPES.length) % HIERARCHY_SIZES.length]);
}

/**
 * A generated skeleton (deep, wide or random; under, at or far over the joint limit), maybe with an extra link
 * (which lists a bone under a second parent, perhaps making a cycle): accepted only within the limit and without it.
 */
function generatedHierarchy(random: Random, shape: HierarchyShape, joints: number): AsfAmcCase {
  const links = parentLinks(hierarchyParents(random, shape, joints));
  const bones = joints - 1;
  const cycle = random.next() < 0.25 && bones > 1;
  if (cycle) links.push([1 + random.int(bones), 1 + random.int(bones)]);
  return {
    what: `generated ${shape} hierarchy of ${joints} joints${cycle ? ` with the extra link ${links[links.length - 1].join(' → ')}` : ''}`,
    asf: generatedASF(bones, links),
    amc: generatedAMC(random, Math.min(bones, MAX_JOINTS - 1), 2),
    expected: joints <= MAX_JOINTS && !cycle ? 'accepted' : 'rejected',
  };
}

/** One AMC case, for the clip's own skeleton: the whole clip truncated, its first frames otherwise damaged. */
function amcCase(seed: number, random: Random, clip: Clip): AsfAmcCase {
  const kind = seed % KINDS;
  if (kind < DAMAGES.length) {
    const { what, text } = DAMAGES[kind](random, DAMAGES[kind] === truncated ? clip.amc : clip.fourFrames);
    return { what, asf: clip.asf, amc: text };
  }
  // AMC declares no frame count; its frame numbers are what can be huge.
  const frame = random.pick(clip.frameNumbers);
  const huge = random.pick(HUGE_COUNTS);
  return { what: `frame number ${frame} → ${huge}`, asf: clip.asf, amc: clip.fourFrames.replace(new RegExp(`^${frame}$`, 'm'), huge) };
}

/**
 * Imports every seed's case (made by `makeCase` from the clip the seed picks) and checks it: checkFuzzCase with
 * the file kinds its message may name, the outcome the case expects, and a line-ending variant reading exactly as
 * the clip. Returns the outcomes by what was done (the case's `what` up to its first detail).
 */
function fuzzCases(format: string, kinds: readonly string[], makeCase: (seed: number, random: Random, clip: Clip) => AsfAmcCase): Map<string, Record<FuzzOutcome, number>> {
  const tally = new Map<string, Record<FuzzOutcome, number>>();
  for (let seed = FIRST_SEED; seed < FIRST_SEED + CASES_PER_FORMAT; seed++) {
    const random = seededRandom(seed);
    const clipIndex = random.int(CLIPS.length);
    const c = makeCase(seed, random, CLIPS[clipIndex]);
    const label = `seed ${seed}, ${format} ${c.what}`;
    let positions: Float32Array | undefined;
    const outcome = checkFuzzCase(label, () => {
      const motion = importMotion(c.amc, 'amc', c.asf);
      positions = motion.positions;
      return motion;
    }, c.asf.length + c.amc.length, kinds);
    if (c.expected) expect(outcome, label).toBe(c.expected);
    if (c.what.startsWith('line endings')) expect(positions && Array.from(positions), label).toEqual(Array.from(REFERENCE[clipIndex]));
    const group = c.what.replace(/^(truncated|bits flipped|numbers replaced|junk inserted|line endings|generated \w+|frame number).*$/, '$1');
    const counts = tally.get(group) ?? { accepted: 0, rejected: 0 };
    counts[outcome]++;
    tally.set(group, counts);
  }
  return tally;
}

describe('fuzzed ASF/AMC import (seeded)', () => {
  it(`ASF: ${CASES_PER_FORMAT} damaged or generated skeletons`, () => {
    const tally = fuzzCases('ASF', ['ASF', 'AMC'], asfCase);
    for (const group of ['truncated', 'bits flipped', 'numbers replaced', 'junk inserted']) expect(tally.get(group)?.rejected, group).toBeGreaterThan(0);
    for (const shape of SHAPES) expect(tally.get(`generated ${shape}`)?.accepted, shape).toBeGreaterThan(0);
  });

  it('skeletons at the joint limit whose bones have no dofs, with frames past the position limit: rejected within the budget', () => {
    const random = seededRandom(FIRST_SEED);
    for (const shape of SHAPES) {
      const asf = generatedASF(MAX_JOINTS - 1, parentLinks(hierarchyParents(random, shape, MAX_JOINTS)), '');
      const frames = 33_000 + random.int(10_000);
      const amc = generatedAMC(random, 0, frames);
      const label = `seed ${FIRST_SEED}, dof-less ${shape} skeleton of ${MAX_JOINTS} joints × ${frames} frames`;
      expect(checkFuzzCase(label, () => importMotion(amc, 'amc', asf), asf.length + amc.length, ['AMC']), label).toBe('rejected');
    }
  });

  it(`AMC: ${CASES_PER_FORMAT} damaged clips`, () => {
    const tally = fuzzCases('AMC', ['AMC'], amcCase);
    for (const group of ['truncated', 'bits flipped', 'numbers replaced', 'junk inserted', 'frame number']) expect(tally.get(group)?.rejected, group).toBeGreaterThan(0);
  });
});
