// BVH import and export.
//
// Import (parseBVH): any channel order and count per joint. A joint's local rotation is the product of
// its rotation channels in the order listed ("Zrotation Yrotation Xrotation" → Rz·Ry·Rx, intrinsic);
// G_j = G_parent · R_j and p_j = p_parent + G_parent · OFFSET_j. The root's position is OFFSET + its
// position channels; a non-root joint with position channels uses them instead of its OFFSET (the
// MotionBuilder/Blender convention). The result is in metres, y up: pass `unitScale` (metres per file
// unit) or let the importer pick metres, centimetres, millimetres, inches or CMU units (0.0254/0.45 m)
// by whichever makes the rest-pose figure closest to 1.7 m tall. fps = 1 / "Frame Time" (rounded to
// an integer when within 0.1%). Joints with a zero OFFSET (and no position channels) coincide with
// their parent and are left out of the Motion; End Sites become joints named `<joint>_end`. Limits
// (MAX_BVH_ENTRIES …, below): at most 3072 JOINT and End Site entries, checked while reading, and 1024
// joints kept; OFFSETs and position channels within ±1e9 file units, rotations within ±1e6°, positions
// within ±1e6 m, "Frame Time" from 0.0001 to 1 s; joint names without control characters. Hierarchies
// are walked with explicit stacks, never recursion. A file cut inside its very last number (with nothing
// after it) reads as a shorter number: the one truncation the format does not let us detect.
//
// Export (exportBVH): centimetres, y up, "Frame Time" = 1/fps; every joint has channels
// "Zrotation Yrotation Xrotation" (the root has "Xposition Yposition Zposition" first), written in
// degrees with 6 decimals. The rest pose (OFFSETs) uses each bone's mean length and, by default
// (restPose 'clip'), its direction in the clip's tallest frame; restPose 'tpose' writes a T-pose facing +z
// instead (restPose.ts), the motion's positions unchanged. Rotations are solved from joint positions as
// minimal swings relative to the parent (jointRotations.ts); joints with several children get zero-offset
// helper joints named `<joint>_to_<child>` and leaf joints a zero-offset End Site, both of which the
// importer drops again. Joint names are
// written as bvhJointNames says: a name parseBVH can return as it is, any other made readable back
// (braces, whitespace, control characters replaced; unique). There is no mapping in the file: BVH has no
// comment syntax, and other readers must be able to open it. So parseBVH(exportBVH(m)) gives back
// bvhJointNames(m.joints) (m's names wherever the importer can return them), m's parents and positions
// (rigid skeletons: exactly, up to 6-decimal rounding) provided the joints are in depth-first order, as
// every importer returns them, and the figure is over about 1.07 m tall (else pass unitScale: 0.01 to
// parseBVH; a figure whose joints all coincide, under 0.05 file units tall at rest, is read as centimetres).
// The frame rate must be at least 1 fps.
import { MotionFormatError, type Motion } from './types';
import { DEG, quatAboutAxis, quatConjugate, quatIdentity, quatMultiply, quatRotate, quatToEulerZYX, type Axis, type Quat, type Vec3 } from './math';
import { jointAt, parentNodeGlobal, rigClip, rotationPairs, solveGlobalRotations, type RigClip } from './jointRotations';
import { REST_POSES, restOffsets, type RestPose } from './restPose';
import { MAX_FRAMES, MAX_VALUES, checkText, parseBounded, parseNumber, parseWork, quoteInput, splitLines, tokens } from './text';
import { MAX_JOINTS, positionOutOfBounds, validateMotion } from './validate';

export interface BVHOptions {
  /** Metres per file unit; detected from the skeleton's rest height when omitted. */
  unitScale?: number;
}

/** Candidate units for detection, in metres per unit. */
export const BVH_UNIT_CANDIDATES: ReadonlyArray<{ name: string; scale: number }> = [
  { name: 'metres', scale: 1 },
  { name: 'centimetres', scale: 0.01 },
  { name: 'millimetres', scale: 0.001 },
  { name: 'inches', scale: 0.0254 },
  { name: 'CMU units', scale: 0.0254 / 0.45 },
];
const TYPICAL_HEIGHT = 1.7;
/** Rest figures shorter than this (file units: 5 cm even in metres, the largest unit) are too small to tell the unit by. */
const MIN_DETECTABLE_HEIGHT = 0.05;

/**
 * Import limits. JOINT and End Site entries (the root included): room for the MAX_JOINTS joints of a
 * motion plus, as exportBVH writes them, a helper joint per child of a branching joint and an End Site
 * per leaf. The joints the Motion keeps (non-zero OFFSET) are limited to MAX_JOINTS.
 */
export const MAX_BVH_ENTRIES = 3 * MAX_JOINTS;
/** Largest OFFSET or position channel value, in file units: MAX_POSITION (1000 km) in millimetres. */
export const MAX_BVH_LENGTH = 1e9;
/** Largest rotation channel value, in degrees (about 2,800 turns: unwrapped angles of a long spin pass). */
export const MAX_BVH_ROTATION = 1e6;
/** "Frame Time" bounds in seconds: 10,000 fps (validateMotion's limit) down to 1 fps. */
export const MIN_FRAME_TIME = 1e-4;
export const MAX_FRAME_TIME = 1;

/** Characters no joint name may hold: C0 and C1 controls other than whitespace (which separates tokens). */
const CONTROL_CHARACTER = /[\u0000-\u0008\u000e-\u001f\u007f-\u009f]/;
const CONTROL_CHARACTERS = new RegExp(CONTROL_CHARACTER, 'g');

type Channel = 'Xposition' | 'Yposition' | 'Zposition' | 'Xrotation' | 'Yrotation' | 'Zrotation';
const AXIS_NAMES: Axis[] = ['x', 'y', 'z'];
const CHANNELS = new Set<string>(['Xposition', 'Yposition', 'Zposition', 'Xrotation', 'Yrotation', 'Zrotation']);

interface BvhNode {
  name: string;
  parent: number; // index into the node list, -1 for the root
  offset: Vec3; // file units
  channels: Channel[];
  firstChannel: number; // index of this node's first value in a frame line
  endSite: boolean;
}

interface Token {
  text: string;
  line: number;
}

/** The nodes read so far, in depth-first order, and the channel count of a frame line. */
interface BvhHierarchy {
  nodes: BvhNode[];
  channelCount: number;
}

/**
 * The hierarchy's tokens, read in order and tokenised a line at a time as they are needed (so a file
 * rejected early costs little); braces are separate tokens. A line starting with MOTION ends them, and
 * running out of them throws "unexpected end of file".
 */
class HierarchyCursor {
  /** 0-based index of the line starting with MOTION, once reached; -1 before (or if there is none). */
  motionLine = -1;
  private nextLine = 0;
  private lineTokens: string[] = [];
  private lineNo = 0;
  private index = 0;

  constructor(private readonly lines: string[]) {}

  peek(): Token | undefined {
    while (this.index >= this.lineTokens.length) {
      if (this.motionLine >= 0 || this.nextLine >= this.lines.length) return undefined;
      const parts = tokens(this.lines[this.nextLine].replace(/[{}]/g, ' $& '));
      if (parts[0] === 'MOTION') {
        this.motionLine = this.nextLine;
      } else {
        this.lineTokens = parts;
        this.lineNo = this.nextLine + 1;
        this.index = 0;
      }
      this.nextLine++;
    }
    return { text: this.lineTokens[this.index], line: this.lineNo };
  }

  /** Line reported when the tokens run out: the MOTION line, else the file's last line. */
  get endLine(): number {
    return this.motionLine >= 0 ? this.motionLine + 1 : this.lines.length;
  }

  next(expected: string): Token {
    const t = this.peek();
    if (!t) throw new MotionFormatError('bvh', `unexpected end of file, expected ${expected} (file truncated?)`, this.endLine);
    this.index++;
    return t;
  }

  expect(word: string): Token {
    const t = this.next(`"${word}"`);
    if (t.text !== word) throw new MotionFormatError('bvh', `expected "${word}", found ${quoteInput(t.text)}`, t.line);
    return t;
  }

  offset(): Vec3 {
    return [this.offsetValue('x'), this.offsetValue('y'), this.offsetValue('z')];
  }

  private offsetValue(axis: string): number {
    const what = `an OFFSET ${axis} value in file units`;
    const t = this.next(what);
    return parseBounded(t.text, 'bvh', t.line, what, MAX_BVH_LENGTH);
  }

  /** Reads "NAME {" (name may contain spaces); the '{' must follow on the same or a later line. */
  name(keywordLine: number): string {
    const parts: string[] = [];
    while (this.peek() && this.peek()!.text !== '{' && this.peek()!.line === keywordLine) parts.push(this.next('a name').text);
    if (parts.length === 0) throw new MotionFormatError('bvh', 'expected a joint name', keywordLine);
    const name = parts.join(' ');
    if (CONTROL_CHARACTER.test(name)) throw new MotionFormatError('bvh', `joint name ${quoteInput(name)} contains a control character`, keywordLine);
    return name;
  }
}

function parseHierarchy(lines: string[]): BvhHierarchy & { motionLine: number } {
  const cursor = new HierarchyCursor(lines);
  const first = cursor.peek();
  if (first?.text !== 'HIERARCHY') {
    throw new MotionFormatError('bvh', `expected "HIERARCHY" at the start, found ${quoteInput(first?.text ?? (cursor.motionLine >= 0 ? 'MOTION' : ''))}`, first?.line ?? cursor.endLine);
  }
  cursor.next('"HIERARCHY"');
  const root = cursor.next('"ROOT"');
  if (root.text !== 'ROOT') throw new MotionFormatError('bvh', `expected "ROOT", found ${quoteInput(root.text)}`, root.line);
  const hierarchy = parseJoints(cursor, cursor.name(root.line), root.line);
  const after = cursor.peek();
  if (after) {
    const what = after.text === 'ROOT' ? 'a second ROOT (only one skeleton per file is supported)' : quoteInput(after.text);
    throw new MotionFormatError('bvh', `expected "MOTION" after the hierarchy, found ${what}`, after.line);
  }
  if (cursor.motionLine < 0) throw new MotionFormatError('bvh', 'expected a "MOTION" section after the hierarchy (file truncated?)', lines.length);
  return { ...hierarchy, motionLine: cursor.motionLine };
}

/** A joint whose "{ … }" block is being read. */
interface OpenJoint {
  index: number;
  name: string;
  line: number;
  sawOffset: boolean;
  sawChannels: boolean;
}

/**
 * Reads the root's "{ … }" block with every joint and End Site in it, appending nodes depth first. Nested
 * blocks are kept on a stack, not the call stack, so depth is limited only by MAX_BVH_ENTRIES.
 */
function parseJoints(cursor: HierarchyCursor, rootName: string, rootLine: number): BvhHierarchy {
  const hierarchy: BvhHierarchy = { nodes: [], channelCount: 0 };
  const { nodes } = hierarchy;
  const addNode = (node: BvhNode, line: number) => {
    if (nodes.length >= MAX_BVH_ENTRIES) {
      throw new MotionFormatError('bvh', `more than ${MAX_BVH_ENTRIES} JOINT and End Site entries (at most ${MAX_JOINTS} joints are supported)`, line);
    }
    nodes.push(node);
  };
  const open: OpenJoint[] = [];
  const openJoint = (name: string, parent: number, line: number) => {
    addNode({ name, parent, offset: [0, 0, 0], channels: [], firstChannel: hierarchy.channelCount, endSite: false }, line);
    cursor.expect('{');
    open.push({ index: nodes.length - 1, name, line, sawOffset: false, sawChannels: false });
  };
  openJoint(rootName, -1, rootLine);
  while (open.length > 0) {
    const joint = open[open.length - 1];
    const node = nodes[joint.index];
    const name = quoteInput(joint.name);
    const t = cursor.next(`"}" closing joint ${name} (opened at line ${joint.line})`);
    if (t.text === '}') {
      if (!joint.sawOffset) throw new MotionFormatError('bvh', `joint ${name} has no OFFSET`, joint.line);
      if (!joint.sawChannels) throw new MotionFormatError('bvh', `joint ${name} has no CHANNELS line`, joint.line);
      open.pop();
    } else if (t.text === 'OFFSET') {
      node.offset = cursor.offset();
      joint.sawOffset = true;
    } else if (t.text === 'CHANNELS') {
      if (joint.sawChannels) throw new MotionFormatError('bvh', `joint ${name} has two CHANNELS lines`, t.line);
      node.channels = readChannels(cursor, name);
      hierarchy.channelCount += node.channels.length;
      joint.sawChannels = true;
    } else if (t.text === 'JOINT') {
      if (!joint.sawOffset) throw new MotionFormatError('bvh', `joint ${name} has no OFFSET before its children`, t.line);
      openJoint(cursor.name(t.line), joint.index, t.line);
    } else if (t.text === 'End') {
      const site = cursor.next('"Site"');
      if (site.text !== 'Site') throw new MotionFormatError('bvh', `expected "Site" after "End", found ${quoteInput(site.text)}`, site.line);
      cursor.expect('{');
      cursor.expect('OFFSET');
      const offset = cursor.offset();
      cursor.expect('}');
      addNode({ name: `${joint.name}_end`, parent: joint.index, offset, channels: [], firstChannel: hierarchy.channelCount, endSite: true }, t.line);
    } else {
      throw new MotionFormatError('bvh', `unexpected ${quoteInput(t.text)} in joint ${name} (expected OFFSET, CHANNELS, JOINT, End Site or "}")`, t.line);
    }
  }
  return hierarchy;
}

/** The rest of a "CHANNELS n name…" line, after the keyword: exactly n channel names. `jointName` is quoted. */
function readChannels(cursor: HierarchyCursor, jointName: string): Channel[] {
  const countTok = cursor.next('a channel count');
  const count = parseNumber(countTok.text, 'bvh', countTok.line, 'a channel count');
  if (!Number.isInteger(count) || count < 0 || count > 6) {
    throw new MotionFormatError('bvh', `expected a channel count from 0 to 6, found ${quoteInput(countTok.text)}`, countTok.line);
  }
  const channels: Channel[] = [];
  for (let c = 0; c < count; c++) {
    const ch = cursor.next(`${count} channel names`);
    if (!CHANNELS.has(ch.text)) {
      throw new MotionFormatError('bvh', `joint ${jointName} declares ${count} channels but ${quoteInput(ch.text)} is not a channel name (Xposition … Zrotation)`, ch.line);
    }
    channels.push(ch.text as Channel);
  }
  const after = cursor.peek();
  if (after && after.line === countTok.line && CHANNELS.has(after.text)) {
    throw new MotionFormatError('bvh', `joint ${jointName} declares ${count} channels but lists more`, countTok.line);
  }
  return channels;
}

/** Rest-pose joint positions (all rotations zero), in file units. */
function restPositions(nodes: ReadonlyArray<{ offset: Vec3; parent: number }>): Vec3[] {
  const rest: Vec3[] = [];
  for (const n of nodes) {
    const base: Vec3 = n.parent < 0 ? [0, 0, 0] : rest[n.parent];
    rest.push([base[0] + n.offset[0], base[1] + n.offset[1], base[2] + n.offset[2]]);
  }
  return rest;
}

/**
 * Metres per file unit: the candidate unit that makes the figure closest to 1.7 m tall. The figure's height is the
 * taller of its rest pose's and its posed height (`posedHeight`, file units: the median vertical extent of a few
 * frames, bvhPosedHeight), so a rest pose lying flat does not shrink it: the Bandai Namco files (centimetres) rest
 * with spine and legs along x, the hips 93 cm above a root joint on the floor, a 1 m rest figure that read as inches.
 */
export function detectBVHUnitScale(nodes: ReadonlyArray<{ offset: Vec3; parent: number }>, posedHeight = 0): number {
  const rest = restPositions(nodes);
  const extent = (axis: number) => {
    let lo = Infinity;
    let hi = -Infinity;
    for (const p of rest) {
      lo = Math.min(lo, p[axis]);
      hi = Math.max(hi, p[axis]);
    }
    return hi - lo;
  };
  // Height is the y extent; a figure lying flat in its rest pose falls back to its largest extent.
  let height = extent(1);
  if (!(height > 0)) height = Math.max(extent(0), extent(2));
  // A rest figure of (almost) no size (every bone of zero length, as exportBVH writes a skeleton whose joints all
  // coincide: 0.001 cm bones) says nothing of its unit; no candidate makes it a figure, so the exporter's centimetres.
  if (!(height >= MIN_DETECTABLE_HEIGHT)) return 0.01;
  if (posedHeight > height) height = posedHeight;
  let best = BVH_UNIT_CANDIDATES[0].scale;
  for (const { scale } of BVH_UNIT_CANDIDATES) {
    if (Math.abs(Math.log((height * scale) / TYPICAL_HEIGHT)) < Math.abs(Math.log((height * best) / TYPICAL_HEIGHT))) best = scale;
  }
  return best;
}

/** Frames sampled (evenly over the file) for the posed height of unit detection. */
const POSED_HEIGHT_SAMPLES = 15;

/**
 * The figure's posed height in file units: the median, over up to POSED_HEIGHT_SAMPLES frame lines spread over the
 * file, of the kept joints' vertical extent. Lines that do not read are skipped here (the frame loop reports them).
 */
function bvhPosedHeight(lines: string[], firstFrameLine: number, nodes: BvhNode[], keptNodes: number[], channelCount: number): number {
  const frameLines: number[] = [];
  for (let k = firstFrameLine; k < lines.length; k++) if (lines[k].trim() !== '') frameLines.push(k);
  const count = Math.min(POSED_HEIGHT_SAMPLES, frameLines.length);
  const posed = posedNodes(nodes);
  const globals: Quat[] = new Array(nodes.length);
  const world: Vec3[] = new Array(nodes.length);
  const values = new Float64Array(channelCount);
  const heights: number[] = [];
  for (let s = 0; s < count; s++) {
    const parts = tokens(lines[frameLines[Math.floor(((s + 0.5) * frameLines.length) / count)]]);
    if (parts.length !== channelCount) continue;
    let ok = true;
    for (let c = 0; c < channelCount && ok; c++) {
      values[c] = Number(parts[c]);
      ok = Number.isFinite(values[c]) && Math.abs(values[c]) <= MAX_BVH_LENGTH;
    }
    if (!ok) continue;
    poseNodes(nodes, posed, values, globals, world);
    let lo = Infinity;
    let hi = -Infinity;
    for (const k of keptNodes) {
      lo = Math.min(lo, world[k][1]);
      hi = Math.max(hi, world[k][1]);
    }
    heights.push(hi - lo);
  }
  if (heights.length === 0) return 0;
  heights.sort((a, b) => a - b);
  return heights[heights.length >> 1];
}

/** Reads "Frames: N" / "Frame Time: t" style header lines; returns the value token or throws. */
function headerValue(line: string | undefined, lineNo: number, label: string[]): string {
  const parts = tokens((line ?? '').replace(/:/g, ' : '));
  const ok = label.every((word, i) => parts[i] === word) && parts[label.length] === ':' && parts.length === label.length + 2;
  if (!ok) {
    throw new MotionFormatError('bvh', `expected "${label.join(' ')}: <number>", found ${quoteInput((line ?? '').trim())}${line === undefined ? ' (end of file)' : ''}`, lineNo);
  }
  return parts[label.length + 1];
}

/** What each frame-line value is and its largest magnitude: a rotation (MAX_BVH_ROTATION) or a position (MAX_BVH_LENGTH). */
function frameValueKinds(nodes: BvhNode[], channelCount: number): { what: string[]; max: Float64Array } {
  const what: string[] = new Array(channelCount);
  const max = new Float64Array(channelCount);
  for (const n of nodes) {
    n.channels.forEach((ch, c) => {
      const rotation = ch.endsWith('rotation');
      what[n.firstChannel + c] = rotation ? 'a rotation in degrees' : 'a position in file units';
      max[n.firstChannel + c] = rotation ? MAX_BVH_ROTATION : MAX_BVH_LENGTH;
    });
  }
  return { what, max };
}

export function parseBVH(text: string, options: BVHOptions = {}): Motion {
  checkText(text, 'bvh');
  const lines = splitLines(text);
  const { nodes, channelCount, motionLine } = parseHierarchy(lines);
  const { joints, parents, keptNodes } = keptJoints(nodes);
  const J = joints.length;
  if (J > MAX_JOINTS) throw new MotionFormatError('bvh', `${J} joints with a non-zero OFFSET; at most ${MAX_JOINTS} are supported`);
  const { frames, fps, framesLine, firstFrameLine } = readMotionHeader(lines, motionLine, channelCount);
  if (frames * J * 3 > MAX_VALUES) {
    throw new MotionFormatError('bvh', `declares ${frames} frames × ${J} joints × 3 = ${frames * J * 3} position values; at most ${MAX_VALUES} are supported`, framesLine);
  }

  let unitScale = options.unitScale;
  if (unitScale === undefined) unitScale = detectBVHUnitScale(nodes, bvhPosedHeight(lines, firstFrameLine, nodes, keptNodes, channelCount));
  if (!(unitScale > 0 && Number.isFinite(unitScale))) throw new Error(`parseBVH: unitScale must be a positive number, got ${unitScale}`);

  // Allocate for the frame lines actually present, so a bogus "Frames:" cannot reserve memory.
  let frameLines = 0;
  for (let k = firstFrameLine; k < lines.length; k++) if (lines[k].trim() !== '') frameLines++;
  const positions = new Float32Array(Math.min(frames, frameLines) * J * 3);
  const posed = posedNodes(nodes);
  const kinds = frameValueKinds(nodes, channelCount);
  const globals: Quat[] = new Array(nodes.length);
  const world: Vec3[] = new Array(nodes.length);
  const values = new Float64Array(channelCount);
  let frame = 0;
  for (let i = firstFrameLine; i < lines.length; i++) {
    const parts = tokens(lines[i]);
    if (parts.length === 0) continue;
    if (frame >= frames) {
      throw new MotionFormatError('bvh', `more frame lines than the ${frames} declared by "Frames:" (line ${framesLine})`, i + 1);
    }
    if (parts.length !== channelCount) {
      throw new MotionFormatError('bvh', `expected ${channelCount} numbers per frame, found ${parts.length}`, i + 1);
    }
    for (let c = 0; c < channelCount; c++) values[c] = parseBounded(parts[c], 'bvh', i + 1, kinds.what[c], kinds.max[c]);
    poseNodes(nodes, posed, values, globals, world);
    const base = frame * J * 3;
    for (let j = 0; j < J; j++) {
      const w = world[keptNodes[j]];
      for (let axis = 0; axis < 3; axis++) {
        const v = w[axis] * unitScale;
        const far = positionOutOfBounds(v, frame + 1, joints[j], axis);
        if (far) throw new MotionFormatError('bvh', far, i + 1);
        positions[base + j * 3 + axis] = v;
      }
    }
    frame++;
  }
  if (frame < frames) {
    throw new MotionFormatError('bvh', `"Frames:" declares ${frames} frames but the file has ${frame} frame lines (file truncated?)`, framesLine);
  }
  return { fps, frames, joints, parents, positions };
}

/**
 * The "Frames:" and "Frame Time:" lines after MOTION (blank lines between them are skipped): the frame
 * count, fps, the 1-based line of "Frames:" and the 0-based index of the line after "Frame Time:".
 */
function readMotionHeader(lines: string[], motionLine: number, channelCount: number): { frames: number; fps: number; framesLine: number; firstFrameLine: number } {
  let i = motionLine + 1;
  const skipBlank = () => {
    while (i < lines.length && lines[i].trim() === '') i++;
  };
  skipBlank();
  const framesTok = headerValue(lines[i], i + 1, ['Frames']);
  const frames = parseNumber(framesTok, 'bvh', i + 1, 'a frame count');
  if (!Number.isInteger(frames) || frames < 1) throw new MotionFormatError('bvh', `expected a positive whole frame count, found ${quoteInput(framesTok)}`, i + 1);
  if (frames > MAX_FRAMES) throw new MotionFormatError('bvh', `declares ${frames} frames; at most ${MAX_FRAMES} are supported`, i + 1);
  if (frames * channelCount > MAX_VALUES) {
    throw new MotionFormatError('bvh', `declares ${frames} frames × ${channelCount} channels = ${frames * channelCount} values; at most ${MAX_VALUES} are supported`, i + 1);
  }
  const framesLine = i + 1;
  i++;
  skipBlank();
  const frameTimeTok = headerValue(lines[i], i + 1, ['Frame', 'Time']);
  const frameTime = parseNumber(frameTimeTok, 'bvh', i + 1, 'a frame time in seconds');
  if (!(frameTime >= MIN_FRAME_TIME && frameTime <= MAX_FRAME_TIME)) {
    throw new MotionFormatError('bvh', `expected a frame time from ${MIN_FRAME_TIME} to ${MAX_FRAME_TIME} second, found ${quoteInput(frameTimeTok)}`, i + 1);
  }
  let fps = 1 / frameTime;
  if (Math.abs(fps - Math.round(fps)) < 1e-3 * fps) fps = Math.round(fps);
  return { frames, fps, framesLine, firstFrameLine: i + 1 };
}

/** Whether a node is a joint of the Motion: the root, a non-zero OFFSET, or position channels of its own. */
function isKept(n: BvhNode): boolean {
  const zero = n.offset[0] === 0 && n.offset[1] === 0 && n.offset[2] === 0;
  return n.parent < 0 || !zero || n.channels.some((c) => c.endsWith('position'));
}

/** The Motion's joints: the kept nodes; parent = nearest kept ancestor. */
function keptJoints(nodes: BvhNode[]): { joints: string[]; parents: number[]; keptNodes: number[] } {
  const joints: string[] = [];
  const parents: number[] = [];
  const keptNodes: number[] = [];
  const nearestKept = new Int32Array(nodes.length).fill(-1);
  nodes.forEach((n, k) => {
    if (isKept(n)) {
      parents.push(n.parent < 0 ? -1 : nearestKept[n.parent]);
      nearestKept[k] = joints.length;
      joints.push(n.name);
      keptNodes.push(k);
    } else {
      nearestKept[k] = nearestKept[n.parent];
    }
  });
  return { joints, parents, keptNodes };
}

/** A node posed in every frame, and the node it hangs from (its nearest posed ancestor; -1 for the root). */
interface PosedNode {
  node: number;
  parent: number;
}

/**
 * The nodes a frame must pose: the kept ones and those with channels. Any other node coincides with its
 * parent and shares its rotation, so it is skipped, and a frame's work is bounded by its values and joints.
 */
function posedNodes(nodes: BvhNode[]): PosedNode[] {
  const posed: PosedNode[] = [];
  const nearestPosed = new Int32Array(nodes.length);
  nodes.forEach((n, k) => {
    const parent = n.parent < 0 ? -1 : nearestPosed[n.parent];
    if (isKept(n) || n.channels.length > 0) {
      posed.push({ node: k, parent });
      nearestPosed[k] = k;
    } else {
      nearestPosed[k] = parent;
    }
  });
  return posed;
}

/** One frame's channel values → the posed nodes' global rotations and world positions (file units). */
function poseNodes(nodes: BvhNode[], posed: PosedNode[], values: Float64Array, globals: Quat[], world: Vec3[]): void {
  parseWork.steps += posed.length;
  for (const { node: k, parent } of posed) {
    const n = nodes[k];
    let local: Vec3 = parent < 0 ? [n.offset[0], n.offset[1], n.offset[2]] : n.offset;
    let rot = quatIdentity();
    let hasPosition = false;
    const posChannels: Vec3 = [0, 0, 0];
    for (let c = 0; c < n.channels.length; c++) {
      const ch = n.channels[c];
      const v = values[n.firstChannel + c];
      const axis = ch.charCodeAt(0) - 88; // 'X' → 0, 'Y' → 1, 'Z' → 2
      if (ch.endsWith('rotation')) {
        rot = quatMultiply(rot, quatAboutAxis(AXIS_NAMES[axis], v * DEG));
      } else {
        posChannels[axis] = v;
        hasPosition = true;
      }
    }
    if (hasPosition) {
      local = parent < 0 ? [local[0] + posChannels[0], local[1] + posChannels[1], local[2] + posChannels[2]] : posChannels;
    }
    if (parent < 0) {
      globals[k] = rot;
      world[k] = local;
    } else {
      const pg = globals[parent];
      const o = quatRotate(pg, local);
      const pw = world[parent];
      world[k] = [pw[0] + o[0], pw[1] + o[1], pw[2] + o[2]];
      globals[k] = quatMultiply(pg, rot);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Export

const CM_PER_M = 100;

function fmt(v: number): string {
  const s = v.toFixed(6);
  return s === '-0.000000' ? '0.000000' : s;
}

/** What a joint line can hold of a name: braces, whitespace other than single inner spaces and control characters replaced. */
function sanitisedName(name: string): string {
  const clean = name.replace(/\{/g, '(').replace(/\}/g, ')').replace(/\s+/g, ' ').trim().replace(CONTROL_CHARACTERS, '_');
  return clean === '' ? 'unnamed' : clean;
}

/**
 * The joint names exportBVH writes, one per joint, unique, each read back as it is by parseBVH. A name
 * parseBVH can return is kept as it is; in any other "{" becomes "(", "}" becomes ")", each run of
 * whitespace (line breaks, tabs, U+2028 …) one space, leading and trailing whitespace goes, control
 * characters become "_", an empty result becomes "unnamed", and a result another joint has already gets
 * "_2", "_3", … appended.
 */
export function bvhJointNames(joints: readonly string[]): string[] {
  const taken = new Set(joints.filter((name) => sanitisedName(name) === name));
  return joints.map((name) => {
    const clean = sanitisedName(name);
    if (clean === name) return name;
    let unique = clean;
    for (let n = 2; taken.has(unique); n++) unique = `${clean}_${n}`;
    taken.add(unique);
    return unique;
  });
}

type ExportNode = { kind: 'joint'; joint: number } | { kind: 'helper'; joint: number; child: number };

export interface BVHExportOptions {
  /** The rest pose written as the HIERARCHY's OFFSETs (restPose.ts); 'clip' (the default) or 'tpose'. */
  restPose?: RestPose;
}

/**
 * Positions-only Motion → BVH text (centimetres, y up, ZYX Euler channels in degrees). `restPose: 'tpose'`
 * throws an Error when the skeleton's legs and arms cannot be named (restPose.ts).
 */
export function exportBVH(motion: Motion, options: BVHExportOptions = {}): string {
  const m = validateMotion(motion);
  const restPose = options.restPose ?? 'clip';
  if (!REST_POSES.includes(restPose)) throw new Error(`BVH export: restPose must be ${REST_POSES.map((p) => `'${p}'`).join(' or ')}, got ${quoteInput(String(restPose))}`);
  if (!(1 / m.fps <= MAX_FRAME_TIME)) {
    throw new Error(`BVH export needs at least ${1 / MAX_FRAME_TIME} fps (a "Frame Time" of at most ${MAX_FRAME_TIME} s, as the importer reads), got ${m.fps}`);
  }
  const clip = rigClip(m);
  const rest = restOffsets(clip, restPose);
  const framePair = rotationPairs(clip, rest);
  const out: string[] = ['HIERARCHY'];
  const order = writeHierarchy(clip, bvhJointNames(clip.joints), rest, out);
  out.push('MOTION', `Frames: ${clip.frames}`, `Frame Time: ${(1 / m.fps).toPrecision(10)}`);

  const jointGlobal: Quat[] = new Array(clip.joints.length);
  const helperGlobal: Quat[] = new Array(clip.joints.length); // indexed by child joint
  for (let f = 0; f < clip.frames; f++) {
    solveGlobalRotations(clip, rest, framePair, f, jointGlobal, helperGlobal);
    out.push(frameLine(clip, f, order, jointGlobal, helperGlobal));
  }
  return out.join('\n') + '\n';
}

/** A piece of the hierarchy still to write: a joint's block (its subtree included), a helper joint's block, or a line. */
type HierarchyStep = { joint: number; offset: Vec3; indent: string } | { helperOf: number; child: number; indent: string } | string;

/**
 * Appends the HIERARCHY lines to `out`, depth first, children in index order; returns the BVH nodes in
 * channel order. Walks with a stack of steps, not recursion, so a deep skeleton cannot overflow the call stack.
 */
function writeHierarchy(clip: RigClip, names: string[], rest: Vec3[], out: string[]): ExportNode[] {
  const { parents, children } = clip;
  const order: ExportNode[] = [];
  const steps: HierarchyStep[] = [{ joint: 0, offset: [0, 0, 0], indent: '' }];
  const writeNext = (next: HierarchyStep[]) => {
    for (let k = next.length - 1; k >= 0; k--) steps.push(next[k]);
  };
  while (steps.length > 0) {
    const step = steps.pop()!;
    if (typeof step === 'string') {
      out.push(step);
    } else if ('helperOf' in step) {
      const { helperOf: j, child: c, indent } = step;
      const inner = indent + '  ';
      out.push(`${indent}JOINT ${names[j]}_to_${names[c]}`, `${indent}{`);
      out.push(`${inner}OFFSET 0.000000 0.000000 0.000000`, `${inner}CHANNELS 3 Zrotation Yrotation Xrotation`);
      order.push({ kind: 'helper', joint: j, child: c });
      writeNext([{ joint: c, offset: rest[c], indent: inner }, `${indent}}`]);
    } else {
      const { joint: j, offset, indent } = step;
      const isRoot = parents[j] < 0;
      const inner = indent + '  ';
      out.push(`${indent}${isRoot ? 'ROOT' : 'JOINT'} ${names[j]}`, `${indent}{`);
      out.push(`${inner}OFFSET ${offset.map((v) => fmt(v * CM_PER_M)).join(' ')}`);
      out.push(`${inner}CHANNELS ${isRoot ? '6 Xposition Yposition Zposition' : '3'} Zrotation Yrotation Xrotation`);
      order.push({ kind: 'joint', joint: j });
      const kids = children[j];
      if (kids.length === 0) {
        out.push(`${inner}End Site`, `${inner}{`, `${inner}  OFFSET 0.000000 0.000000 0.000000`, `${inner}}`, `${indent}}`);
      } else if (kids.length === 1) {
        writeNext([{ joint: kids[0], offset: rest[kids[0]], indent: inner }, `${indent}}`]);
      } else {
        writeNext([...kids.map((c) => ({ helperOf: j, child: c, indent: inner })), `${indent}}`]);
      }
    }
  }
  return order;
}

/** Frame f's motion line: root position (cm), then each node's local rotation as Z Y X degrees. */
function frameLine(clip: RigClip, f: number, order: ExportNode[], jointGlobal: Quat[], helperGlobal: Quat[]): string {
  const line: string[] = [];
  const euler = (q: Quat) => {
    const [z, y, x] = quatToEulerZYX(q);
    line.push(fmt(z / DEG), fmt(y / DEG), fmt(x / DEG));
  };
  const root = jointAt(clip, f, 0);
  line.push(fmt(root[0] * CM_PER_M), fmt(root[1] * CM_PER_M), fmt(root[2] * CM_PER_M));
  for (const node of order) {
    if (node.kind === 'helper') {
      euler(quatMultiply(quatConjugate(jointGlobal[node.joint]), helperGlobal[node.child]));
    } else {
      const j = node.joint;
      euler(quatMultiply(quatConjugate(parentNodeGlobal(clip, j, jointGlobal, helperGlobal)), jointGlobal[j]));
    }
  }
  return line.join(' ');
}
