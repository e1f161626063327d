// Acclaim ASF (skeleton) / AMC (motion) import, as used by the CMU motion capture database.
//
// Units: `:units length L` means one length unit is 1/L inch, so lengths are scaled by 0.0254 / L to
// metres (CMU: L = 0.45). Angles are degrees unless `angle rad` (or an AMC `:RADIANS` line).
// Axes follow the file: CMU data is y up and faces +z in its rest pose, which is our convention.
//
// Kinematics (as in the widely used AMC parsers): for each bone
//   C = Euler(axis angles, axis order), M = Euler(dof values, dof order)   — extrinsic, "XYZ" → Rz·Ry·Rx
//   G_bone = G_parent · C · M · C⁻¹,  end_bone = end_parent + G_bone · (direction · length)
// and for the root G_root = C_root · M_root · C_root⁻¹ (C_root from `orientation` in `axis` order),
// root position = (TX, TY, TZ) + `position`. Joint "lfemur" of the Motion is the END of the femur
// (the knee); joint "root" is the root position. Translation and length dofs (tx, ty, tz, l) on
// bones are read but ignored.
//
// Limits: at most MAX_JOINTS joints (the root and MAX_JOINTS − 1 bones), checked while reading
// :bonedata; at most MAX_FRAMES frames and MAX_VALUES values (the file's, and the positions': frames × joints
// × 3), checked at each frame number before the frame is read; finite values beyond the bounds below are
// rejected as absurd, so positions stay finite.
import { MotionFormatError, type Motion } from './types';
import { DEG, eulerToQuat, quatConjugate, quatIdentity, quatMultiply, quatRotate, type Quat, type Vec3 } from './math';
import { MAX_FRAMES, MAX_VALUES, checkText, parseBounded, parseNumber, parseWork, quoteInput, splitLines, tokens } from './text';
import { MAX_JOINTS, positionOutOfBounds } from './validate';

/** `:units length L` (one length unit is 1/L inch) must lie in [MIN_LENGTH_UNIT, MAX_LENGTH_UNIT]. */
export const MIN_LENGTH_UNIT = 1e-4;
export const MAX_LENGTH_UNIT = 1e4;
/** Largest bone length, in length units. */
export const MAX_BONE_LENGTH = 1e4;
/** Largest root position or AMC translation (root TX TY TZ, bone tx ty tz l), in length units. */
export const MAX_TRANSLATION = 1e6;
/** Largest angle (axis, orientation, AMC rotation), in the file's angle unit (degrees or radians). */
export const MAX_ANGLE = 1e6;

export interface AsfBone {
  name: string;
  /** Unit direction of the bone in the rest pose (world axes). */
  direction: Vec3;
  /** Length in ASF units (multiply by AsfSkeleton.lengthScale for metres). */
  length: number;
  /** Local axis angles in the skeleton's angle unit, applied in `axisOrder` (e.g. "XYZ"). */
  axis: Vec3;
  axisOrder: string;
  /** Degrees of freedom in the order AMC lists their values: rx, ry, rz, tx, ty, tz, l. */
  dof: string[];
}

export interface AsfSkeleton {
  name: string;
  /** Metres per ASF length unit (0.0254 / `length`). */
  lengthScale: number;
  angleUnit: 'deg' | 'rad';
  root: {
    /** AMC value order for the root, e.g. ["TX","TY","TZ","RX","RY","RZ"]. */
    order: string[];
    axisOrder: string;
    position: Vec3;
    orientation: Vec3;
  };
  /** Bones in :bonedata order. */
  bones: AsfBone[];
  /** Motion joint order: "root", then bones in :hierarchy depth-first order. */
  joints: string[];
  /** Parent index of each entry of `joints` (-1 for the root). */
  parents: number[];
}

const DOF_NAMES = new Set(['rx', 'ry', 'rz', 'tx', 'ty', 'tz', 'l']);
const ROOT_ORDER_NAMES = new Set(['TX', 'TY', 'TZ', 'RX', 'RY', 'RZ']);

function axisOrder(token: string | undefined, line: number): string {
  const order = (token ?? '').toUpperCase();
  if (!/^[XYZ]{3}$/.test(order) || new Set(order).size !== 3) {
    throw new MotionFormatError('asf', `expected an axis order like XYZ, found ${quoteInput(token ?? '')}`, line);
  }
  return order;
}

/** Three numbers from parts[from], each at most `max` in magnitude. */
function vec3(parts: string[], from: number, line: number, what: string, max = Infinity): Vec3 {
  if (parts.length < from + 3) throw new MotionFormatError('asf', `expected 3 numbers for ${what}, found ${Math.max(0, parts.length - from)}`, line);
  return [parseBounded(parts[from], 'asf', line, what, max), parseBounded(parts[from + 1], 'asf', line, what, max), parseBounded(parts[from + 2], 'asf', line, what, max)];
}

/** The direction of d as a unit vector (scaled first, so huge components do not overflow); zero stays zero. */
function unitDirection(d: Vec3): Vec3 {
  const largest = Math.max(Math.abs(d[0]), Math.abs(d[1]), Math.abs(d[2]));
  if (largest === 0) return [0, 0, 0];
  const x = d[0] / largest, y = d[1] / largest, z = d[2] / largest;
  const n = Math.hypot(x, y, z);
  return [x / n, y / n, z / n];
}

const ANGLE_UNIT_NAMES = { deg: 'degrees', rad: 'radians' } as const;

/** :hierarchy lines: parent name → children, with the line that first names the parent. */
type BoneChildren = Map<string, { names: string[]; line: number }>;
/** :hierarchy links: bone name → its parent's name, with the line that lists it. */
type BoneParents = Map<string, { parent: string; line: number }>;

/** What parseASF has read so far: the skeleton, the open section and the bone or block being read. */
interface AsfReader {
  skeleton: AsfSkeleton;
  section: string;
  sawBonedata: boolean;
  sawHierarchy: boolean;
  /** The :bonedata entry between "begin" and "end", with the line of its "begin". */
  bone: (Partial<AsfBone> & { line: number }) | undefined;
  boneNames: Set<string>;
  inHierarchyBlock: boolean;
  children: BoneChildren;
  parentOf: BoneParents;
}

export function parseASF(text: string): AsfSkeleton {
  checkText(text, 'asf');
  const reader = readASFSections(splitLines(text));
  orderJoints(reader.skeleton, reader.children, reader.parentOf);
  return reader.skeleton;
}

/** Reads every line into the skeleton's header, root and bones, and the :hierarchy lists. */
function readASFSections(lines: string[]): AsfReader {
  const reader: AsfReader = {
    skeleton: {
      name: '',
      lengthScale: 0.0254,
      angleUnit: 'deg',
      root: { order: ['TX', 'TY', 'TZ', 'RX', 'RY', 'RZ'], axisOrder: 'XYZ', position: [0, 0, 0], orientation: [0, 0, 0] },
      bones: [],
      joints: [],
      parents: [],
    },
    section: '',
    sawBonedata: false,
    sawHierarchy: false,
    bone: undefined,
    boneNames: new Set(),
    inHierarchyBlock: false,
    children: new Map(),
    parentOf: new Map(),
  };
  for (let i = 0; i < lines.length; i++) {
    const lineNo = i + 1;
    const hash = lines[i].indexOf('#');
    const parts = tokens(hash >= 0 ? lines[i].slice(0, hash) : lines[i]);
    if (parts.length === 0) continue;
    const key = parts[0];
    if (key.startsWith(':')) {
      openSection(reader, key, parts, lineNo);
      continue;
    }
    const k = key.toLowerCase();
    if (reader.section === ':units') readUnitsLine(reader.skeleton, k, parts, lineNo);
    else if (reader.section === ':root') readRootLine(reader.skeleton, k, parts, lineNo);
    else if (reader.section === ':bonedata') readBonedataLine(reader, k, key, parts, lineNo);
    else if (reader.section === ':hierarchy') readHierarchyLine(reader, k, key, parts, lineNo);
  }
  if (reader.bone) throw new MotionFormatError('asf', `bone starting at line ${reader.bone.line} has no "end" (file truncated?)`, lines.length);
  if (reader.inHierarchyBlock) throw new MotionFormatError('asf', ':hierarchy block has no "end" (file truncated?)', lines.length);
  if (!reader.sawBonedata) throw new MotionFormatError('asf', 'missing :bonedata section (expected the bone definitions)');
  if (!reader.sawHierarchy) throw new MotionFormatError('asf', 'missing :hierarchy section (expected the bone parent/child lists)');
  return reader;
}

/** A ":keyword" line: closes the previous section (which must not be mid-bone or mid-block). */
function openSection(reader: AsfReader, key: string, parts: string[], lineNo: number): void {
  if (reader.bone) throw new MotionFormatError('asf', `bone starting at line ${reader.bone.line} has no "end"`, lineNo);
  if (reader.inHierarchyBlock) throw new MotionFormatError('asf', ':hierarchy block has no "end"', lineNo);
  reader.section = key.toLowerCase();
  if (reader.section === ':name') reader.skeleton.name = parts.slice(1).join(' ');
  if (reader.section === ':bonedata') reader.sawBonedata = true;
  if (reader.section === ':hierarchy') reader.sawHierarchy = true;
}

function readUnitsLine(skeleton: AsfSkeleton, k: string, parts: string[], lineNo: number): void {
  if (k === 'length') {
    const l = parseNumber(parts[1] ?? '', 'asf', lineNo, 'a length unit');
    if (!(l >= MIN_LENGTH_UNIT && l <= MAX_LENGTH_UNIT)) {
      throw new MotionFormatError('asf', `expected a length unit L from ${MIN_LENGTH_UNIT} to ${MAX_LENGTH_UNIT} (one unit is 1/L inch), found ${quoteInput(parts[1])}`, lineNo);
    }
    skeleton.lengthScale = 0.0254 / l;
  } else if (k === 'angle') {
    const unit = (parts[1] ?? '').toLowerCase();
    if (unit.startsWith('deg')) skeleton.angleUnit = 'deg';
    else if (unit.startsWith('rad')) skeleton.angleUnit = 'rad';
    else throw new MotionFormatError('asf', `expected angle unit "deg" or "rad", found ${quoteInput(parts[1] ?? '')}`, lineNo);
  }
}

/** The first entry of `names` that repeats an earlier one, or undefined. */
function firstRepeat(names: string[]): string | undefined {
  const seen = new Set<string>();
  for (const name of names) {
    if (seen.has(name)) return name;
    seen.add(name);
  }
  return undefined;
}

function readRootLine(skeleton: AsfSkeleton, k: string, parts: string[], lineNo: number): void {
  if (k === 'order') {
    const order = parts.slice(1).map((p) => p.toUpperCase());
    for (const o of order) if (!ROOT_ORDER_NAMES.has(o)) throw new MotionFormatError('asf', `unknown root order entry ${quoteInput(o)} (expected TX TY TZ RX RY RZ)`, lineNo);
    const repeated = firstRepeat(order);
    if (repeated) throw new MotionFormatError('asf', `root order lists "${repeated}" twice`, lineNo);
    skeleton.root.order = order;
  } else if (k === 'axis') skeleton.root.axisOrder = axisOrder(parts[1], lineNo);
  else if (k === 'position') skeleton.root.position = vec3(parts, 1, lineNo, 'a root position in length units', MAX_TRANSLATION);
  else if (k === 'orientation') skeleton.root.orientation = vec3(parts, 1, lineNo, `a root orientation angle in ${ANGLE_UNIT_NAMES[skeleton.angleUnit]}`, MAX_ANGLE);
}

/** One :bonedata line: "begin" … "end" around name, direction, length, axis and dof lines. */
function readBonedataLine(reader: AsfReader, k: string, key: string, parts: string[], lineNo: number): void {
  if (k === 'begin') {
    if (reader.bone) throw new MotionFormatError('asf', `bone starting at line ${reader.bone.line} has no "end"`, lineNo);
    if (reader.skeleton.bones.length >= MAX_JOINTS - 1) {
      throw new MotionFormatError('asf', `more than ${MAX_JOINTS - 1} bones (a skeleton has at most ${MAX_JOINTS} joints: the root and ${MAX_JOINTS - 1} bones)`, lineNo);
    }
    reader.bone = { line: lineNo };
    return;
  }
  if (k === 'end') {
    finishBone(reader, lineNo);
    return;
  }
  const bone = reader.bone;
  if (!bone) {
    throw new MotionFormatError('asf', `expected "begin" in :bonedata, found ${quoteInput(key)}`, lineNo);
  } else if (k === 'name') {
    if (!parts[1]) throw new MotionFormatError('asf', 'expected a bone name', lineNo);
    bone.name = parts[1];
  } else if (k === 'direction') {
    bone.direction = vec3(parts, 1, lineNo, 'the bone direction');
  } else if (k === 'length') {
    const len = parseBounded(parts[1] ?? '', 'asf', lineNo, 'a bone length in length units', MAX_BONE_LENGTH);
    if (len < 0) throw new MotionFormatError('asf', `expected a non-negative bone length, found ${quoteInput(parts[1])}`, lineNo);
    bone.length = len;
  } else if (k === 'axis') {
    bone.axis = vec3(parts, 1, lineNo, `an axis angle in ${ANGLE_UNIT_NAMES[reader.skeleton.angleUnit]}`, MAX_ANGLE);
    bone.axisOrder = axisOrder(parts[4], lineNo);
  } else if (k === 'dof') {
    const dof = parts.slice(1).map((d) => d.toLowerCase());
    for (const d of dof) if (!DOF_NAMES.has(d)) throw new MotionFormatError('asf', `unknown dof ${quoteInput(d)} (expected rx ry rz tx ty tz l)`, lineNo);
    const repeated = firstRepeat(dof);
    if (repeated) throw new MotionFormatError('asf', `dof "${repeated}" is listed twice`, lineNo);
    bone.dof = dof;
  }
  // id, limits (and their continuation lines), bodymass, cofmass: not needed.
}

/** The bone's "end" line: checks the entry and adds it to the skeleton. */
function finishBone(reader: AsfReader, endLine: number): void {
  const bone = reader.bone;
  if (!bone) throw new MotionFormatError('asf', '"end" without "begin" in :bonedata', endLine);
  for (const field of ['name', 'direction', 'length'] as const) {
    if (bone[field] === undefined) throw new MotionFormatError('asf', `bone starting at line ${bone.line} has no ${field}`, endLine);
  }
  const name = bone.name!;
  if (name === 'root' || reader.boneNames.has(name)) throw new MotionFormatError('asf', `duplicate bone name ${quoteInput(name)}`, bone.line);
  reader.boneNames.add(name);
  reader.skeleton.bones.push({
    name,
    direction: unitDirection(bone.direction!),
    length: bone.length!,
    axis: bone.axis ?? [0, 0, 0],
    axisOrder: bone.axisOrder ?? 'XYZ',
    dof: bone.dof ?? [],
  });
  reader.bone = undefined;
}

/**
 * One :hierarchy line: "begin", "end", or "parent child1 child2 …" inside the block. A bone is listed
 * under one parent only, so the links form a tree from the root (and perhaps cycles cut off from it).
 */
function readHierarchyLine(reader: AsfReader, k: string, key: string, parts: string[], lineNo: number): void {
  if (k === 'begin') reader.inHierarchyBlock = true;
  else if (k === 'end') reader.inHierarchyBlock = false;
  else {
    if (!reader.inHierarchyBlock) throw new MotionFormatError('asf', `expected "begin" in :hierarchy, found ${quoteInput(key)}`, lineNo);
    let entry = reader.children.get(key);
    if (!entry) reader.children.set(key, (entry = { names: [], line: lineNo }));
    for (let c = 1; c < parts.length; c++) {
      const child = parts[c];
      const listed = reader.parentOf.get(child);
      if (listed) {
        throw new MotionFormatError('asf', `:hierarchy lists bone ${quoteInput(child)} under both ${quoteInput(listed.parent)} (line ${listed.line}) and ${quoteInput(key)}`, lineNo);
      }
      reader.parentOf.set(child, { parent: key, line: lineNo });
      entry.names.push(child);
    }
  }
}

/** Fills skeleton.joints and .parents depth first from the root, children in the order listed. */
function orderJoints(skeleton: AsfSkeleton, children: BoneChildren, parentOf: BoneParents): void {
  const known = new Set(skeleton.bones.map((b) => b.name));
  for (const [parent, { names, line }] of children) {
    if (parent !== 'root' && !known.has(parent)) throw new MotionFormatError('asf', `:hierarchy names unknown bone ${quoteInput(parent)}`, line);
    for (const c of names) if (!known.has(c)) throw new MotionFormatError('asf', `:hierarchy names unknown bone ${quoteInput(c)}`, parentOf.get(c)!.line);
  }
  // Every bone has at most one parent and the root none, so this walk meets each joint once.
  const stack: Array<{ name: string; parent: number }> = [{ name: 'root', parent: -1 }];
  while (stack.length > 0) {
    const { name, parent } = stack.pop()!;
    const index = skeleton.joints.length;
    skeleton.joints.push(name);
    skeleton.parents.push(parent);
    parseWork.steps++;
    const names = children.get(name)?.names ?? [];
    for (let c = names.length - 1; c >= 0; c--) stack.push({ name: names[c], parent: index });
  }
  if (skeleton.joints.length === skeleton.bones.length + 1) return;
  const placed = new Set(skeleton.joints);
  const cutOff = skeleton.bones.find((b) => !placed.has(b.name))!.name;
  // Up from a bone the walk missed: the links end at a bone without a parent, or go round a cycle.
  const above = new Set<string>();
  let name = cutOff;
  while (parentOf.has(name) && !above.has(name)) {
    above.add(name);
    name = parentOf.get(name)!.parent;
  }
  if (above.has(name)) throw new MotionFormatError('asf', `:hierarchy links bone ${quoteInput(name)} below itself (a cycle cut off from the root)`, parentOf.get(name)!.line);
  throw new MotionFormatError('asf', `bone ${quoteInput(cutOff)} is not connected to the root in :hierarchy`);
}

export interface AMCOptions {
  /** Frames per second (AMC files do not say); CMU captures are 120. */
  fps?: number;
}

interface JointKinematics {
  bone?: AsfBone;
  c: Quat; // axis rotation C
  cInv: Quat;
  offset: Vec3; // direction · length, metres
  /** Axis letters of the rotation dofs in value order, and where each value sits in the bone's line. */
  rotAxes: string;
  rotSlots: number[];
  /** What each value of the bone's line is, for the bound it must keep: a rotation (angle) or not. */
  valueIsAngle: boolean[];
  valueCount: number;
  firstValue: number; // index of the first value in a frame vector
}

const angleScale = (unit: 'deg' | 'rad') => (unit === 'deg' ? DEG : 1);

export function parseAMC(text: string, asf: AsfSkeleton | string, options: AMCOptions = {}): Motion {
  const skeleton = typeof asf === 'string' ? parseASF(asf) : asf;
  checkText(text, 'amc');
  const fps = options.fps ?? 120;
  if (!(fps > 0 && Number.isFinite(fps))) throw new Error(`parseAMC: fps must be a positive number, got ${fps}`);

  const { kin, valuesPerFrame } = jointKinematics(skeleton);
  const frames = readAMCFrames(splitLines(text), skeleton, kin, valuesPerFrame);
  setAxisRotations(skeleton, kin);
  const positions = amcPositions(skeleton, kin, frames, angleScale(frames.angleUnit));
  return { fps, frames: frames.frameValues.length, joints: skeleton.joints.slice(), parents: skeleton.parents.slice(), positions };
}

/** Per joint: where its values live in a frame vector and which rotation they make (C still identity). */
function jointKinematics(skeleton: AsfSkeleton): { kin: JointKinematics[]; valuesPerFrame: number } {
  const byName = new Map(skeleton.bones.map((b) => [b.name, b]));
  let valuesPerFrame = 0;
  const kin: JointKinematics[] = skeleton.joints.map((name) => {
    const bone = name === 'root' ? undefined : byName.get(name)!;
    const dof = bone ? bone.dof : skeleton.root.order.map((o) => o.toLowerCase());
    const rotSlots: number[] = [];
    let rotAxes = '';
    dof.forEach((d, i) => {
      if (d[0] === 'r') {
        rotAxes += d[1];
        rotSlots.push(i);
      }
    });
    const k: JointKinematics = {
      bone,
      c: quatIdentity(),
      cInv: quatIdentity(),
      offset: bone ? [bone.direction[0] * bone.length * skeleton.lengthScale, bone.direction[1] * bone.length * skeleton.lengthScale, bone.direction[2] * bone.length * skeleton.lengthScale] : [0, 0, 0],
      rotAxes,
      rotSlots,
      valueIsAngle: dof.map((d) => d[0] === 'r'),
      valueCount: dof.length,
      firstValue: valuesPerFrame,
    };
    valuesPerFrame += dof.length;
    return k;
  });
  return { kin, valuesPerFrame };
}

/** An AMC file's frames: their value vectors, the file's number for the first one, the line of each one's number; its angle unit. */
interface AMCFrames {
  frameValues: Float64Array[];
  firstNumber: number;
  numberLines: number[];
  angleUnit: 'deg' | 'rad';
}

/**
 * The frames of an AMC file, and its angle unit. AMC lines: ":DEGREES" / ":RADIANS" / other headers,
 * "#" comments, frame numbers, "bone v1 v2 …".
 */
function readAMCFrames(lines: string[], skeleton: AsfSkeleton, kin: JointKinematics[], valuesPerFrame: number): AMCFrames {
  const J = skeleton.joints.length;
  let angleUnit = skeleton.angleUnit;
  const jointIndex = new Map(skeleton.joints.map((n, j) => [n, j]));
  const frameValues: Float64Array[] = [];
  const numberLines: number[] = [];
  let firstNumber = 0;
  let current: Float64Array | undefined;
  const seen = new Uint8Array(J);
  let currentLine = 0;
  let expectedNumber = -1;

  const closeFrame = (atEnd: boolean) => {
    if (!current) return;
    for (let j = 0; j < J; j++) {
      if (!seen[j] && kin[j].valueCount > 0) {
        const hint = atEnd ? ' (file truncated?)' : '';
        throw new MotionFormatError('amc', `frame ${expectedNumber - 1} has no values for ${quoteInput(skeleton.joints[j])}${hint}`, currentLine);
      }
    }
    frameValues.push(current);
  };

  for (let i = 0; i < lines.length; i++) {
    const lineNo = i + 1;
    const trimmed = lines[i].trim();
    if (trimmed === '' || trimmed.startsWith('#')) continue;
    if (trimmed.startsWith(':')) {
      const key = trimmed.split(/\s+/)[0].toUpperCase();
      if (key === ':DEGREES') angleUnit = 'deg';
      else if (key === ':RADIANS') angleUnit = 'rad';
      continue;
    }
    const parts = tokens(trimmed);
    if (parts.length === 1 && /^\d+$/.test(parts[0])) {
      const n = Number(parts[0]);
      if (n > Number.MAX_SAFE_INTEGER) throw new MotionFormatError('amc', `expected a frame number of at most ${Number.MAX_SAFE_INTEGER}, found ${quoteInput(parts[0])}`, lineNo);
      if (expectedNumber >= 0 && n !== expectedNumber) {
        throw new MotionFormatError('amc', `expected frame number ${expectedNumber}, found ${n}`, lineNo);
      }
      closeFrame(false);
      if (frameValues.length >= MAX_FRAMES) throw new MotionFormatError('amc', `more than ${MAX_FRAMES} frames`, lineNo);
      if ((frameValues.length + 1) * valuesPerFrame > MAX_VALUES) throw new MotionFormatError('amc', `more than ${MAX_VALUES} values`, lineNo);
      const positionValues = (frameValues.length + 1) * J * 3;
      if (positionValues > MAX_VALUES) {
        throw new MotionFormatError('amc', `${frameValues.length + 1} frames × ${J} joints × 3 = ${positionValues} position values; at most ${MAX_VALUES} are supported`, lineNo);
      }
      if (expectedNumber < 0) firstNumber = n;
      expectedNumber = n + 1;
      numberLines.push(lineNo);
      current = new Float64Array(valuesPerFrame);
      seen.fill(0);
      currentLine = lineNo;
      continue;
    }
    if (!current) throw new MotionFormatError('amc', `expected a frame number before ${quoteInput(parts[0])}`, lineNo);
    const j = jointIndex.get(parts[0]);
    if (j === undefined) throw new MotionFormatError('amc', `unknown bone ${quoteInput(parts[0])} (not in the ASF skeleton)`, lineNo);
    if (seen[j]) throw new MotionFormatError('amc', `bone ${quoteInput(parts[0])} appears twice in frame ${expectedNumber - 1}`, lineNo);
    readBoneValues(kin[j], parts, current, lineNo, angleUnit);
    seen[j] = 1;
  }
  closeFrame(true);
  if (frameValues.length === 0) throw new MotionFormatError('amc', 'no frames found (expected a frame number followed by bone lines)');
  return { frameValues, firstNumber, numberLines, angleUnit };
}

const AMC_ANGLE = { deg: `an angle in ${ANGLE_UNIT_NAMES.deg}`, rad: `an angle in ${ANGLE_UNIT_NAMES.rad}` } as const;

/** A "bone v1 v2 …" line: its values into the bone's slots of the frame vector, each within its bound. */
function readBoneValues(k: JointKinematics, parts: string[], frame: Float64Array, lineNo: number, angleUnit: 'deg' | 'rad'): void {
  if (parts.length - 1 !== k.valueCount) {
    throw new MotionFormatError('amc', `expected ${k.valueCount} numbers for ${quoteInput(parts[0])}, found ${parts.length - 1}`, lineNo);
  }
  const translation = k.bone ? 'a bone translation or length in length units' : 'a root translation in length units';
  for (let v = 0; v < k.valueCount; v++) {
    frame[k.firstValue + v] = k.valueIsAngle[v]
      ? parseBounded(parts[v + 1], 'amc', lineNo, AMC_ANGLE[angleUnit], MAX_ANGLE)
      : parseBounded(parts[v + 1], 'amc', lineNo, translation, MAX_TRANSLATION);
  }
}

/** Axis rotations C (and C⁻¹), in the ASF's own angle unit. */
function setAxisRotations(skeleton: AsfSkeleton, kin: JointKinematics[]): void {
  const asfAngle = angleScale(skeleton.angleUnit);
  kin.forEach((k, j) => {
    if (j === 0) {
      const o = skeleton.root.orientation;
      k.c = eulerToQuat([o[0] * asfAngle, o[1] * asfAngle, o[2] * asfAngle], skeleton.root.axisOrder, false);
    } else {
      const a = k.bone!.axis;
      k.c = eulerToQuat([a[0] * asfAngle, a[1] * asfAngle, a[2] * asfAngle], k.bone!.axisOrder, false);
    }
    k.cInv = quatConjugate(k.c);
  });
}

/**
 * Forward kinematics: frames × joints × 3 positions in metres (see the header comment); a position beyond
 * ±MAX_POSITION on an axis is rejected, naming the frame (by its number in the file) and the line of that number.
 */
function amcPositions(skeleton: AsfSkeleton, kin: JointKinematics[], { frameValues, firstNumber, numberLines }: AMCFrames, motionAngle: number): Float32Array {
  const J = skeleton.joints.length;
  const frames = frameValues.length;
  const positions = new Float32Array(frames * J * 3);
  const rootOrder = skeleton.root.order;
  const s = skeleton.lengthScale;
  const globals: Quat[] = new Array(J);
  const ends: Vec3[] = new Array(J);
  const parents = skeleton.parents;
  for (let f = 0; f < frames; f++) {
    const values = frameValues[f];
    parseWork.steps += J;
    for (let j = 0; j < J; j++) {
      const k = kin[j];
      const angles = k.rotSlots.map((slot) => values[k.firstValue + slot] * motionAngle);
      const m = eulerToQuat(angles, k.rotAxes, false);
      const local = quatMultiply(quatMultiply(k.c, m), k.cInv);
      if (j === 0) {
        const t: Vec3 = [skeleton.root.position[0], skeleton.root.position[1], skeleton.root.position[2]];
        rootOrder.forEach((o, i) => {
          if (o[0] === 'T') t[o.charCodeAt(1) - 88] += values[k.firstValue + i];
        });
        globals[0] = local;
        ends[0] = [t[0] * s, t[1] * s, t[2] * s];
      } else {
        const p = parents[j];
        globals[j] = quatMultiply(globals[p], local);
        const o = quatRotate(globals[j], k.offset);
        ends[j] = [ends[p][0] + o[0], ends[p][1] + o[1], ends[p][2] + o[2]];
      }
      for (let axis = 0; axis < 3; axis++) {
        const far = positionOutOfBounds(ends[j][axis], firstNumber + f, skeleton.joints[j], axis);
        if (far) throw new MotionFormatError('amc', far, numberLines[f]);
      }
      positions.set(ends[j], (f * J + j) * 3);
    }
  }
  return positions;
}
