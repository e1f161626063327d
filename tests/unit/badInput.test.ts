// Malformed input: every case must raise a MotionFormatError that names the format, the line where
// known and what was expected — never hang, never return NaN positions.
import { describe, expect, it } from 'vitest';
import { parseBVH } from '../../web/motion/bvh';
import { parseAMC, parseASF } from '../../web/motion/asfamc';
import { importMotion } from '../../web/motion/io';
import { MotionFormatError } from '../../web/motion/types';
import { readCorpus } from './corpus';
import { MAX_JOINTS } from '../../web/motion/validate';
import { generatedBVH } from './bvhText';
import { checkFuzzCase, generatedAMC, generatedASF, hierarchyParents, parentLinks, seededRandom } from './fuzz';
import { MAX_VALUES } from '../../web/motion/text';

/** Runs fn, expects a MotionFormatError of that format (and line), returns its message. */
function formatError(fn: () => unknown, format: 'bvh' | 'amc' | 'asf', line?: number): string {
  let error: unknown;
  try {
    fn();
  } catch (e) {
    error = e;
  }
  expect(error).toBeInstanceOf(MotionFormatError);
  const e = error as MotionFormatError;
  expect(e.format).toBe(format);
  if (line !== undefined) expect(e.line).toBe(line);
  return e.message;
}

const BVH = readCorpus('cmu/bvh/07_04.bvh.gz');
const BVH_LINES = BVH.split('\n');
const FIRST_FRAME_LINE = 188; // 1-based line of the first frame in 07_04
const withLine = (lineNo: number, replace: (line: string) => string) =>
  BVH_LINES.map((l, i) => (i === lineNo - 1 ? replace(l) : l)).join('\n');

const ASF = readCorpus('cmu/asf/16.asf');
const AMC = readCorpus('cmu/amc/16_11.amc.gz');
const AMC_LINES = AMC.split('\n');
const amcWithLine = (lineNo: number, replace: (line: string) => string) =>
  AMC_LINES.map((l, i) => (i === lineNo - 1 ? replace(l) : l)).join('\n');

describe('bad BVH input', () => {
  it('rejects an empty file', () => {
    expect(formatError(() => parseBVH(''), 'bvh')).toBe('BVH: file is empty');
    expect(formatError(() => parseBVH('  \n\t\n'), 'bvh')).toBe('BVH: file is empty');
  });

  it('rejects binary junk', () => {
    expect(formatError(() => parseBVH('HIERARCHY\0\0\u0001ROOT'), 'bvh')).toMatch(/NUL bytes/);
    let junk = '';
    for (let i = 0; i < 2000; i++) junk += String.fromCharCode((i * 7919) % 256);
    expect(formatError(() => parseBVH(junk.replace(/\0/g, '\u0001')), 'bvh')).toMatch(/looks binary/);
  });

  it('rejects a file truncated inside the hierarchy', () => {
    const cut = BVH_LINES.slice(0, 100).join('\n');
    expect(formatError(() => parseBVH(cut), 'bvh', 100)).toMatch(/unexpected end of file, expected .*\(file truncated\?\)/);
  });

  it('rejects a file truncated inside the motion data', () => {
    // Cut in the middle of a frame line: that line has too few numbers.
    const cutMidLine = BVH_LINES.slice(0, 300).join('\n').slice(0, -40);
    expect(formatError(() => parseBVH(cutMidLine), 'bvh', 300)).toMatch(/^BVH line 300: expected 96 numbers per frame, found \d\d$/);
    // Cut at a line end: fewer frame lines than "Frames:" declares.
    const cutAtLine = BVH_LINES.slice(0, 300).join('\n');
    expect(formatError(() => parseBVH(cutAtLine), 'bvh', 186)).toBe('BVH line 186: "Frames:" declares 450 frames but the file has 113 frame lines (file truncated?)');
  });

  it('rejects frame lines with too few or too many numbers', () => {
    const fewer = withLine(212, (l) => l.trim().split(/\s+/).slice(0, 93).join(' '));
    expect(formatError(() => parseBVH(fewer), 'bvh', 212)).toBe('BVH line 212: expected 96 numbers per frame, found 93');
    expect(formatError(() => parseBVH(withLine(212, (l) => l + ' 1.5')), 'bvh', 212)).toBe('BVH line 212: expected 96 numbers per frame, found 97');
  });

  it('rejects NaN, infinities and non-numeric values', () => {
    for (const bad of ['NaN', 'nan', 'Infinity', '-inf', 'abc', '1.2.3', '0x1F', '1e999', '12,5']) {
      const text = withLine(FIRST_FRAME_LINE + 3, (l) => l.replace(/^(\S+\s+\S+\s+)\S+/, `$1${bad}`));
      expect(formatError(() => parseBVH(text), 'bvh', FIRST_FRAME_LINE + 3)).toBe(`BVH line ${FIRST_FRAME_LINE + 3}: expected a position in file units, found "${bad}"`);
    }
    expect(formatError(() => parseBVH(BVH.replace('OFFSET 2.36836 -6.50702 0.00000', 'OFFSET 2.36836 NaN 0.00000')), 'bvh', 16)).toMatch(/expected an OFFSET y value in file units, found "NaN"/);
  });

  it('rejects frame counts that do not match the data or are absurd', () => {
    expect(formatError(() => parseBVH(BVH.replace('Frames: 450', 'Frames: 449')), 'bvh', 637)).toBe('BVH line 637: more frame lines than the 449 declared by "Frames:" (line 186)');
    expect(formatError(() => parseBVH(BVH.replace('Frames: 450', 'Frames: 451')), 'bvh', 186)).toMatch(/declares 451 frames but the file has 450 frame lines/);
    expect(formatError(() => parseBVH(BVH.replace('Frames: 450', 'Frames: 5000000')), 'bvh', 186)).toBe('BVH line 186: declares 5000000 frames; at most 1000000 are supported');
    expect(formatError(() => parseBVH(BVH.replace('Frames: 450', 'Frames: -3')), 'bvh', 186)).toMatch(/expected a positive whole frame count/);
    expect(formatError(() => parseBVH(BVH.replace('Frames: 450', 'Frames: 4.5')), 'bvh', 186)).toMatch(/expected a positive whole frame count/);
    expect(formatError(() => parseBVH(BVH.replace('Frames: 450', 'Frames lots')), 'bvh', 186)).toMatch(/expected "Frames: <number>"/);
    expect(formatError(() => parseBVH(BVH.replace('Frame Time: .0083333', 'Frame Time: 0')), 'bvh', 187)).toMatch(/expected a frame time from 0.0001 to 1 second, found "0"/);
  });

  it('rejects more than 100 million values before allocating them', () => {
    // 40 joints × 3 + 6 = 126 channels × 900,000 frames ≈ 113M values.
    let hierarchy = 'HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n';
    for (let j = 1; j <= 40; j++) hierarchy += `JOINT j${j}\n{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Yrotation Xrotation\n`;
    hierarchy += 'End Site\n{\nOFFSET 0 1 0\n}\n' + '}\n'.repeat(41);
    const text = hierarchy + 'MOTION\nFrames: 900000\nFrame Time: 0.01\n0 0 0\n';
    expect(formatError(() => parseBVH(text), 'bvh')).toMatch(/declares 900000 frames × 126 channels = 113400000 values; at most 100000000 are supported/);
  });

  it('rejects files without a usable hierarchy', () => {
    expect(formatError(() => parseBVH('MOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0\n'), 'bvh', 1)).toBe('BVH line 1: expected "HIERARCHY" at the start, found "MOTION"');
    expect(formatError(() => parseBVH('HIERARCHY\nMOTION\nFrames: 1\nFrame Time: 0.1\n\n'), 'bvh')).toMatch(/unexpected end of file, expected "ROOT"/);
    expect(formatError(() => parseBVH('hello world\n'), 'bvh', 1)).toMatch(/expected "HIERARCHY" at the start, found "hello"/);
    expect(formatError(() => parseBVH(BVH.replace('ROOT Hips', 'ROOT')), 'bvh', 2)).toMatch(/expected a joint name/);
  });

  it('rejects unknown channels and wrong channel counts in the hierarchy', () => {
    expect(formatError(() => parseBVH(BVH.replace('CHANNELS 3 Zrotation Yrotation Xrotation', 'CHANNELS 3 Zrotation Wrotation Xrotation')), 'bvh', 9)).toMatch(/"Wrotation" is not a channel name/);
    expect(formatError(() => parseBVH(BVH.replace('CHANNELS 3 Zrotation Yrotation Xrotation', 'CHANNELS 2 Zrotation Yrotation Xrotation')), 'bvh', 9)).toMatch(/declares 2 channels but lists more/);
    expect(formatError(() => parseBVH(BVH.replace('CHANNELS 3 Zrotation Yrotation Xrotation', 'CHANNELS 4 Zrotation Yrotation Xrotation')), 'bvh')).toMatch(/"JOINT" is not a channel name/);
    expect(formatError(() => parseBVH(BVH.replace('CHANNELS 3 Zrotation Yrotation Xrotation', 'CHANNELS 9 Zrotation Yrotation Xrotation')), 'bvh', 9)).toMatch(/expected a channel count from 0 to 6, found "9"/);
  });

  it('rejects a second ROOT and stray tokens', () => {
    const two = BVH.replace('MOTION', 'ROOT Other\n{\nOFFSET 0 0 0\nCHANNELS 0\n}\nMOTION');
    expect(formatError(() => parseBVH(two), 'bvh', 185)).toMatch(/expected "MOTION" after the hierarchy, found a second ROOT/);
    expect(formatError(() => parseBVH(BVH.replace('OFFSET 0 0 0', 'OFSET 0 0 0')), 'bvh', 8)).toMatch(/unexpected "OFSET" in joint "LHipJoint"/);
  });

  it('rejects position values so large that positions would overflow, instead of returning non-finite numbers', () => {
    const text = withLine(FIRST_FRAME_LINE, (l) => l.replace(/^\S+/, '1e300'));
    expect(formatError(() => parseBVH(text), 'bvh', FIRST_FRAME_LINE)).toMatch(/expected a position in file units of at most 1000000000 in magnitude, found "1e300"$/);
  });
});

describe('hostile BVH input (issue 21)', () => {
  const LONG = 'q'.repeat(100_000);
  const SMALL = 'HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n}\nMOTION\nFrames: 1\nFrame Time: 0.04\n0 90 0\n';

  it('quotes at most 40 characters of the input, whatever the file holds', () => {
    expect(formatError(() => importMotion('x'.repeat(20e6), 'bvh'), 'bvh', 1)).toBe(`BVH line 1: expected "HIERARCHY" at the start, found "${'x'.repeat(40)}…"`);
    const sites: Array<[string, string]> = [
      ['joint name', SMALL.replace('ROOT Hips\n{\nOFFSET 0 0 0\n', `ROOT ${LONG}\n{\n`)],
      ['keyword', BVH.replace('OFFSET 0 0 0', `${LONG} 0 0 0`)],
      ['brace', BVH.replace('ROOT Hips\n{', `ROOT Hips\n${LONG}`)],
      ['End Site', BVH.replace('End Site', `End ${LONG}`)],
      ['channel name', BVH.replace('CHANNELS 3 Zrotation Yrotation', `CHANNELS 3 ${LONG} Yrotation`)],
      ['channel count', BVH.replace('CHANNELS 3 Zrotation', `CHANNELS ${LONG} Zrotation`)],
      ['after the hierarchy', BVH.replace('MOTION', `${LONG}\nMOTION`)],
      ['Frames line', BVH.replace('Frames: 450', LONG)],
      ['frame count', BVH.replace('Frames: 450', `Frames: ${LONG}`)],
      ['frame time', BVH.replace('Frame Time: .0083333', `Frame Time: ${LONG}`)],
      ['frame value', withLine(FIRST_FRAME_LINE, (l) => l.replace(/^\S+/, LONG))],
    ];
    for (const [site, text] of sites) {
      const message = formatError(() => parseBVH(text), 'bvh');
      expect(message.length, site).toBeLessThanOrEqual(300);
      expect(message, site).toContain(`"${'q'.repeat(40)}…"`);
      expect(message, site).not.toContain('q'.repeat(41));
    }
  });

  it('rejects hierarchies past the joint limit while reading them, however deep or wide', () => {
    // 3 × 1024 entries: room for an exported 1024-joint motion (helper joints and End Sites included).
    const tooMany = /^BVH line \d+: more than 3072 JOINT and End Site entries \(at most 1024 joints are supported\)$/;
    const random = seededRandom(21);
    for (const [shape, joints] of [['wide', 200_000], ['chain', 10_000], ['random', 20_000]] as const) {
      expect(formatError(() => parseBVH(generatedBVH(hierarchyParents(random, shape, joints))), 'bvh'), `${shape} ${joints}`).toMatch(tooMany);
    }
    // Under the entry limit, the joints that make it into the motion (non-zero OFFSETs) are counted.
    expect(formatError(() => parseBVH(generatedBVH(hierarchyParents(random, 'chain', 1025))), 'bvh')).toBe('BVH: 1025 joints with a non-zero OFFSET; at most 1024 are supported');
    const chain = parseBVH(generatedBVH(hierarchyParents(random, 'chain', 1024)));
    expect(chain.joints.length).toBe(1024);
    expect(chain.parents[1023]).toBe(1022);
  });

  it('rejects declared frame counts whose positions would pass 100 million values, before reading frames', () => {
    // 1000 joints with no channels of their own: 1 value per frame line but 3000 position values per frame.
    let text = 'HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 1 Xposition\n';
    for (let j = 1; j < 1000; j++) text += `JOINT j${j}\n{\nOFFSET 0 0.1 0\nCHANNELS 0\n}\n`;
    text += '}\nMOTION\nFrames: 40000\nFrame Time: 0.01\n0\n';
    expect(formatError(() => parseBVH(text), 'bvh', 5003)).toBe('BVH line 5003: declares 40000 frames × 1000 joints × 3 = 120000000 position values; at most 100000000 are supported');
  });

  it('rejects absurd but finite values, naming the bound', () => {
    const value = (index: number, v: string) => withLine(FIRST_FRAME_LINE, (l) => l.trim().split(/\s+/).map((x, i) => (i === index ? v : x)).join(' '));
    expect(formatError(() => parseBVH(value(4, '1e300')), 'bvh', FIRST_FRAME_LINE)).toBe(`BVH line ${FIRST_FRAME_LINE}: expected a rotation in degrees of at most 1000000 in magnitude, found "1e300"`);
    expect(formatError(() => parseBVH(value(10, '-1000001')), 'bvh', FIRST_FRAME_LINE)).toMatch(/expected a rotation in degrees of at most 1000000 in magnitude, found "-1000001"$/);
    expect(parseBVH(value(10, '-999999')).frames).toBe(450); // many turns, but a rotation
    expect(formatError(() => parseBVH(BVH.replace('OFFSET 2.36836 -6.50702 0.00000', 'OFFSET 2.36836 1e300 0.00000')), 'bvh', 16))
      .toBe('BVH line 16: expected an OFFSET y value in file units of at most 1000000000 in magnitude, found "1e300"');
    // Within the file bound but beyond 1000 km once in metres.
    expect(formatError(() => parseBVH(SMALL.replace('0 90 0\n', '0 5e8 0\n'), { unitScale: 1 }), 'bvh', 10))
      .toBe('BVH line 10: frame 1 puts joint "Hips" at y = 500000000 m (at most ±1000000 m on each axis)');
    for (const time of ['10', '1.5', '0.00005', '0', '-0.01']) {
      expect(formatError(() => parseBVH(SMALL.replace('Frame Time: 0.04', `Frame Time: ${time}`)), 'bvh', 9), time)
        .toBe(`BVH line 9: expected a frame time from 0.0001 to 1 second, found "${time}"`);
    }
    expect(parseBVH(SMALL.replace('Frame Time: 0.04', 'Frame Time: 1')).fps).toBe(1);
    expect(parseBVH(SMALL.replace('Frame Time: 0.04', 'Frame Time: 0.0001')).fps).toBe(10000);
  });

  it('rejects joint names with control characters, showing them escaped', () => {
    expect(formatError(() => parseBVH(SMALL.replace('Hips', 'Hi\u0007ps')), 'bvh', 2)).toBe('BVH line 2: joint name "Hi\\u0007ps" contains a control character');
  });

  it('reads U+2028 and U+2029 line separators as line breaks', () => {
    const motion = parseBVH(BVH);
    for (const separator of ['\u2028', '\u2029', '\r\n', '\r']) {
      const back = parseBVH(BVH.replace(/\n/g, separator));
      expect(back.joints).toEqual(motion.joints);
      expect(back.positions).toEqual(motion.positions);
    }
  });

  it('detects every truncation but one inside the last number at the very end of the file', () => {
    // docs/api.md: a file cut inside its last number, with nothing after it, reads as a shorter number.
    const text = BVH_LINES.slice(0, FIRST_FRAME_LINE + 1).join('\n').replace('Frames: 450', 'Frames: 2');
    const lastLine = BVH_LINES[FIRST_FRAME_LINE];
    const lastNumberStart = text.length - lastLine.length + lastLine.trimEnd().lastIndexOf(' ') + 1;
    for (let cut = text.length - lastLine.length - 200; cut < text.length; cut++) {
      const prefix = text.slice(0, cut);
      let accepted = true;
      try {
        parseBVH(prefix);
      } catch (e) {
        expect(e).toBeInstanceOf(MotionFormatError);
        accepted = false;
      }
      // Accepted exactly when the cut keeps part of the last number and that part is still a number ("1.", not "1e").
      const kept = prefix.slice(lastNumberStart).trim();
      expect(accepted, `cut at ${cut}: ${JSON.stringify(prefix.slice(-12))}`).toBe(cut > lastNumberStart && Number.isFinite(Number(kept)));
    }
  });
});

describe('bad ASF input', () => {
  it('rejects an empty or binary file', () => {
    expect(formatError(() => parseASF(''), 'asf')).toBe('ASF: file is empty');
    expect(formatError(() => parseASF('\0\0\0\0'), 'asf')).toMatch(/NUL bytes/);
  });

  it('rejects a skeleton without :bonedata', () => {
    const noBones = ASF.slice(0, ASF.indexOf(':bonedata')) + ASF.slice(ASF.indexOf(':hierarchy'));
    expect(formatError(() => parseASF(noBones), 'asf')).toBe('ASF: missing :bonedata section (expected the bone definitions)');
  });

  it('rejects a skeleton without :hierarchy, or truncated inside a bone', () => {
    expect(formatError(() => parseASF(ASF.slice(0, ASF.indexOf(':hierarchy'))), 'asf')).toMatch(/missing :hierarchy section/);
    const cut = ASF.split('\n').slice(0, 30).join('\n');
    expect(formatError(() => parseASF(cut), 'asf', 30)).toMatch(/bone starting at line 25 has no "end" \(file truncated\?\)/);
  });

  it('rejects bones missing fields, unknown dofs and unknown bones in the hierarchy', () => {
    expect(formatError(() => parseASF(ASF.replace('length 7.03469', '')), 'asf')).toMatch(/bone starting at line \d+ has no length/);
    expect(formatError(() => parseASF(ASF.replace('lhipjoint lfemur', 'lhipjoint lfemur lwing')), 'asf', 315)).toBe('ASF line 315: :hierarchy names unknown bone "lwing"');
    expect(formatError(() => parseASF(ASF.replace('dof rx ry rz', 'dof rx rq rz')), 'asf')).toMatch(/unknown dof "rq"/);
    expect(formatError(() => parseASF(ASF.replace('length 7.03469', 'length seven')), 'asf')).toMatch(/expected a bone length in length units, found "seven"/);
  });

  it('quotes at most a few dozen characters of a long name or token', () => {
    const long = 'x'.repeat(5_000_000);
    const quoted = `"${'x'.repeat(40)}…"`;
    expect(formatError(() => parseASF(ASF.replace('lhipjoint lfemur', `lhipjoint lfemur ${long}`)), 'asf', 315)).toBe(`ASF line 315: :hierarchy names unknown bone ${quoted}`);
    expect(formatError(() => parseASF(ASF.replace('dof rx ry rz', `dof rx ${long}`)), 'asf', 31)).toBe(`ASF line 31: unknown dof ${quoted} (expected rx ry rz tx ty tz l)`);
    expect(formatError(() => parseASF(ASF.replace('axis 0 0 20  XYZ', `axis 0 0 20 ${long}`)), 'asf', 30)).toBe(`ASF line 30: expected an axis order like XYZ, found ${quoted}`);
    expect(formatError(() => parseASF(ASF.replace('name lfemur', `name ${long}`).replace('name ltibia', `name ${long}`)), 'asf')).toMatch(/^ASF line \d+: duplicate bone name "x{40}…"$/);
  });

  // Generated skeletons: line 10 is the first bone's "begin" and each bone takes 7 lines (see generatedASF).
  const boneBeginLine = (bone: number) => 10 + 7 * (bone - 1);
  const chainLinks = (bones: number) => parentLinks(hierarchyParents(seededRandom(1), 'chain', bones + 1));

  it('rejects more bones than a skeleton may have while reading them, however they are linked', () => {
    const tooMany = boneBeginLine(MAX_JOINTS);
    const message = `ASF line ${tooMany}: more than ${MAX_JOINTS - 1} bones (a skeleton has at most ${MAX_JOINTS} joints: the root and ${MAX_JOINTS - 1} bones)`;
    expect(formatError(() => parseASF(generatedASF(10_000, chainLinks(10_000))), 'asf', tooMany)).toBe(message);
    expect(formatError(() => parseASF(generatedASF(20_000, [...chainLinks(20_000), [20_000, 1]])), 'asf', tooMany)).toBe(message);
    expect(formatError(() => parseASF(generatedASF(50_000, parentLinks(hierarchyParents(seededRandom(1), 'wide', 50_001)))), 'asf', tooMany)).toBe(message);
  });

  it('reads a skeleton at the joint limit: a chain 1023 bones deep', () => {
    const skeleton = parseASF(generatedASF(MAX_JOINTS - 1, chainLinks(MAX_JOINTS - 1)));
    expect(skeleton.joints).toHaveLength(MAX_JOINTS);
    expect(skeleton.parents.every((p, j) => p === j - 1)).toBe(true);
    let amc = '1\nroot 0 0 0 0 0 0\n';
    for (let b = 1; b < MAX_JOINTS; b++) amc += `b${b} 0 0 0\n`;
    const m = parseAMC(amc, skeleton);
    expect(m.positions[(MAX_JOINTS - 1) * 3 + 1]).toBeCloseTo((MAX_JOINTS - 1) * 0.0254, 5);
  });

  it('names a bone listed under two parents, and a cycle cut off from the root', () => {
    // Three bones: :hierarchy is on line 31, "begin" 32, the parent lines from 33.
    expect(formatError(() => parseASF(generatedASF(3, [[0, 1], [0, 2], [1, 2], [2, 3]])), 'asf', 34)).toBe('ASF line 34: :hierarchy lists bone "b2" under both "root" (line 33) and "b1"');
    expect(formatError(() => parseASF(generatedASF(3, [[0, 1], [2, 3], [3, 2]])), 'asf', 35)).toBe('ASF line 35: :hierarchy links bone "b2" below itself (a cycle cut off from the root)');
    expect(formatError(() => parseASF(generatedASF(100, [...chainLinks(100), [100, 1]])), 'asf', 812)).toBe('ASF line 812: :hierarchy lists bone "b1" under both "root" (line 712) and "b100"');
    expect(formatError(() => parseASF(generatedASF(2, [[0, 1]])), 'asf')).toBe('ASF: bone "b2" is not connected to the root in :hierarchy');
  });

  it('reads :hierarchy lines of 200,000 names without overflowing the stack', () => {
    const names = Array.from({ length: 200_000 }, (_, i) => `n${i}`).join(' ');
    expect(formatError(() => parseASF(ASF.replace('root lhipjoint rhipjoint lowerback', `root lhipjoint rhipjoint lowerback\nroot ${names}`)), 'asf', 315)).toBe('ASF line 315: :hierarchy names unknown bone "n0"');
  });

  it('rejects repeated dofs and root order entries', () => {
    expect(formatError(() => parseASF(ASF.replace('dof rx ry rz', 'dof rx ry rx')), 'asf', 31)).toBe('ASF line 31: dof "rx" is listed twice');
    expect(formatError(() => parseASF(ASF.replace('order TX TY TZ RX RY RZ', 'order TX TY TZ RX RY TX')), 'asf', 13)).toBe('ASF line 13: root order lists "TX" twice');
  });

  it('rejects absurd but finite units, lengths, angles and positions, naming the limit', () => {
    expect(formatError(() => parseASF(ASF.replace('length 0.45', 'length 1e-300')), 'asf', 7)).toBe('ASF line 7: expected a length unit L from 0.0001 to 10000 (one unit is 1/L inch), found "1e-300"');
    expect(formatError(() => parseASF(ASF.replace('length 0.45', 'length 1e300')), 'asf', 7)).toMatch(/expected a length unit L from 0.0001 to 10000/);
    expect(formatError(() => parseASF(ASF.replace('length 7.03469', 'length 1e300')), 'asf', 29)).toBe('ASF line 29: expected a bone length in length units of at most 10000 in magnitude, found "1e300"');
    expect(formatError(() => parseASF(ASF.replace('axis 0 0 20  XYZ', 'axis 0 0 1e300 XYZ')), 'asf', 30)).toBe('ASF line 30: expected an axis angle in degrees of at most 1000000 in magnitude, found "1e300"');
    expect(formatError(() => parseASF(ASF.replace('position 0 0 0', 'position 0 1e300 0')), 'asf', 15)).toBe('ASF line 15: expected a root position in length units of at most 1000000 in magnitude, found "1e300"');
    expect(formatError(() => parseASF(ASF.replace('orientation 0 0 0', 'orientation 0 0 -1e300').replace('angle deg', 'angle rad')), 'asf', 16)).toBe('ASF line 16: expected a root orientation angle in radians of at most 1000000 in magnitude, found "-1e300"');
  });

  it('normalises a huge but finite direction instead of overflowing it to zero', () => {
    const femur = parseASF(ASF.replace('direction 0.34202 -0.939693 0', 'direction 1.5e308 -1.5e308 0')).bones.find((b) => b.name === 'lfemur')!;
    expect(femur.direction[0]).toBeCloseTo(Math.SQRT1_2, 12);
    expect(femur.direction[1]).toBeCloseTo(-Math.SQRT1_2, 12);
  });
});

describe('bad AMC input', () => {
  it('needs its ASF', () => {
    expect(formatError(() => importMotion(AMC, 'amc'), 'amc')).toBe('AMC: an AMC motion needs its ASF skeleton file (none given)');
    expect(formatError(() => importMotion(AMC, 'amc', ''), 'asf')).toBe('ASF: file is empty');
  });

  it('rejects an empty, header-only or binary file', () => {
    expect(formatError(() => parseAMC('', ASF), 'amc')).toBe('AMC: file is empty');
    expect(formatError(() => parseAMC(':FULLY-SPECIFIED\n:DEGREES\n', ASF), 'amc')).toMatch(/no frames found/);
    expect(formatError(() => parseAMC('1\nroot \0\0\0', ASF), 'amc')).toMatch(/NUL bytes/);
  });

  it('rejects a bone the ASF lacks', () => {
    expect(formatError(() => parseAMC(amcWithLine(10, () => 'tail 1 2 3'), ASF), 'amc', 10)).toBe('AMC line 10: unknown bone "tail" (not in the ASF skeleton)');
  });

  it('quotes at most a few dozen characters of a long bone name or line', () => {
    expect(formatError(() => parseAMC(amcWithLine(10, () => `${'y'.repeat(5_000_000)} 1 2 3`), ASF), 'amc', 10)).toBe(`AMC line 10: unknown bone "${'y'.repeat(40)}…" (not in the ASF skeleton)`);
    expect(formatError(() => parseAMC('x'.repeat(20_000_000), ASF), 'amc', 1)).toBe(`AMC line 1: expected a frame number before "${'x'.repeat(40)}…"`);
    expect(formatError(() => parseAMC(amcWithLine(30, () => `lfemur ${'9'.repeat(1000)}`), ASF), 'amc', 30)).toBe('AMC line 30: expected 3 numbers for "lfemur", found 1');
  });

  it('rejects absurd but finite angles, translations and frame numbers, naming the limit', () => {
    expect(formatError(() => parseAMC(amcWithLine(30, () => 'lfemur 1e300 0 0'), ASF), 'amc', 30)).toBe('AMC line 30: expected an angle in degrees of at most 1000000 in magnitude, found "1e300"');
    expect(formatError(() => parseAMC(amcWithLine(3, () => ':RADIANS').replace('lfemur -18.0782', 'lfemur -2e6'), ASF), 'amc', 30)).toBe('AMC line 30: expected an angle in radians of at most 1000000 in magnitude, found "-2e6"');
    expect(formatError(() => parseAMC(amcWithLine(5, () => 'root 1e300 17.5143 -32.75 -1.4536 -6.19748 1.72036'), ASF), 'amc', 5)).toBe('AMC line 5: expected a root translation in length units of at most 1000000 in magnitude, found "1e300"');
    expect(formatError(() => parseAMC(amcWithLine(4, () => '9007199254740993'), ASF), 'amc', 4)).toBe('AMC line 4: expected a frame number of at most 9007199254740991, found "9007199254740993"');
    // Within the file bound, but 228,600 km out with a length unit of 1/0.0001 inch: named like BVH's (frame, joint, axis, bound).
    const tinyUnits = ASF.replace('length 0.45', 'length 0.0001');
    const far = amcWithLine(5, () => 'root 900000 17.5143 -32.75 -1.4536 -6.19748 1.72036');
    expect(formatError(() => importMotion(far, 'amc', tinyUnits), 'amc', 4)).toBe('AMC line 4: frame 1 puts joint "root" at x = 228600000 m (at most ±1000000 m on each axis)');
  });

  it('rejects lines with the wrong number of values', () => {
    // Line 30 is "lfemur -18.0782 -1.58962 -24.8838" (dof rx ry rz).
    expect(AMC_LINES[29]).toMatch(/^lfemur /);
    expect(formatError(() => parseAMC(amcWithLine(30, () => 'lfemur -18.0782 -1.58962'), ASF), 'amc', 30)).toBe('AMC line 30: expected 3 numbers for "lfemur", found 2');
    expect(formatError(() => parseAMC(amcWithLine(30, (l) => l + ' 4'), ASF), 'amc', 30)).toBe('AMC line 30: expected 3 numbers for "lfemur", found 4');
  });

  it('rejects NaN and non-numeric values', () => {
    expect(formatError(() => parseAMC(amcWithLine(30, () => 'lfemur NaN 0 0'), ASF), 'amc', 30)).toBe('AMC line 30: expected an angle in degrees, found "NaN"');
    expect(formatError(() => parseAMC(amcWithLine(30, () => 'lfemur 1 two 3'), ASF), 'amc', 30)).toBe('AMC line 30: expected an angle in degrees, found "two"');
  });

  it('rejects a truncated file (last frame incomplete)', () => {
    // Frames are 30 lines (number + 29 bones) after 3 header lines; keep frame 3's first 10 bones.
    const cut = AMC_LINES.slice(0, 3 + 30 * 2 + 11).join('\n');
    expect(formatError(() => parseAMC(cut, ASF), 'amc', 64)).toBe('AMC line 64: frame 3 has no values for "lfemur" (file truncated?)');
    const midLine = AMC.slice(0, AMC.indexOf('\nlfemur', 5000) + 12);
    expect(formatError(() => parseAMC(midLine, ASF), 'amc')).toMatch(/expected 3 numbers for "lfemur", found [12]/);
  });

  it('rejects out-of-sequence frame numbers and duplicated bones', () => {
    expect(formatError(() => parseAMC(amcWithLine(34, () => '7'), ASF), 'amc', 34)).toBe('AMC line 34: expected frame number 2, found 7');
    expect(formatError(() => parseAMC(amcWithLine(31, () => AMC_LINES[29]), ASF), 'amc', 31)).toBe('AMC line 31: bone "lfemur" appears twice in frame 1');
    // A frame missing a bone in the middle of the file.
    expect(formatError(() => parseAMC(amcWithLine(31, () => ''), ASF), 'amc', 4)).toBe('AMC line 4: frame 1 has no values for "ltibia"');
    expect(formatError(() => parseAMC('root 0 0 0 0 0 0\n', ASF), 'amc', 1)).toMatch(/expected a frame number before "root"/);
  });

  it('rejects frames whose positions would pass 100 million values while reading them, within the work budget', () => {
    // 1024 joints whose bones have no dofs: 6 values per frame but 3072 position values.
    const asf = generatedASF(MAX_JOINTS - 1, parentLinks(hierarchyParents(seededRandom(1), 'wide', MAX_JOINTS)), '');
    const amc = generatedAMC(seededRandom(2), 0, 40_000);
    const frames = Math.floor(MAX_VALUES / (MAX_JOINTS * 3)) + 1; // the first frame too many: 32553
    const line = 3 + (frames - 1) * 2;
    expect(checkFuzzCase('1024 dof-less joints × 40,000 frames', () => importMotion(amc, 'amc', asf), asf.length + amc.length, ['AMC'])).toBe('rejected');
    expect(formatError(() => parseAMC(amc, asf), 'amc', line)).toBe(`AMC line ${line}: ${frames} frames × 1024 joints × 3 = ${frames * 1024 * 3} position values; at most 100000000 are supported`);
  });

  it('rejects more than a million frames', () => {
    // A skeleton whose root has no values, so each frame is just its number.
    const asf = ':units\n  length 1\n:root\n  order\n:bonedata\n:hierarchy\n  begin\n  end\n';
    let amc = '';
    for (let f = 1; f <= 1_000_001; f++) amc += f + '\n';
    expect(formatError(() => parseAMC(amc, asf), 'amc', 1_000_001)).toBe('AMC line 1000001: more than 1000000 frames');
  });
});
