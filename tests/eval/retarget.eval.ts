// npm run evaluate:retarget → docs/models/retarget.json and retarget.md: web/motion/retarget.ts on character rigs of
// five namings and the project's CC0 character, each source retargeted with and without the foot IK and measured as
// tests/unit/retarget.test.ts measures it (tests/unit/retargetCases.ts). The page is written from the numbers here.
import { writeFileSync } from 'node:fs';
import { it } from 'vitest';
import { retarget, type CharacterRig } from '../../web/motion/retarget';
import type { Motion } from '../../web/motion/types';
import { REPO_ROOT } from '../unit/corpus';
import { PLANTED_FLOOR, RIGS, buildRig, loadSources, measure, quaterniusRig, type Measures } from '../unit/retargetCases';

interface Row {
  rig: string;
  source: string;
  scale: number;
  unitsPerMetre: number;
  withIK: Measures;
  withoutIK: Measures;
  met: boolean;
}

const SLIDING_MARGIN = 0.03;
const ANGLE_LIMIT = 10;

/** A sliding difference in words: over or under the source's. */
const slideWords = (d: number) => (d > 0 ? `at most ${d.toFixed(3)} m/s over the source's` : `under the source's in every row (the closest ${(-d).toFixed(3)} m/s under)`);
const f2 = (x: number) => x.toFixed(2);
const f3 = (x: number) => x.toFixed(3);
const cm = (x: number) => (100 * x).toFixed(1);

/** How a live stream retargeted window by window (31 frames ending at each new one, as the viewer does) compares with the whole retargeting. */
interface Live { withCalibration: { mean: number; max: number }; without: { mean: number; max: number } }

function liveWindows(stream: Motion, rig: CharacterRig): Live {
  const J = stream.joints.length, B = rig.bones.length;
  const whole = retarget(stream, rig);
  const run = (calibrated: boolean) => {
    let sum = 0, n = 0, max = 0;
    for (let end = 31; end <= stream.frames; end++) {
      const from = end - 31;
      const window = { ...stream, frames: 31, positions: stream.positions.slice(from * J * 3, end * J * 3), contacts: stream.contacts?.slice(from * 2, end * 2) };
      const live = retarget(window, rig, calibrated ? { calibration: whole.calibration } : {}).motion.positions;
      for (let b = 0; b < B; b++) {
        const o = 30 * B * 3 + b * 3, w = (end - 1) * B * 3 + b * 3;
        const d = Math.hypot(live[o] - whole.motion.positions[w], live[o + 1] - whole.motion.positions[w + 1], live[o + 2] - whole.motion.positions[w + 2]);
        sum += d;
        n++;
        max = Math.max(max, d);
      }
    }
    return { mean: sum / n, max };
  };
  return { withCalibration: run(true), without: run(false) };
}

function markdown(rows: Row[], rigLabels: Array<[string, string]>, sources: string[], sourceWords: string[], live: Live): string {
  const met = rows.filter((r) => r.met).length;
  const worst = (pick: (r: Row) => number) => rows.reduce((a, b) => (pick(b) > pick(a) ? b : a));
  const worstAngle = worst((r) => r.withIK.angle);
  const worstSlide = worst((r) => r.withIK.sliding - r.withIK.sourceSliding);
  const worstPlanted = worst((r) => r.withIK.planted95);
  const maxPlanted = worst((r) => r.withIK.plantedMax);
  const worstBone = worst((r) => r.withIK.worstBoneAngle);
  const lines = [
    '# Retargeting onto your own character (issue 40)',
    '',
    '- **What it does:** `retarget(motion, rig)` (web/motion/retarget.ts) plays any humanoid motion on a character\'s own skeleton: each bone turned as the source\'s, rest poses aligned, proportions scaled by leg length, planted feet held on the floor by leg IK.',
    '- **In the page:** the character you load (`loadCharacter`) is driven by the `rotations` and root translations it returns; its `motion` is the character\'s bones\' world positions.',
    `- **On ${rigLabels.length} rigs × ${sources.length} sources:** ${met} of ${rows.length} meet all three bars; mean limb angle to the source at most ${f2(worstAngle.withIK.angle)}° (bar 10°); lowest-foot sliding ${slideWords(worstSlide.withIK.sliding - worstSlide.withIK.sourceSliding)}; bar: the source's + 0.03 m/s.`,
    `- **Planted feet:** 95% of planted foot-frames within ${cm(worstPlanted.withIK.planted95)} cm of the floor in every row and all within ${cm(maxPlanted.withIK.plantedMax)} cm (bar 3 cm), mean ${cm(Math.max(...rows.map((r) => r.withIK.plantedMean)))} cm at most; without the foot IK the 95th percentile is up to ${cm(Math.max(...rows.map((r) => r.withoutIK.planted95)))} cm.`,
    `- **Not met:** ${rows.length - met === 0 ? 'no row fails a bar; ' : `${rows.length - met} rows fail a bar; `}the foot bone alone differs from the source's by up to ${f2(worstBone.withIK.worstBoneAngle)}° (${worstBone.rig}, ${worstBone.source}), by design: a flat foot stays flat on a rig whose foot slopes otherwise. The rigs but one are built in the test, not loaded from files.`,
    '',
    '## How it works',
    'The source becomes the 25 canonical points (web/motion/humanoid.ts maps any humanoid skeleton; skeletonMap.ts places the points it lacks). The rig\'s rest pose is mapped the same way. Per frame each mapped bone\'s world rotation is the rotation that takes its rest segment (to the next canonical point) and a twist reference (the hip line, the shoulder line, the knee\'s or elbow\'s bend with the foot\'s or chest\'s forward) to the source\'s, times its rest world rotation; a rig\'s T or A pose, a rest pose facing −z and bone axes that do not follow the bones cancel out. Bones the map does not name (fingers, twist bones, clavicles, a root at the floor) keep their rest rotation under their parent. The feet and toes are turned by the difference between the rig\'s rest slope and the source\'s flat-foot slope, so a flat foot stays flat. The legs\' hip joints follow the source\'s, scaled by leg length, with the ankles as high as the source\'s. Where the source\'s feet are planted (its contacts, else labelled from height and speed) the character\'s foot stands on its lowest point (heel, ball or a toe-tip bone, each against its rest height), held where the contact began, by two-bone IK on thigh and shin; a push-off out of reach turns the foot about the ball or tip, and the hips come down where even that does not reach. Corrections fade in and out over 0.15 s.',
    '',
    "## Results (npm run evaluate:retarget)",
    'Angle: mean over frames of the angle between each mapped limb bone of the character and the source\'s (thigh, shin, foot, upper arm, forearm, hips→neck, neck→head); worst bone: the largest per-bone mean. Sliding: the reports\' lowest-foot sliding (footSkating.ts lowFootSliding: the lowest foot point\'s horizontal speed while within 4 cm of the floor, at 30 fps) of the source on y = 0 and of the character on its floor raised by how much higher its planted lowest foot point stands than the source\'s (foot joints sit at different heights inside different feet); on a rig without toe-tip bones both are measured on ankle and toe base. Planted: over the source\'s planted frames, the height of the character\'s lowest foot point (heel, ball, toe-tip bone) above the floor less that point\'s height in the rig\'s rest pose: mean / 95th percentile / largest, cm. "No IK": the same with `footIK: false`.',
    '',
    '| Rig | Source | Scale | Angle (°) | Worst bone (°) | Sliding: source → character (m/s) | Planted mean / p95 / max (cm) | No IK: sliding, planted p95 | Met |',
    '|---|---|---|---|---|---|---|---|---|',
    ...rows.map((r) => `| ${r.rig} | ${r.source} | ${f2(r.scale)} | ${f2(r.withIK.angle)} | ${f2(r.withIK.worstBoneAngle)} ${r.withIK.worstBone.replace('→', ' → ')} | ${f3(r.withIK.sourceSliding)} → ${f3(r.withIK.sliding)} | ${cm(r.withIK.plantedMean)} / ${cm(r.withIK.planted95)} / ${cm(r.withIK.plantedMax)} | ${f3(r.withoutIK.sliding)}, ${cm(r.withoutIK.planted95)} | ${r.met ? 'yes' : 'no'} |`),
    '',
    `Largest planted height: ${cm(maxPlanted.withIK.plantedMax)} cm (${maxPlanted.rig}, ${maxPlanted.source}).`,
    '',
    '## Live',
    `A live stream is retargeted window by window (web/viewer/userCharacter.ts: each new frame with the 30 before it). Passing the calibration of the stream's first retargeting (\`options.calibration\`: scale, ankle and sole heights, foot slopes) to every window keeps each new frame where the whole motion's retargeting puts it: on the Quaternius character and the model-like walk, bones within ${cm(live.withCalibration.max)} cm of it (mean ${cm(live.withCalibration.mean)} cm); measured window by window instead, up to ${cm(live.without.max)} cm off (mean ${cm(live.without.mean)} cm).`,
    '',
    '## The rigs and sources',
    '| Rig | What it is |',
    '|---|---|',
    ...rigLabels.map(([name, what]) => `| ${name} | ${what} |`),
    '',
    `Sources: ${sourceWords.join('; ')}. Each is rested with its feet' 5th-percentile lowest point on y = 0; the model-like one is the walk on the canonical skeleton with contact labels, as the locomotion models give. Planted frames: the source's contacts where it has them, else labelled from foot height and speed (contactLabels.ts); a planted foot follows the source's foot up to 2 cm above the floor at a contact's first and last frames, hence the 2.0 cm. The rigs are built as a glTF loader would give them (tests/unit/retargetCases.ts); the Quaternius character is read from its GLB file.`,
    '',
  ];
  return lines.join('\n');
}

it('writes docs/models/retarget.md', () => {
  const sources = loadSources();
  const rigs: Array<{ name: string; what: string; rig: CharacterRig }> = [
    ...RIGS.map((spec) => ({ name: spec.label.split(' (')[0], what: spec.label.slice(spec.label.indexOf('(') + 1, -1), rig: buildRig(spec) })),
    { name: 'Quaternius (GLB)', what: 'the CC0 character ../shared/characters/quaternius-human-male.glb: Unreal-style names, metres, T-pose, the file\'s rest rotations, its root turned from z up', rig: quaterniusRig() },
  ];
  const rows: Row[] = [];
  for (const { name, rig } of rigs) {
    for (const source of sources) {
      const result = retarget(source.motion, rig);
      const withIK = measure(source.motion, result);
      const withoutIK = measure(source.motion, retarget(source.motion, rig, { footIK: false }));
      const met = withIK.angle <= ANGLE_LIMIT && withIK.sliding <= withIK.sourceSliding + SLIDING_MARGIN && withIK.planted95 <= PLANTED_FLOOR;
      rows.push({ rig: name, source: source.label, scale: result.scale, unitsPerMetre: result.unitsPerMetre, withIK, withoutIK, met });
    }
  }
  const live = liveWindows(sources[3].motion, rigs[rigs.length - 1].rig);
  writeFileSync(`${REPO_ROOT}docs/models/retarget.json`, JSON.stringify({ rows, live }, null, 1) + '\n');
  const sourceWords = sources.map(({ label, motion }) => `${label}: ${motion.frames} frames at ${motion.fps} fps, ${motion.joints.length} joints${motion.contacts ? ', with contacts' : ''}`);
  writeFileSync(`${REPO_ROOT}docs/models/retarget.md`, markdown(rows, rigs.map((r) => [r.name, r.what]), sources.map((s) => s.label), sourceWords, live));
  console.log(`${rows.filter((r) => r.met).length} of ${rows.length} rows meet the bars`);
}, 600_000);
