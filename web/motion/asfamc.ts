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
import { MotionFormatError, type Motion } from './types';
import { DEG, eulerToQuat, quatConjugate, quatIdentity, quatMultiply, quatRotate, type Quat, type Vec3 } from './math';
import { MAX_FRAMES, MAX_VALUES, checkText, parseNumber, splitLines, tokens } from './text';

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
    throw new MotionFormatError('asf', `expected an axis order like XYZ, found "${token ?? ''}"`, line);
  }
  return order;
}

function vec3(parts: string[], from: number, line: number, what: string): Vec3 {
  if (parts.length < from + 3) throw new MotionFormatError('asf', `expected 3 numbers for ${what}, found ${Math.max(0, parts.length - from)}`, line);
  return [parseNumber(parts[from], 'asf', line, what), parseNumber(parts[from + 1], 'asf', line, what), parseNumber(parts[from + 2], 'asf', line, what)];
}

type BoneChildren = Map<string, { names: string[]; line: number }>;

/** What parseASF has read so far: the skeleton, the open section and the bone or block being read. */
interface AsfReader {
  skeleton: AsfSkeleton;
  section: string;
  sawBonedata: boolean;
  sawHierarchy: boolean;
  /** The :bonedata entry between "begin" and "end", with the line of its "begin". */
  bone: (Partial<AsfBone> & { line: number }) | undefined;
  inHierarchyBlock: boolean;
  /** :hierarchy lines: parent name → children, with the line that first names the parent. */
  children: BoneChildren;
}

export function parseASF(text: string): AsfSkeleton {
  checkText(text, 'asf');
  const reader = readASFSections(splitLines(text));
  orderJoints(reader.skeleton, reader.children);
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
    inHierarchyBlock: false,
    children: new Map(),
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
    if (!(l > 0)) throw new MotionFormatError('asf', `expected a positive length unit, found ${parts[1]}`, lineNo);
    skeleton.lengthScale = 0.0254 / l;
  } else if (k === 'angle') {
    const unit = (parts[1] ?? '').toLowerCase();
    if (unit.startsWith('deg')) skeleton.angleUnit = 'deg';
    else if (unit.startsWith('rad')) skeleton.angleUnit = 'rad';
    else throw new MotionFormatError('asf', `expected angle unit "deg" or "rad", found "${parts[1] ?? ''}"`, lineNo);
  }
}

function readRootLine(skeleton: AsfSkeleton, k: string, parts: string[], lineNo: number): void {
  if (k === 'order') {
    const order = parts.slice(1).map((p) => p.toUpperCase());
    for (const o of order) if (!ROOT_ORDER_NAMES.has(o)) throw new MotionFormatError('asf', `unknown root order entry "${o}" (expected TX TY TZ RX RY RZ)`, lineNo);
    skeleton.root.order = order;
  } else if (k === 'axis') skeleton.root.axisOrder = axisOrder(parts[1], lineNo);
  else if (k === 'position') skeleton.root.position = vec3(parts, 1, lineNo, 'the root position');
  else if (k === 'orientation') skeleton.root.orientation = vec3(parts, 1, lineNo, 'the root orientation');
}

/** One :bonedata line: "begin" … "end" around name, direction, length, axis and dof lines. */
function readBonedataLine(reader: AsfReader, k: string, key: string, parts: string[], lineNo: number): void {
  if (k === 'begin') {
    if (reader.bone) throw new MotionFormatError('asf', `bone starting at line ${reader.bone.line} has no "end"`, lineNo);
    reader.bone = { line: lineNo };
    return;
  }
  if (k === 'end') {
    finishBone(reader, lineNo);
    return;
  }
  const bone = reader.bone;
  if (!bone) {
    throw new MotionFormatError('asf', `expected "begin" in :bonedata, found "${key}"`, lineNo);
  } else if (k === 'name') {
    if (!parts[1]) throw new MotionFormatError('asf', 'expected a bone name', lineNo);
    bone.name = parts[1];
  } else if (k === 'direction') {
    bone.direction = vec3(parts, 1, lineNo, 'the bone direction');
  } else if (k === 'length') {
    const len = parseNumber(parts[1] ?? '', 'asf', lineNo, 'a bone length');
    if (len < 0) throw new MotionFormatError('asf', `expected a non-negative bone length, found ${len}`, lineNo);
    bone.length = len;
  } else if (k === 'axis') {
    bone.axis = vec3(parts, 1, lineNo, 'the bone axis');
    bone.axisOrder = axisOrder(parts[4], lineNo);
  } else if (k === 'dof') {
    const dof = parts.slice(1).map((d) => d.toLowerCase());
    for (const d of dof) if (!DOF_NAMES.has(d)) throw new MotionFormatError('asf', `unknown dof "${d}" (expected rx ry rz tx ty tz l)`, lineNo);
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
  const bones = reader.skeleton.bones;
  const name = bone.name!;
  if (name === 'root' || bones.some((b) => b.name === name)) throw new MotionFormatError('asf', `duplicate bone name "${name}"`, bone.line);
  const d = bone.direction!;
  const n = Math.hypot(d[0], d[1], d[2]);
  bones.push({
    name,
    direction: n > 0 ? [d[0] / n, d[1] / n, d[2] / n] : [0, 0, 0],
    length: bone.length!,
    axis: bone.axis ?? [0, 0, 0],
    axisOrder: bone.axisOrder ?? 'XYZ',
    dof: bone.dof ?? [],
  });
  reader.bone = undefined;
}

/** One :hierarchy line: "begin", "end", or "parent child1 child2 …" inside the block. */
function readHierarchyLine(reader: AsfReader, k: string, key: string, parts: string[], lineNo: number): void {
  if (k === 'begin') reader.inHierarchyBlock = true;
  else if (k === 'end') reader.inHierarchyBlock = false;
  else {
    if (!reader.inHierarchyBlock) throw new MotionFormatError('asf', `expected "begin" in :hierarchy, found "${key}"`, lineNo);
    const entry = reader.children.get(key);
    if (entry) entry.names.push(...parts.slice(1));
    else reader.children.set(key, { names: parts.slice(1), line: lineNo });
  }
}

/** Fills skeleton.joints and .parents depth first from the root, children in the order listed. */
function orderJoints(skeleton: AsfSkeleton, children: BoneChildren): void {
  const known = new Set(skeleton.bones.map((b) => b.name));
  for (const [parent, { names, line }] of children) {
    if (parent !== 'root' && !known.has(parent)) throw new MotionFormatError('asf', `:hierarchy names unknown bone "${parent}"`, line);
    for (const c of names) if (!known.has(c)) throw new MotionFormatError('asf', `:hierarchy names unknown bone "${c}"`, line);
  }
  const visit = (name: string, parent: number) => {
    if (skeleton.joints.includes(name)) throw new MotionFormatError('asf', `:hierarchy lists bone "${name}" twice or in a cycle`, children.get(name)?.line);
    const index = skeleton.joints.length;
    skeleton.joints.push(name);
    skeleton.parents.push(parent);
    for (const c of children.get(name)?.names ?? []) visit(c, index);
  };
  visit('root', -1);
  for (const b of skeleton.bones) {
    if (!skeleton.joints.includes(b.name)) throw new MotionFormatError('asf', `bone "${b.name}" is not connected to the root in :hierarchy`);
  }
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
  const { frameValues, angleUnit } = readAMCFrames(splitLines(text), skeleton, kin, valuesPerFrame);
  setAxisRotations(skeleton, kin);
  const positions = amcPositions(skeleton, kin, frameValues, angleScale(angleUnit));
  return { fps, frames: frameValues.length, joints: skeleton.joints.slice(), parents: skeleton.parents.slice(), positions };
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
      valueCount: dof.length,
      firstValue: valuesPerFrame,
    };
    valuesPerFrame += dof.length;
    return k;
  });
  return { kin, valuesPerFrame };
}

/**
 * The frame vectors of an AMC file, and its angle unit. AMC lines: ":DEGREES" / ":RADIANS" / other
 * headers, "#" comments, frame numbers, "bone v1 v2 …".
 */
function readAMCFrames(
  lines: string[], skeleton: AsfSkeleton, kin: JointKinematics[], valuesPerFrame: number,
): { frameValues: Float64Array[]; angleUnit: 'deg' | 'rad' } {
  const J = skeleton.joints.length;
  let angleUnit = skeleton.angleUnit;
  const jointIndex = new Map(skeleton.joints.map((n, j) => [n, j]));
  const frameValues: Float64Array[] = [];
  let current: Float64Array | undefined;
  const seen = new Uint8Array(J);
  let currentLine = 0;
  let expectedNumber = -1;

  const closeFrame = (atEnd: boolean) => {
    if (!current) return;
    for (let j = 0; j < J; j++) {
      if (!seen[j] && kin[j].valueCount > 0) {
        const hint = atEnd ? ' (file truncated?)' : '';
        throw new MotionFormatError('amc', `frame ${expectedNumber - 1} has no values for "${skeleton.joints[j]}"${hint}`, currentLine);
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
      if (expectedNumber >= 0 && n !== expectedNumber) {
        throw new MotionFormatError('amc', `expected frame number ${expectedNumber}, found ${n}`, lineNo);
      }
      closeFrame(false);
      if (frameValues.length >= MAX_FRAMES) throw new MotionFormatError('amc', `more than ${MAX_FRAMES} frames`, lineNo);
      if ((frameValues.length + 1) * valuesPerFrame > MAX_VALUES) throw new MotionFormatError('amc', `more than ${MAX_VALUES} values`, lineNo);
      expectedNumber = n + 1;
      current = new Float64Array(valuesPerFrame);
      seen.fill(0);
      currentLine = lineNo;
      continue;
    }
    if (!current) throw new MotionFormatError('amc', `expected a frame number before "${parts[0]}"`, lineNo);
    const j = jointIndex.get(parts[0]);
    if (j === undefined) throw new MotionFormatError('amc', `unknown bone "${parts[0]}" (not in the ASF skeleton)`, lineNo);
    if (seen[j]) throw new MotionFormatError('amc', `bone "${parts[0]}" appears twice in frame ${expectedNumber - 1}`, lineNo);
    readBoneValues(kin[j], parts, current, lineNo);
    seen[j] = 1;
  }
  closeFrame(true);
  if (frameValues.length === 0) throw new MotionFormatError('amc', 'no frames found (expected a frame number followed by bone lines)');
  return { frameValues, angleUnit };
}

/** A "bone v1 v2 …" line: its values into the bone's slots of the frame vector. */
function readBoneValues(k: JointKinematics, parts: string[], frame: Float64Array, lineNo: number): void {
  if (parts.length - 1 !== k.valueCount) {
    throw new MotionFormatError('amc', `expected ${k.valueCount} numbers for "${parts[0]}", found ${parts.length - 1}`, lineNo);
  }
  for (let v = 0; v < k.valueCount; v++) frame[k.firstValue + v] = parseNumber(parts[v + 1], 'amc', lineNo);
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

/** Forward kinematics: frames × joints × 3 positions in metres (see the header comment). */
function amcPositions(skeleton: AsfSkeleton, kin: JointKinematics[], frameValues: Float64Array[], motionAngle: number): Float32Array {
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
      positions.set(ends[j], (f * J + j) * 3);
    }
  }
  for (let v = 0; v < positions.length; v++) {
    if (!Number.isFinite(positions[v])) throw new MotionFormatError('amc', 'joint positions overflow (values too large)');
  }
  return positions;
}
