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
// their parent and are left out of the Motion; End Sites become joints named `<joint>_end`.
//
// Export (exportBVH): centimetres, y up, "Frame Time" = 1/fps; every joint has channels
// "Zrotation Yrotation Xrotation" (the root has "Xposition Yposition Zposition" first), written in
// degrees with 6 decimals. The rest pose (OFFSETs) uses each bone's mean length and its direction in
// the clip's tallest frame. Rotations are solved from joint positions as minimal swings relative to
// the parent; joints with several children get zero-offset helper joints named `<joint>_to_<child>`
// and leaf joints a zero-offset End Site, both of which the importer drops again. So
// parseBVH(exportBVH(m)) gives back m's joint names, parents and positions (rigid skeletons: exactly,
// up to 6-decimal rounding) provided the joints are in depth-first order, as every importer returns
// them, and the figure is over about 1.07 m tall (else pass unitScale: 0.01 to parseBVH).
import { MotionFormatError, type Motion } from './types';
import {
  DEG, quatAboutAxis, quatConjugate, quatIdentity, quatMultiply, quatRotate, quatToEulerZYX,
  rotationFromTwoVectors, swingRotation, cross, length, normalize, type Axis, type Quat, type Vec3,
} from './math';
import { MAX_FRAMES, MAX_VALUES, checkText, parseNumber, splitLines, tokens } from './text';
import { validateMotion } from './validate';

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
const MAX_DEPTH = 512;

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

/** Tokenises the hierarchy part; braces are separate tokens. Stops at MOTION. */
function tokenizeHierarchy(lines: string[]): { toks: Token[]; motionLine: number } {
  const toks: Token[] = [];
  for (let i = 0; i < lines.length; i++) {
    const parts = tokens(lines[i].replace(/[{}]/g, ' $& '));
    if (parts[0] === 'MOTION') return { toks, motionLine: i };
    for (const text of parts) toks.push({ text, line: i + 1 });
  }
  return { toks, motionLine: -1 };
}

/** The nodes read so far, in depth-first order, and the channel count of a frame line. */
interface BvhHierarchy {
  nodes: BvhNode[];
  channelCount: number;
}

/** The hierarchy tokens, read in order; running out of them throws "unexpected end of file". */
class HierarchyCursor {
  pos = 0;
  /** @param endLine line reported when the tokens run out: the MOTION line, else the file's last line. */
  constructor(private readonly toks: Token[], private readonly endLine: number) {}

  peek(): Token | undefined {
    return this.toks[this.pos];
  }

  next(expected: string): Token {
    const t = this.toks[this.pos++];
    if (!t) throw new MotionFormatError('bvh', `unexpected end of file, expected ${expected} (file truncated?)`, this.endLine);
    return t;
  }

  expect(word: string): Token {
    const t = this.next(`"${word}"`);
    if (t.text !== word) throw new MotionFormatError('bvh', `expected "${word}", found "${t.text}"`, t.line);
    return t;
  }

  number(what: string): number {
    const t = this.next(what);
    return parseNumber(t.text, 'bvh', t.line, what);
  }

  offset(): Vec3 {
    return [this.number('an OFFSET x value'), this.number('an OFFSET y value'), this.number('an OFFSET z value')];
  }

  /** Reads "NAME {" (name may contain spaces); the '{' must follow on the same or a later line. */
  name(keywordLine: number): string {
    const parts: string[] = [];
    while (this.peek() && this.peek()!.text !== '{' && this.peek()!.line === keywordLine) parts.push(this.next('a name').text);
    if (parts.length === 0) throw new MotionFormatError('bvh', 'expected a joint name', keywordLine);
    return parts.join(' ');
  }
}

function parseHierarchy(lines: string[]): BvhHierarchy & { motionLine: number } {
  const { toks, motionLine } = tokenizeHierarchy(lines);
  if (toks.length === 0 || toks[0].text !== 'HIERARCHY') {
    throw new MotionFormatError('bvh', `expected "HIERARCHY" at the start, found "${toks[0]?.text ?? (motionLine >= 0 ? 'MOTION' : '')}"`, toks[0]?.line ?? 1);
  }
  const cursor = new HierarchyCursor(toks, motionLine >= 0 ? motionLine + 1 : lines.length);
  cursor.pos = 1;
  const root = cursor.next('"ROOT"');
  if (root.text !== 'ROOT') throw new MotionFormatError('bvh', `expected "ROOT", found "${root.text}"`, root.line);
  const hierarchy: BvhHierarchy = { nodes: [], channelCount: 0 };
  parseJoint(cursor, hierarchy, cursor.name(root.line), -1, 0, root.line);
  if (cursor.pos < toks.length) {
    const t = toks[cursor.pos];
    const what = t.text === 'ROOT' ? 'a second ROOT (only one skeleton per file is supported)' : `"${t.text}"`;
    throw new MotionFormatError('bvh', `expected "MOTION" after the hierarchy, found ${what}`, t.line);
  }
  if (motionLine < 0) throw new MotionFormatError('bvh', 'expected a "MOTION" section after the hierarchy (file truncated?)', lines.length);
  return { ...hierarchy, motionLine };
}

/** Reads a joint's "{ … }" block, its children and End Site included, appending nodes depth first. */
function parseJoint(
  cursor: HierarchyCursor, hierarchy: BvhHierarchy, name: string, parent: number, depth: number, openLine: number,
): void {
  if (depth > MAX_DEPTH) throw new MotionFormatError('bvh', `hierarchy nested deeper than ${MAX_DEPTH} joints`, openLine);
  const { nodes } = hierarchy;
  const index = nodes.length;
  const node: BvhNode = { name, parent, offset: [0, 0, 0], channels: [], firstChannel: hierarchy.channelCount, endSite: false };
  nodes.push(node);
  cursor.expect('{');
  let sawOffset = false;
  let sawChannels = false;
  for (;;) {
    const t = cursor.next(`"}" closing joint "${name}" (opened at line ${openLine})`);
    if (t.text === '}') break;
    if (t.text === 'OFFSET') {
      node.offset = cursor.offset();
      sawOffset = true;
    } else if (t.text === 'CHANNELS') {
      if (sawChannels) throw new MotionFormatError('bvh', `joint "${name}" has two CHANNELS lines`, t.line);
      node.channels = readChannels(cursor, name);
      hierarchy.channelCount += node.channels.length;
      sawChannels = true;
    } else if (t.text === 'JOINT') {
      if (!sawOffset) throw new MotionFormatError('bvh', `joint "${name}" has no OFFSET before its children`, t.line);
      parseJoint(cursor, hierarchy, cursor.name(t.line), index, depth + 1, t.line);
    } else if (t.text === 'End') {
      const site = cursor.next('"Site"');
      if (site.text !== 'Site') throw new MotionFormatError('bvh', `expected "End Site", found "End ${site.text}"`, site.line);
      cursor.expect('{');
      cursor.expect('OFFSET');
      const offset = cursor.offset();
      cursor.expect('}');
      nodes.push({ name: `${name}_end`, parent: index, offset, channels: [], firstChannel: hierarchy.channelCount, endSite: true });
    } else {
      throw new MotionFormatError('bvh', `unexpected "${t.text}" in joint "${name}" (expected OFFSET, CHANNELS, JOINT, End Site or "}")`, t.line);
    }
  }
  if (!sawOffset) throw new MotionFormatError('bvh', `joint "${name}" has no OFFSET`, openLine);
  if (!sawChannels) throw new MotionFormatError('bvh', `joint "${name}" has no CHANNELS line`, openLine);
}

/** The rest of a "CHANNELS n name…" line, after the keyword: exactly n channel names. */
function readChannels(cursor: HierarchyCursor, jointName: string): Channel[] {
  const countTok = cursor.next('a channel count');
  const count = parseNumber(countTok.text, 'bvh', countTok.line, 'a channel count');
  if (!Number.isInteger(count) || count < 0 || count > 6) {
    throw new MotionFormatError('bvh', `expected a channel count from 0 to 6, found ${countTok.text}`, countTok.line);
  }
  const channels: Channel[] = [];
  for (let c = 0; c < count; c++) {
    const ch = cursor.next(`${count} channel names`);
    if (!CHANNELS.has(ch.text)) {
      throw new MotionFormatError('bvh', `joint "${jointName}" declares ${count} channels but "${ch.text}" is not a channel name (Xposition … Zrotation)`, ch.line);
    }
    channels.push(ch.text as Channel);
  }
  const after = cursor.peek();
  if (after && after.line === countTok.line && CHANNELS.has(after.text)) {
    throw new MotionFormatError('bvh', `joint "${jointName}" declares ${count} channels but lists more`, countTok.line);
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

/** Metres per file unit: the candidate unit that makes the rest figure closest to 1.7 m tall. */
export function detectBVHUnitScale(nodes: ReadonlyArray<{ offset: Vec3; parent: number }>): number {
  const rest = restPositions(nodes);
  const extent = (axis: number) => Math.max(...rest.map((p) => p[axis])) - Math.min(...rest.map((p) => p[axis]));
  // Height is the y extent; a figure lying flat in its rest pose falls back to its largest extent.
  let height = extent(1);
  if (!(height > 0)) height = Math.max(extent(0), extent(2));
  if (!(height > 0)) return 0.01;
  let best = BVH_UNIT_CANDIDATES[0].scale;
  for (const { scale } of BVH_UNIT_CANDIDATES) {
    if (Math.abs(Math.log((height * scale) / TYPICAL_HEIGHT)) < Math.abs(Math.log((height * best) / TYPICAL_HEIGHT))) best = scale;
  }
  return best;
}

/** Reads "Frames: N" / "Frame Time: t" style header lines; returns the value token or throws. */
function headerValue(line: string | undefined, lineNo: number, label: string[]): string {
  const parts = tokens((line ?? '').replace(/:/g, ' : '));
  const ok = label.every((word, i) => parts[i] === word) && parts[label.length] === ':' && parts.length === label.length + 2;
  if (!ok) {
    throw new MotionFormatError('bvh', `expected "${label.join(' ')}: <number>", found "${(line ?? '').trim().slice(0, 60)}"${line === undefined ? ' (end of file)' : ''}`, lineNo);
  }
  return parts[label.length + 1];
}

export function parseBVH(text: string, options: BVHOptions = {}): Motion {
  checkText(text, 'bvh');
  const lines = splitLines(text);
  const { nodes, channelCount, motionLine } = parseHierarchy(lines);
  const { frames, fps, framesLine, firstFrameLine } = readMotionHeader(lines, motionLine, channelCount);

  let unitScale = options.unitScale;
  if (unitScale === undefined) unitScale = detectBVHUnitScale(nodes);
  if (!(unitScale > 0 && Number.isFinite(unitScale))) throw new Error(`parseBVH: unitScale must be a positive number, got ${unitScale}`);

  const { joints, parents, keptNodes } = keptJoints(nodes);
  const J = joints.length;

  // Allocate for the frame lines actually present, so a bogus "Frames:" cannot reserve memory.
  let frameLines = 0;
  for (let k = firstFrameLine; k < lines.length; k++) if (lines[k].trim() !== '') frameLines++;
  const positions = new Float32Array(Math.min(frames, frameLines) * J * 3);
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
    for (let c = 0; c < channelCount; c++) values[c] = parseNumber(parts[c], 'bvh', i + 1);
    poseNodes(nodes, values, globals, world);
    const base = frame * J * 3;
    for (let j = 0; j < J; j++) {
      const w = world[keptNodes[j]];
      positions[base + j * 3] = w[0] * unitScale;
      positions[base + j * 3 + 1] = w[1] * unitScale;
      positions[base + j * 3 + 2] = w[2] * unitScale;
    }
    frame++;
  }
  if (frame < frames) {
    throw new MotionFormatError('bvh', `"Frames:" declares ${frames} frames but the file has ${frame} frame lines (file truncated?)`, framesLine);
  }
  for (let v = 0; v < positions.length; v++) {
    if (!Number.isFinite(positions[v])) throw new MotionFormatError('bvh', 'joint positions overflow (values too large)');
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
  if (!Number.isInteger(frames) || frames < 1) throw new MotionFormatError('bvh', `expected a positive whole frame count, found ${framesTok}`, i + 1);
  if (frames > MAX_FRAMES) throw new MotionFormatError('bvh', `declares ${frames} frames; at most ${MAX_FRAMES} are supported`, i + 1);
  if (frames * channelCount > MAX_VALUES) {
    throw new MotionFormatError('bvh', `declares ${frames} frames × ${channelCount} channels = ${frames * channelCount} values; at most ${MAX_VALUES} are supported`, i + 1);
  }
  const framesLine = i + 1;
  i++;
  skipBlank();
  const frameTime = parseNumber(headerValue(lines[i], i + 1, ['Frame', 'Time']), 'bvh', i + 1, 'a frame time in seconds');
  if (!(frameTime > 0 && frameTime < 10)) throw new MotionFormatError('bvh', `expected a positive frame time in seconds, found ${frameTime}`, i + 1);
  let fps = 1 / frameTime;
  if (Math.abs(fps - Math.round(fps)) < 1e-3 * fps) fps = Math.round(fps);
  return { frames, fps, framesLine, firstFrameLine: i + 1 };
}

/** The Motion's joints: nodes other than zero-offset ones without position channels; parent = nearest kept ancestor. */
function keptJoints(nodes: BvhNode[]): { joints: string[]; parents: number[]; keptNodes: number[] } {
  const keptIndex = new Int32Array(nodes.length).fill(-1);
  const joints: string[] = [];
  const parents: number[] = [];
  const keptNodes: number[] = [];
  const nearestKept = new Int32Array(nodes.length).fill(-1);
  nodes.forEach((n, k) => {
    const zero = n.offset[0] === 0 && n.offset[1] === 0 && n.offset[2] === 0;
    const hasPosition = n.channels.some((c) => c.endsWith('position'));
    const keep = n.parent < 0 || !zero || hasPosition;
    if (keep) {
      keptIndex[k] = joints.length;
      joints.push(n.name);
      parents.push(n.parent < 0 ? -1 : nearestKept[n.parent]);
      keptNodes.push(k);
    }
    nearestKept[k] = keep ? keptIndex[k] : nearestKept[n.parent];
  });
  return { joints, parents, keptNodes };
}

/** One frame's channel values → every node's global rotation and world position (file units). */
function poseNodes(nodes: BvhNode[], values: Float64Array, globals: Quat[], world: Vec3[]): void {
  for (let k = 0; k < nodes.length; k++) {
    const n = nodes[k];
    let local: Vec3 = n.parent < 0 ? [n.offset[0], n.offset[1], n.offset[2]] : n.offset;
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
      local = n.parent < 0 ? [local[0] + posChannels[0], local[1] + posChannels[1], local[2] + posChannels[2]] : posChannels;
    }
    if (n.parent < 0) {
      globals[k] = rot;
      world[k] = local;
    } else {
      const pg = globals[n.parent];
      const o = quatRotate(pg, local);
      const pw = world[n.parent];
      world[k] = [pw[0] + o[0], pw[1] + o[1], pw[2] + o[2]];
      globals[k] = quatMultiply(pg, rot);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Export

const CM_PER_M = 100;
/** Rest offset (metres) given to bones of zero length so the importer does not drop their joint. */
const TINY_BONE = 1e-5;

function fmt(v: number): string {
  const s = v.toFixed(6);
  return s === '-0.000000' ? '0.000000' : s;
}

type ExportNode = { kind: 'joint'; joint: number } | { kind: 'helper'; joint: number; child: number };

/** A validated Motion as the exporter reads it, with each joint's children in index order. */
interface ExportClip {
  frames: number;
  joints: string[];
  parents: number[];
  positions: Float32Array;
  children: number[][];
}

/** Positions-only Motion → BVH text (centimetres, y up, ZYX Euler channels in degrees). */
export function exportBVH(motion: Motion): string {
  const m = validateMotion(motion);
  const children: number[][] = m.joints.map(() => []);
  for (let j = 1; j < m.joints.length; j++) children[m.parents[j]].push(j);
  const clip: ExportClip = { frames: m.frames, joints: m.joints, parents: m.parents, positions: m.positions, children };

  const rest = restBones(clip);
  const framePair = rotationPairs(clip, rest);
  const out: string[] = ['HIERARCHY'];
  const order = writeHierarchy(clip, rest, out);
  out.push('MOTION', `Frames: ${clip.frames}`, `Frame Time: ${(1 / m.fps).toPrecision(10)}`);

  const jointGlobal: Quat[] = new Array(clip.joints.length);
  const helperGlobal: Quat[] = new Array(clip.joints.length); // indexed by child joint
  for (let f = 0; f < clip.frames; f++) {
    solveGlobalRotations(clip, rest, framePair, f, jointGlobal, helperGlobal);
    out.push(frameLine(clip, f, order, jointGlobal, helperGlobal));
  }
  return out.join('\n') + '\n';
}

function jointAt(clip: ExportClip, f: number, j: number): Vec3 {
  const P = clip.positions;
  const b = (f * clip.joints.length + j) * 3;
  return [P[b], P[b + 1], P[b + 2]];
}

/** Joint j's position minus its parent's in frame f. */
function boneVector(clip: ExportClip, f: number, j: number): Vec3 {
  const a = jointAt(clip, f, clip.parents[j]);
  const b = jointAt(clip, f, j);
  return [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
}

/** The frame with the largest y extent (the first of equals). */
function tallestFrame(clip: ExportClip): number {
  const P = clip.positions;
  const J = clip.joints.length;
  let restFrame = 0;
  let tallest = -Infinity;
  for (let f = 0; f < clip.frames; f++) {
    let lo = Infinity;
    let hi = -Infinity;
    for (let j = 0; j < J; j++) {
      const y = P[(f * J + j) * 3 + 1];
      lo = Math.min(lo, y);
      hi = Math.max(hi, y);
    }
    if (hi - lo > tallest + 1e-9) {
      tallest = hi - lo;
      restFrame = f;
    }
  }
  return restFrame;
}

/**
 * Rest bone of each joint (metres; zero for the root): direction from the tallest frame (keeps unit
 * detection on re-import reliable even if the clip starts crouched), length averaged over all frames.
 */
function restBones(clip: ExportClip): Vec3[] {
  const F = clip.frames;
  const restFrame = tallestFrame(clip);
  const rest: Vec3[] = clip.joints.map(() => [0, 0, 0]);
  for (let j = 1; j < clip.joints.length; j++) {
    let mean = 0;
    for (let f = 0; f < F; f++) mean += length(boneVector(clip, f, j));
    mean /= F;
    let dir = normalize(boneVector(clip, restFrame, j));
    for (let f = 0; length(dir) === 0 && f < F; f++) dir = normalize(boneVector(clip, f, j));
    if (length(dir) === 0) dir = [0, 1, 0];
    const len = mean > TINY_BONE ? mean : TINY_BONE;
    rest[j] = [dir[0] * len, dir[1] * len, dir[2] * len];
  }
  return rest;
}

/**
 * For joints with several children, the pair of children whose rest bones are least parallel
 * defines the joint's own rotation; undefined where no pair is far enough from parallel.
 */
function rotationPairs(clip: ExportClip, rest: Vec3[]): Array<[number, number] | undefined> {
  return clip.children.map((kids) => {
    let best: [number, number] | undefined;
    let bestSin = 1e-3;
    for (let a = 0; a < kids.length; a++) {
      for (let b = a + 1; b < kids.length; b++) {
        const s = length(cross(normalize(rest[kids[a]]), normalize(rest[kids[b]])));
        if (s > bestSin) {
          bestSin = s;
          best = [kids[a], kids[b]];
        }
      }
    }
    return best;
  });
}

/** Appends the HIERARCHY lines to `out`, depth first, children in index order; returns the BVH nodes in channel order. */
function writeHierarchy(clip: ExportClip, rest: Vec3[], out: string[]): ExportNode[] {
  const { joints, parents, children } = clip;
  const order: ExportNode[] = [];
  const writeJoint = (j: number, offset: Vec3, indent: string): void => {
    const isRoot = parents[j] < 0;
    out.push(`${indent}${isRoot ? 'ROOT' : 'JOINT'} ${joints[j]}`, `${indent}{`);
    out.push(`${indent}  OFFSET ${offset.map((v) => fmt(v * CM_PER_M)).join(' ')}`);
    out.push(`${indent}  CHANNELS ${isRoot ? '6 Xposition Yposition Zposition' : '3'} Zrotation Yrotation Xrotation`);
    order.push({ kind: 'joint', joint: j });
    const kids = children[j];
    if (kids.length === 0) {
      out.push(`${indent}  End Site`, `${indent}  {`, `${indent}    OFFSET 0.000000 0.000000 0.000000`, `${indent}  }`);
    } else if (kids.length === 1) {
      writeJoint(kids[0], rest[kids[0]], indent + '  ');
    } else {
      for (const c of kids) {
        const inner = indent + '    ';
        out.push(`${indent}  JOINT ${joints[j]}_to_${joints[c]}`, `${indent}  {`);
        out.push(`${inner}OFFSET 0.000000 0.000000 0.000000`, `${inner}CHANNELS 3 Zrotation Yrotation Xrotation`);
        order.push({ kind: 'helper', joint: j, child: c });
        writeJoint(c, rest[c], inner);
        out.push(`${indent}  }`);
      }
    }
    out.push(`${indent}}`);
  };
  writeJoint(0, [0, 0, 0], '');
  return order;
}

/** Global rotation of the BVH node directly above joint j: identity, j's helper joint, or j's parent. */
function parentNodeGlobal(clip: ExportClip, j: number, jointGlobal: Quat[], helperGlobal: Quat[]): Quat {
  const p = clip.parents[j];
  return p < 0 ? quatIdentity() : clip.children[p].length > 1 ? helperGlobal[j] : jointGlobal[p];
}

/**
 * Frame f's global rotations, parents first. A joint's rotation aims its child bone(s); it starts from
 * the rotation of the BVH node above it, so local rotations stay small and twist-free.
 */
function solveGlobalRotations(
  clip: ExportClip, rest: Vec3[], framePair: Array<[number, number] | undefined>, f: number, jointGlobal: Quat[], helperGlobal: Quat[],
): void {
  for (let j = 0; j < clip.joints.length; j++) {
    const base = parentNodeGlobal(clip, j, jointGlobal, helperGlobal);
    const kids = clip.children[j];
    const current = kids.map((c) => boneVector(clip, f, c));
    let g = base;
    if (kids.length === 1) {
      g = quatMultiply(swingRotation(quatRotate(base, rest[kids[0]]), current[0]), base);
    } else if (kids.length > 1) {
      const pair = framePair[j];
      if (pair) {
        const [a, b] = pair;
        g = rotationFromTwoVectors(rest[a], rest[b], boneVector(clip, f, a), boneVector(clip, f, b)) ?? base;
      }
      kids.forEach((c, k) => {
        helperGlobal[c] = quatMultiply(swingRotation(quatRotate(g, rest[c]), current[k]), g);
      });
    }
    jointGlobal[j] = g;
  }
}

/** Frame f's motion line: root position (cm), then each node's local rotation as Z Y X degrees. */
function frameLine(clip: ExportClip, f: number, order: ExportNode[], jointGlobal: Quat[], helperGlobal: Quat[]): string {
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
