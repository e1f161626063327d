// glTF 2.0 export of a positions-only Motion, as one binary file (.glb), for Blender, three.js, game engines.
//
//   exportGLB(motion: Motion, options?: GLBExportOptions): Uint8Array
//     options.restPose  'tpose' (default) or 'clip': the bind pose (restPose.ts). 'tpose' throws an Error
//                       when the skeleton is not a humanoid the mapper can read ("T-pose rest needs …").
//     options.name      the scene's, figure's and animation's name (default 'motion').
//   gltfJointNames(joints: readonly string[]): string[]
//     the node name each joint gets: a name of letters, digits and other characters glTF readers keep is kept
//     as it is; in any other whitespace and . : / [ ] { } and control characters become "_" (three.js's
//     animation paths and Blender's bone names cannot hold some of them), a name Object.prototype has
//     (__proto__, constructor, …: three.js's GLTFLoader renames those) gets "_joint" after it, and a clash gets
//     "_2", "_3", …. A renamed joint's node keeps its own name in `extras.name`.
//
// Metres, y up, +z forward: glTF's own axes are the playground's, so nothing is converted. The file holds
//   - one node per joint (rest translation = its rest offset from the node above, rotation identity) and, as
//     the BVH export does, a zero-offset helper node `<joint>_to_<child>` between a joint with several children
//     and each child (jointRotations.ts), so positions are reproduced exactly for rigid skeletons;
//   - a skin over all of those nodes (inverse bind matrices of the rest pose) and a skinned mesh: a tapered
//     box along each bone, its vertices weighted 1.0 to the node that turns that bone (importers such as
//     Blender's make an armature from a skin; bare nodes would arrive as empties);
//   - one animation: the root's translation and every node's rotation, one key per frame at time frame / fps,
//     LINEAR. The rest pose stands on y = 0 (its lowest joint); the animation puts the root where the clip has it.
import { quatConjugate, quatMultiply, cross, length, normalize, type Quat, type Vec3 } from './math';
import { jointAt, parentNodeGlobal, rigClip, rotationPairs, solveGlobalRotations, type RigClip } from './jointRotations';
import { REST_POSES, restOffsets, type RestPose } from './restPose';
import { quoteInput } from './text';
import type { Motion } from './types';
import { validateMotion } from './validate';

export interface GLBExportOptions {
  /** The bind pose: 'tpose' (default) or 'clip' (restPose.ts). */
  restPose?: RestPose;
  /** Name of the scene, the figure and the animation (default 'motion'). */
  name?: string;
}

/** Characters a node name may not keep (three.js animation paths reserve . : / [ ]; whitespace and controls). */
const UNSAFE_NAME_CHARACTERS = /[\s.:/[\]{}\u0000-\u001f\u007f-\u009f]/g;

/**
 * A name three.js's GLTFLoader can keep: it counts node names in a plain object (createUniqueName), where
 * Object.prototype's properties (`__proto__`, `constructor`, `toString`, …) are already present, and gave such a node
 * the name "constructor_NaN", which nothing looks up. Those names get `_joint` after them.
 */
function safeName(name: string): string {
  const clean = name.replace(UNSAFE_NAME_CHARACTERS, '_');
  if (clean === '') return 'unnamed';
  return clean in Object.prototype ? `${clean}_joint` : clean;
}

/** `base`, or `base_2`, `base_3`, … whichever `taken` lacks first; added to `taken`. */
function uniqueName(base: string, taken: Set<string>): string {
  let name = base;
  for (let n = 2; taken.has(name); n++) name = `${base}_${n}`;
  taken.add(name);
  return name;
}

/** The node names exportGLB gives the joints (see the header). */
export function gltfJointNames(joints: readonly string[]): string[] {
  return jointAndHelperNames(joints, []).jointNames;
}

/** Joint names (safe ones kept first), then helper names `<joint>_to_<child>`, all unique. */
function jointAndHelperNames(joints: readonly string[], helpers: ReadonlyArray<{ joint: number; child: number }>) {
  const taken = new Set(joints.filter((name) => safeName(name) === name));
  const jointNames = joints.map((name) => (safeName(name) === name ? name : uniqueName(safeName(name), taken)));
  const helperNames = helpers.map(({ joint, child }) => uniqueName(`${jointNames[joint]}_to_${jointNames[child]}`, taken));
  return { jointNames, helperNames };
}

/**
 * The node tree: nodes 0 … J−1 are the joints, then one helper node per child of each joint with several
 * children. `above[n]` is the node a node hangs from (−1 for the root).
 */
interface NodeTree {
  helpers: Array<{ joint: number; child: number }>;
  /** Per joint: the node directly above it (its parent joint or its helper node; −1 for the root). */
  above: number[];
  /** Per node: its child nodes. */
  children: number[][];
}

function nodeTree(clip: RigClip): NodeTree {
  const J = clip.joints.length;
  const helpers: NodeTree['helpers'] = [];
  const above = clip.parents.slice();
  const children: number[][] = clip.children.map(() => []);
  for (let j = 0; j < J; j++) {
    const kids = clip.children[j];
    if (kids.length === 1) children[j].push(kids[0]);
    if (kids.length < 2) continue;
    for (const c of kids) {
      const node = J + helpers.length;
      helpers.push({ joint: j, child: c });
      children[j].push(node);
      children.push([c]);
      above[c] = node;
    }
  }
  return { helpers, above, children };
}

const FLOAT = 5126;
const UNSIGNED_BYTE = 5121;
const UNSIGNED_SHORT = 5123;
const UNSIGNED_INT = 5125;
const ARRAY_BUFFER = 34962;
const ELEMENT_ARRAY_BUFFER = 34963;
const COMPONENTS = { SCALAR: 1, VEC3: 3, VEC4: 4, MAT4: 16 } as const;
type AccessorType = keyof typeof COMPONENTS;

/** The binary chunk being built, with a buffer view (4-byte aligned) and an accessor per array. */
class BinaryChunk {
  readonly bufferViews: object[] = [];
  readonly accessors: object[] = [];
  private readonly parts: Uint8Array[] = [];
  private byteLength = 0;

  /** Adds `data` as an accessor of `type`; `withBounds` writes its min and max (required for POSITION and animation input). */
  accessor(data: Float32Array | Uint8Array | Uint16Array | Uint32Array, type: AccessorType, options: { target?: number; withBounds?: boolean } = {}): number {
    const componentType = data instanceof Float32Array ? FLOAT : data instanceof Uint8Array ? UNSIGNED_BYTE : data instanceof Uint16Array ? UNSIGNED_SHORT : UNSIGNED_INT;
    const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
    this.bufferViews.push({ buffer: 0, byteOffset: this.byteLength, byteLength: bytes.byteLength, ...(options.target ? { target: options.target } : {}) });
    this.parts.push(bytes);
    this.byteLength += bytes.byteLength;
    const padding = (4 - (this.byteLength % 4)) % 4;
    if (padding) {
      this.parts.push(new Uint8Array(padding));
      this.byteLength += padding;
    }
    const width = COMPONENTS[type];
    const accessor: Record<string, unknown> = { bufferView: this.bufferViews.length - 1, componentType, count: data.length / width, type };
    if (options.withBounds) {
      const min = new Array<number>(width).fill(Infinity);
      const max = new Array<number>(width).fill(-Infinity);
      for (let i = 0; i < data.length; i++) {
        min[i % width] = Math.min(min[i % width], data[i]);
        max[i % width] = Math.max(max[i % width], data[i]);
      }
      Object.assign(accessor, { min, max });
    }
    this.accessors.push(accessor);
    return this.accessors.length - 1;
  }

  bytes(): Uint8Array {
    const out = new Uint8Array(this.byteLength);
    let offset = 0;
    for (const part of this.parts) {
      out.set(part, offset);
      offset += part.byteLength;
    }
    return out;
  }
}

/** Positions-only Motion → binary glTF 2.0 (see the header). */
export function exportGLB(motion: Motion, options: GLBExportOptions = {}): Uint8Array<ArrayBuffer> {
  const m = validateMotion(motion);
  const restPose = options.restPose ?? 'tpose';
  if (!REST_POSES.includes(restPose)) throw new Error(`glTF export: restPose must be ${REST_POSES.map((p) => `'${p}'`).join(' or ')}, got ${quoteInput(String(restPose))}`);
  const name = options.name ?? 'motion';
  if (typeof name !== 'string') throw new Error(`glTF export: name must be a string, got ${typeof name}`);

  const clip = rigClip(m);
  const rest = restOffsets(clip, restPose);
  const tree = nodeTree(clip);
  const J = clip.joints.length;
  const nodeCount = J + tree.helpers.length;
  const { jointNames, helperNames } = jointAndHelperNames(clip.joints, tree.helpers);

  // Rest pose: identity rotations, so a node's world position is the sum of the offsets above it. Joints come
  // in parent order and a helper sits at its joint, so one pass places them.
  const world: Vec3[] = new Array(nodeCount);
  for (let j = 0; j < J; j++) {
    const a = tree.above[j];
    const base = a < 0 ? [0, 0, 0] : world[a];
    world[j] = [base[0] + rest[j][0], base[1] + rest[j][1], base[2] + rest[j][2]];
    for (const n of tree.children[j]) if (n >= J) world[n] = [...world[j]];
  }
  const lift = -Math.min(...world.map((p) => p[1]));
  for (const p of world) p[1] += lift;

  const bin = new BinaryChunk();
  const nodes: object[] = [];
  for (let n = 0; n < nodeCount; n++) {
    const translation = n === 0 ? world[0] : n < J ? rest[n] : [0, 0, 0];
    const node: Record<string, unknown> = { name: n < J ? jointNames[n] : helperNames[n - J], translation: Array.from(translation) };
    if (n < J && jointNames[n] !== clip.joints[n]) node.extras = { name: clip.joints[n] }; // the joint's own name (three.js: userData.name)
    if (tree.children[n].length > 0) node.children = tree.children[n];
    nodes.push(node);
  }
  const meshNode = nodes.length;
  nodes.push({ name, mesh: 0, skin: 0 });

  const figure = boneBoxes(tree, world, J);
  const attributes = {
    POSITION: bin.accessor(figure.positions, 'VEC3', { target: ARRAY_BUFFER, withBounds: true }),
    JOINTS_0: bin.accessor(figure.joints(nodeCount), 'VEC4', { target: ARRAY_BUFFER }),
    WEIGHTS_0: bin.accessor(figure.weights, 'VEC4', { target: ARRAY_BUFFER }),
  };
  const indices = bin.accessor(figure.indices, 'SCALAR', { target: ELEMENT_ARRAY_BUFFER });

  const inverseBind = new Float32Array(nodeCount * 16);
  for (let n = 0; n < nodeCount; n++) {
    // Column-major translation by −world: the inverse of a rest node's global matrix (its rotation is identity).
    inverseBind.set([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -world[n][0], -world[n][1], -world[n][2], 1], n * 16);
  }
  const inverseBindMatrices = bin.accessor(inverseBind, 'MAT4');

  const animation = animationChannels(clip, rest, tree, m.fps, bin);

  const document = {
    asset: { version: '2.0', generator: 'Motion Playground exportGLB' },
    scene: 0,
    scenes: [{ name, nodes: [0, meshNode] }],
    nodes,
    meshes: [{ name, primitives: [{ attributes, indices, mode: 4 }] }],
    skins: [{ name, inverseBindMatrices, skeleton: 0, joints: Array.from({ length: nodeCount }, (_, n) => n) }],
    animations: [{ name, ...animation }],
    buffers: [{ byteLength: 0 }],
    bufferViews: bin.bufferViews,
    accessors: bin.accessors,
  };
  const binBytes = bin.bytes();
  document.buffers[0].byteLength = binBytes.byteLength;
  return glbFile(document, binBytes);
}

/**
 * The animation's samplers and channels: key times frame / fps; the root's translation; each node's local
 * rotation, from the global rotations solved against the rest pose (consecutive keys on the same hemisphere,
 * so interpolation takes the short way).
 */
function animationChannels(clip: RigClip, rest: Vec3[], tree: NodeTree, fps: number, bin: BinaryChunk) {
  const F = clip.frames;
  const J = clip.joints.length;
  const nodeCount = J + tree.helpers.length;
  const times = new Float32Array(F);
  const rootTranslation = new Float32Array(F * 3);
  const rotations = Array.from({ length: nodeCount }, () => new Float32Array(F * 4));
  const framePair = rotationPairs(clip, rest);
  const jointGlobal: Quat[] = new Array(J);
  const helperGlobal: Quat[] = new Array(J); // indexed by child joint
  const store = (n: number, f: number, q: Quat) => {
    const out = rotations[n];
    const norm = Math.hypot(q[0], q[1], q[2], q[3]);
    const previous = f > 0 ? out[(f - 1) * 4] * q[0] + out[(f - 1) * 4 + 1] * q[1] + out[(f - 1) * 4 + 2] * q[2] + out[(f - 1) * 4 + 3] * q[3] : 1;
    const s = (previous < 0 ? -1 : 1) / norm;
    out.set([q[0] * s, q[1] * s, q[2] * s, q[3] * s], f * 4);
  };
  for (let f = 0; f < F; f++) {
    times[f] = f / fps;
    rootTranslation.set(jointAt(clip, f, 0), f * 3);
    solveGlobalRotations(clip, rest, framePair, f, jointGlobal, helperGlobal);
    for (let j = 0; j < J; j++) store(j, f, quatMultiply(quatConjugate(parentNodeGlobal(clip, j, jointGlobal, helperGlobal)), jointGlobal[j]));
    tree.helpers.forEach(({ joint, child }, h) => store(J + h, f, quatMultiply(quatConjugate(jointGlobal[joint]), helperGlobal[child])));
  }
  const input = bin.accessor(times, 'SCALAR', { withBounds: true });
  const samplers = [{ input, output: bin.accessor(rootTranslation, 'VEC3'), interpolation: 'LINEAR' }];
  const channels = [{ sampler: 0, target: { node: 0, path: 'translation' } }];
  for (let n = 0; n < nodeCount; n++) {
    samplers.push({ input, output: bin.accessor(rotations[n], 'VEC4'), interpolation: 'LINEAR' });
    channels.push({ sampler: samplers.length - 1, target: { node: n, path: 'rotation' } });
  }
  return { samplers, channels };
}

/**
 * The figure in the rest pose: a box along each bone, tapering from its start (the node above the joint) to
 * the joint, weighted 1.0 to that node, which is what turns the bone. A skeleton without bones gets a 2 cm box
 * at the root.
 */
function boneBoxes(tree: NodeTree, world: Vec3[], J: number) {
  const positions: number[] = [];
  const owners: number[] = [];
  const indices: number[] = [];
  const addBox = (start: Vec3, end: Vec3, owner: number) => {
    const axis = [end[0] - start[0], end[1] - start[1], end[2] - start[2]] as Vec3;
    const len = length(axis);
    const along = normalize(axis);
    const side = normalize(cross(along, Math.abs(along[1]) < 0.9 ? [0, 1, 0] : [1, 0, 0]));
    const up = cross(along, side);
    const startWidth = Math.min(0.04, Math.max(0.004, 0.15 * len));
    const first = positions.length / 3;
    for (const [centre, width] of [[start, startWidth], [end, startWidth / 2]] as const) {
      for (const [a, b] of [[1, 1], [-1, 1], [-1, -1], [1, -1]]) {
        for (let k = 0; k < 3; k++) positions.push(centre[k] + width * (a * side[k] + b * up[k]));
        owners.push(owner);
      }
    }
    // Outward-facing triangles: four sides, then the start and end caps.
    for (let k = 0; k < 4; k++) {
      const a0 = first + k, a1 = first + ((k + 1) % 4);
      indices.push(a0, a1, a1 + 4, a0, a1 + 4, a0 + 4);
    }
    indices.push(first, first + 2, first + 1, first, first + 3, first + 2);
    indices.push(first + 4, first + 5, first + 6, first + 4, first + 6, first + 7);
  };
  for (let j = 1; j < J; j++) {
    const owner = tree.above[j];
    if (length([world[j][0] - world[owner][0], world[j][1] - world[owner][1], world[j][2] - world[owner][2]]) > 1e-4) addBox(world[owner], world[j], owner);
  }
  if (indices.length === 0) addBox([world[0][0], world[0][1] - 0.01, world[0][2]], [world[0][0], world[0][1] + 0.01, world[0][2]], 0);
  const weights = new Float32Array(owners.length * 4);
  for (let v = 0; v < owners.length; v++) weights[v * 4] = 1;
  return {
    positions: Float32Array.from(positions),
    weights,
    indices: Uint32Array.from(indices),
    /** JOINTS_0: each vertex's node as its first joint (bytes while the node indices fit). */
    joints(nodeCount: number) {
      const out = nodeCount <= 256 ? new Uint8Array(owners.length * 4) : new Uint16Array(owners.length * 4);
      owners.forEach((n, v) => (out[v * 4] = n));
      return out;
    },
  };
}

/** The GLB container: 12-byte header, the JSON chunk (padded with spaces) and the BIN chunk (padded with zeros). */
function glbFile(document: object, binBytes: Uint8Array): Uint8Array<ArrayBuffer> {
  const json = new TextEncoder().encode(JSON.stringify(document));
  const jsonLength = Math.ceil(json.byteLength / 4) * 4;
  const binLength = Math.ceil(binBytes.byteLength / 4) * 4;
  const total = 12 + 8 + jsonLength + 8 + binLength;
  const out = new Uint8Array(total);
  const view = new DataView(out.buffer);
  view.setUint32(0, 0x46546c67, true); // 'glTF'
  view.setUint32(4, 2, true);
  view.setUint32(8, total, true);
  view.setUint32(12, jsonLength, true);
  view.setUint32(16, 0x4e4f534a, true); // 'JSON'
  out.set(json, 20);
  out.fill(0x20, 20 + json.byteLength, 20 + jsonLength);
  view.setUint32(20 + jsonLength, binLength, true);
  view.setUint32(24 + jsonLength, 0x004e4942, true); // 'BIN'
  out.set(binBytes, 28 + jsonLength);
  return out;
}
