// Seeded fuzzing of ASF/AMC import (importMotion, as the page calls it): each case, built from its seed alone,
// is rejected with a short Error naming the file kind or accepted with finite positions, within the parse
// work budget (checkFuzzCase in fuzz.ts). A failure message starts with the seed that reproduces it.
import { describe, expect, it } from 'vitest';
import { importMotion } from '../../web/motion/io';
import { MAX_JOINTS } from '../../web/motion/validate';
import { readCorpus } from './corpus';
import {
  HIERARCHY_SIZES, HUGE_COUNTS, byteFlips, checkFuzzCase, generatedAMC, generatedASF, hierarchyParents, hugeNumbers, lineEndings,
  parentLinks, seededRandom, truncated, type FuzzCase, type FuzzOutcome, type HierarchyShape, type Random,
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

/** Each format's case kinds take turns with the seed, so every kind (and every hierarchy) is covered. */
const KINDS = 5;
const SHAPES: HierarchyShape[] = ['chain', 'wide', 'random'];

/** One ASF case: the skeleton damaged (or generated) and an AMC to read with it. */
function asfCase(seed: number, random: Random, clip: Clip): FuzzCase & { amc: string } {
  const kind = seed % KINDS;
  if (kind === 0) return { ...truncated(random, clip.asf), amc: clip.fourFrames };
  if (kind === 1) return { ...byteFlips(random, clip.asf), amc: clip.fourFrames };
  if (kind === 2) return { ...hugeNumbers(random, clip.asf), amc: clip.fourFrames };
  if (kind === 3) return { ...lineEndings(random, clip.asf), amc: clip.fourFrames };
  const turn = Math.floor(seed / KINDS);
  return generatedHierarchy(random, SHAPES[turn % SHAPES.length], HIERARCHY_SIZES[Math.floor(turn / SHAPES.length) % HIERARCHY_SIZES.length]);
}

/** A generated skeleton (deep, wide or random; under, at or far over the joint limit), maybe with a cycle. */
function generatedHierarchy(random: Random, shape: HierarchyShape, joints: number): FuzzCase & { amc: string } {
  const links = parentLinks(hierarchyParents(random, shape, joints));
  const bones = joints - 1;
  const cycle = random.next() < 0.25 && bones > 1;
  if (cycle) links.push([1 + random.int(bones), 1 + random.int(bones)]);
  return {
    what: `generated ${shape} hierarchy of ${joints} joints${cycle ? ` with the extra link ${links[links.length - 1].join(' → ')}` : ''}`,
    text: generatedASF(bones, links),
    amc: generatedAMC(random, Math.min(bones, MAX_JOINTS - 1), 2),
  };
}

/** One AMC case, for the clip's own skeleton. */
function amcCase(seed: number, random: Random, clip: Clip): FuzzCase {
  const kind = seed % KINDS;
  if (kind === 0) return truncated(random, clip.amc);
  if (kind === 1) return byteFlips(random, clip.fourFrames);
  if (kind === 2) return hugeNumbers(random, clip.fourFrames);
  if (kind === 3) return lineEndings(random, clip.fourFrames);
  // AMC declares no frame count; its frame numbers are what can be huge.
  const frame = random.pick(clip.frameNumbers);
  const huge = random.pick(HUGE_COUNTS);
  return { what: `frame number ${frame} → ${huge}`, text: clip.fourFrames.replace(new RegExp(`^${frame}$`, 'm'), huge) };
}

/** Runs every seed's case; returns the outcomes by what was done (the `what` up to its first detail). */
function runCases(check: (seed: number) => { what: string; outcome: FuzzOutcome }): Map<string, Record<FuzzOutcome, number>> {
  const tally = new Map<string, Record<FuzzOutcome, number>>();
  for (let seed = FIRST_SEED; seed < FIRST_SEED + CASES_PER_FORMAT; seed++) {
    const { what, outcome } = check(seed);
    const group = what.replace(/^(truncated|bits flipped|numbers replaced|line endings|generated \w+|frame number).*$/, '$1');
    const counts = tally.get(group) ?? { accepted: 0, rejected: 0 };
    counts[outcome]++;
    tally.set(group, counts);
  }
  return tally;
}

describe('fuzzed ASF/AMC import (seeded)', () => {
  const reference = CLIPS.map((clip) => importMotion(clip.fourFrames, 'amc', clip.asf).positions);

  it(`ASF: ${CASES_PER_FORMAT} damaged or generated skeletons`, () => {
    const tally = runCases((seed) => {
      const random = seededRandom(seed);
      const clipIndex = random.int(CLIPS.length);
      const c = asfCase(seed, random, CLIPS[clipIndex]);
      const label = `seed ${seed}, ASF ${c.what}`;
      let positions: Float32Array | undefined;
      const outcome = checkFuzzCase(label, () => {
        const motion = importMotion(c.amc, 'amc', c.text);
        positions = motion.positions;
        return motion;
      }, c.text.length + c.amc.length, ['ASF', 'AMC']);
      if (c.what.startsWith('line endings')) expect(positions && Array.from(positions), label).toEqual(Array.from(reference[clipIndex]));
      return { what: c.what, outcome };
    });
    expect(tally.get('line endings')?.rejected ?? 0).toBe(0);
    for (const group of ['truncated', 'bits flipped', 'numbers replaced']) expect(tally.get(group)?.rejected, group).toBeGreaterThan(0);
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
    const tally = runCases((seed) => {
      const random = seededRandom(seed);
      const clipIndex = random.int(CLIPS.length);
      const clip = CLIPS[clipIndex];
      const c = amcCase(seed, random, clip);
      const label = `seed ${seed}, AMC ${c.what}`;
      let positions: Float32Array | undefined;
      const outcome = checkFuzzCase(label, () => {
        const motion = importMotion(c.text, 'amc', clip.asf);
        positions = motion.positions;
        return motion;
      }, c.text.length + clip.asf.length, ['AMC']);
      if (c.what.startsWith('line endings')) expect(positions && Array.from(positions), label).toEqual(Array.from(reference[clipIndex]));
      return { what: c.what, outcome };
    });
    expect(tally.get('line endings')?.rejected ?? 0).toBe(0);
    for (const group of ['truncated', 'bits flipped', 'numbers replaced', 'frame number']) expect(tally.get(group)?.rejected, group).toBeGreaterThan(0);
  });
});
