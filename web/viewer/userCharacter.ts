// A user's own character (issue 40): a rigged humanoid read from a .glb, a self-contained .gltf or a .vrm with
// three.js's GLTFLoader, its skeleton as a CharacterRig (web/motion/retarget.ts), its humanoid map (the file's own
// VRM map when it has one, else mapRig), and a copy of it posed every frame from a retargeted motion.
//
// Units. A rig's bones are kept in their own units (a Mixamo armature scaled 0.01 has centimetre bones): each
// non-root bone's rest is its transform relative to its parent bone, and a root's rest is relative to the scene
// with the armature's rotation folded in and its translation divided by the armature's scale S, so the whole rig is
// in bone units. A posed copy is drawn inside a group scaled 1 / (S · unitsPerMetre): metres on screen.

import * as THREE from 'three';
import { GLTFLoader, type GLTF } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { clone as cloneSkinned } from 'three/examples/jsm/utils/SkeletonUtils.js';
import { CANONICAL_JOINTS, CANONICAL_PARENTS, SkeletonMapError, type CanonicalJoint, type HumanoidMap } from '../motion/humanoid';
import { mapSkeleton, toCanonical, type SkeletonMapping } from '../motion/skeletonMap';
import type { Quat, Vec3 } from '../motion/math';
import { mapRig, restPositions, retarget, type CharacterRig, type RetargetCalibration, type RetargetResult } from '../motion/retarget';
import { quoteInput } from '../motion/text';
import type { Motion } from '../motion/types';
import { matcap } from './mannequin';

/** Refused input (not a glTF, no skin, not a humanoid): the message says why, briefly. */
export class CharacterFileError extends Error {
  constructor(message: string) {
    super(message);
    this.name = 'CharacterFileError';
  }
}

/** A character read from a file: the template every posed copy is cloned from, and its rig. */
export interface CharacterAsset {
  /** The file's name without its extension (or the scene's name). */
  name: string;
  /** The file's bone names (as the file writes them, not three.js's cleaned names), rig order. */
  boneNames: string[];
  rig: CharacterRig;
  /** The humanoid map used (the file's VRM map, or found by mapRig). */
  mapping: HumanoidMap;
  /** 'vrm0', 'vrm1' when the file gave its own humanoid map; else 'mapped'. */
  mapSource: 'vrm0' | 'vrm1' | 'mapped';
  /** Bone units per metre, from the rig's height (a guess the retargeting makes too; its own is used to draw). */
  unitsPerMetre: number;
  /** The standing height in metres. */
  height: number;
  /** Vertices of its skinned meshes. */
  vertexCount: number;
  /** The loaded scene (never drawn itself; copies are). */
  readonly template: THREE.Object3D;
  /** The template's bones in rig order. */
  readonly templateBones: THREE.Bone[];
}

/** A VRM humanoid bone name → the canonical point it is. */
const VRM_POINTS: Partial<Record<string, CanonicalJoint>> = {
  hips: 'Hips', spine: 'Spine', chest: 'Spine1', neck: 'Neck', head: 'Head',
  leftUpperLeg: 'LeftUpLeg', leftLowerLeg: 'LeftLeg', leftFoot: 'LeftFoot', leftToes: 'LeftToeBase',
  rightUpperLeg: 'RightUpLeg', rightLowerLeg: 'RightLeg', rightFoot: 'RightFoot', rightToes: 'RightToeBase',
  leftUpperArm: 'LeftArm', leftLowerArm: 'LeftForeArm', leftHand: 'LeftHand', leftMiddleProximal: 'LeftHand_end',
  rightUpperArm: 'RightArm', rightLowerArm: 'RightForeArm', rightHand: 'RightHand', rightMiddleProximal: 'RightHand_end',
};

/** The points a VRM map must give (VRM's own required bones that the canonical skeleton has). */
const VRM_REQUIRED: CanonicalJoint[] = ['Hips', 'Spine', 'Head', 'LeftUpLeg', 'LeftLeg', 'LeftFoot', 'RightUpLeg', 'RightLeg', 'RightFoot', 'LeftArm', 'LeftForeArm', 'LeftHand', 'RightArm', 'RightForeArm', 'RightHand'];

const GLB_MAGIC = 0x46546c67; // "glTF"

/** Reads a character file (bytes of a .glb, .gltf or .vrm). Throws CharacterFileError with a short reason. */
export async function parseCharacter(bytes: ArrayBuffer, fileName: string): Promise<CharacterAsset> {
  const quoted = quoteInput(fileName, 60);
  const view = new DataView(bytes);
  const glb = bytes.byteLength >= 12 && view.getUint32(0, true) === GLB_MAGIC;
  let data: ArrayBuffer | string = bytes;
  if (!glb) {
    const text = new TextDecoder().decode(bytes.slice(0, Math.min(bytes.byteLength, 64))).trimStart();
    if (!text.startsWith('{')) throw new CharacterFileError(`${quoted} is not a glTF file (.glb, .gltf or .vrm)`);
    data = new TextDecoder().decode(bytes);
  } else if (view.getUint32(8, true) > bytes.byteLength) {
    throw new CharacterFileError(`${quoted} is cut short: its header says ${view.getUint32(8, true)} bytes, the file has ${bytes.byteLength}`);
  }
  let gltf: GLTF;
  try {
    gltf = await new GLTFLoader().parseAsync(data, '');
  } catch (e) {
    const why = e instanceof Error ? e.message : String(e);
    throw new CharacterFileError(`${quoted} could not be read as glTF (${why.slice(0, 140)})`);
  }
  return characterFromGltf(gltf, fileName.replace(/^.*[\\/]/, '').replace(/\.(glb|gltf|vrm)$/i, '') || gltf.scene.name || 'character');
}

function characterFromGltf(gltf: GLTF, name: string): CharacterAsset {
  const scene = gltf.scene;
  scene.updateMatrixWorld(true);
  const skinned: THREE.SkinnedMesh[] = [];
  scene.traverse((o) => {
    if ((o as THREE.SkinnedMesh).isSkinnedMesh) skinned.push(o as THREE.SkinnedMesh);
  });
  if (skinned.length === 0) throw new CharacterFileError(`${quoteInput(name, 60)} has no skinned mesh: a character needs a mesh bound to a skeleton (a skin)`);
  const boneSet = new Set<THREE.Object3D>();
  for (const mesh of skinned) for (const bone of mesh.skeleton.bones) boneSet.add(bone);
  // Rig order: the scene's depth-first order (parents before children); a bone's parent is its nearest bone ancestor.
  const bones: THREE.Bone[] = [];
  scene.traverse((o) => {
    if (boneSet.has(o)) bones.push(o as THREE.Bone);
  });
  const index = new Map(bones.map((b, k) => [b as THREE.Object3D, k]));
  const parents = bones.map((b) => {
    for (let p = b.parent; p; p = p.parent) if (index.has(p)) return index.get(p)!;
    return -1;
  });
  const nodeOf = new Map<THREE.Object3D, number>();
  for (const [object, assoc] of gltf.parser.associations) if (assoc && 'nodes' in assoc && assoc.nodes !== undefined) nodeOf.set(object as THREE.Object3D, assoc.nodes);
  const json = gltf.parser.json as { nodes?: Array<{ name?: string }>; extensions?: Record<string, unknown> };
  const boneNames = uniqueNames(bones.map((b) => json.nodes?.[nodeOf.get(b) ?? -1]?.name ?? b.name ?? 'bone'));

  const { rotations, translations } = restTransforms(bones, parents);
  const rig: CharacterRig = { bones: boneNames, parents, restRotations: rotations, restTranslations: translations };
  const positions = restPositions(rig);

  let mapSource: CharacterAsset['mapSource'] = 'mapped';
  const vrm = vrmHumanBones(json.extensions);
  if (vrm) {
    const byNode = new Map<number, number>();
    bones.forEach((b, k) => {
      const n = nodeOf.get(b);
      if (n !== undefined) byNode.set(n, k);
    });
    rig.humanoid = vrmMap(vrm.bones, byNode, positions, vrm.version);
    mapSource = vrm.version;
  }
  let mapping: HumanoidMap;
  try {
    mapping = mapRig(rig);
  } catch (e) {
    if (e instanceof SkeletonMapError) throw new CharacterFileError(`${quoteInput(name, 60)}: ${e.message}`);
    throw e;
  }
  const sceneScale = rootParentScale(bones, parents);
  const unitsPerMetre = guessUnitsPerMetre(mapping.height, sceneScale);
  let vertexCount = 0;
  for (const mesh of skinned) vertexCount += mesh.geometry.getAttribute('position')?.count ?? 0;
  return { name, boneNames, rig, mapping, mapSource, unitsPerMetre, height: mapping.height / unitsPerMetre, vertexCount, template: scene, templateBones: bones };
}

/** Names made unique ("_2", "_3" … on a clash), so a name finds one bone. */
function uniqueNames(names: string[]): string[] {
  const taken = new Set<string>();
  return names.map((base) => {
    let n = base;
    for (let k = 2; taken.has(n); k++) n = `${base}_${k}`;
    taken.add(n);
    return n;
  });
}

/** The world scale of the roots' parent (the armature): 1 when a root hangs from the scene itself. */
function rootParentScale(bones: THREE.Bone[], parents: number[]): number {
  const root = bones[parents.indexOf(-1)];
  if (!root?.parent) return 1;
  const s = new THREE.Vector3();
  root.parent.matrixWorld.decompose(new THREE.Vector3(), new THREE.Quaternion(), s);
  return (Math.abs(s.x) + Math.abs(s.y) + Math.abs(s.z)) / 3 || 1;
}

/** Bone units per metre: the scene's unit taken as a metre when the figure is 0.3–4 of them tall, else centimetres or millimetres. */
function guessUnitsPerMetre(heightInBoneUnits: number, sceneScale: number): number {
  const sceneHeight = heightInBoneUnits * sceneScale;
  for (const perMetre of [1, 100, 1000]) {
    const metres = sceneHeight / perMetre;
    if (metres >= 0.3 && metres <= 4) return perMetre / sceneScale;
  }
  return 1 / sceneScale;
}

/** Each bone's rest rotation and translation relative to its parent bone (roots: to the scene, in bone units). */
function restTransforms(bones: THREE.Bone[], parents: number[]): { rotations: Quat[]; translations: Vec3[] } {
  const rotations: Quat[] = [];
  const translations: Vec3[] = [];
  const local = new THREE.Matrix4(), inv = new THREE.Matrix4();
  const t = new THREE.Vector3(), q = new THREE.Quaternion(), s = new THREE.Vector3();
  bones.forEach((bone, k) => {
    const p = parents[k];
    if (p >= 0) {
      local.multiplyMatrices(inv.copy(bones[p].matrixWorld).invert(), bone.matrixWorld);
      local.decompose(t, q, s);
      // Relative to the parent bone: its scale (the armature's, shared) is removed by the inverse.
    } else {
      bone.matrixWorld.decompose(t, q, s);
      const scale = bone.parent ? new THREE.Vector3().setFromMatrixScale(bone.parent.matrixWorld).x || 1 : 1;
      t.divideScalar(scale); // in bone units
    }
    q.normalize();
    rotations.push([q.x, q.y, q.z, q.w]);
    translations.push([t.x, t.y, t.z]);
  });
  return { rotations, translations };
}

/** The VRM humanoid's bones (0.x: extensions.VRM, 1.0: extensions.VRMC_vrm), bone name → node index; null when none. */
function vrmHumanBones(extensions: Record<string, unknown> | undefined): { version: 'vrm0' | 'vrm1'; bones: Map<string, number> } | null {
  const v1 = (extensions?.VRMC_vrm as { humanoid?: { humanBones?: Record<string, { node?: unknown }> } } | undefined)?.humanoid?.humanBones;
  if (v1 && typeof v1 === 'object') {
    const bones = new Map<string, number>();
    for (const [bone, entry] of Object.entries(v1)) if (Number.isInteger(entry?.node)) bones.set(bone, entry.node as number);
    return { version: 'vrm1', bones };
  }
  const v0 = (extensions?.VRM as { humanoid?: { humanBones?: Array<{ bone?: unknown; node?: unknown }> } } | undefined)?.humanoid?.humanBones;
  if (Array.isArray(v0)) {
    const bones = new Map<string, number>();
    for (const entry of v0) if (typeof entry?.bone === 'string' && Number.isInteger(entry.node)) bones.set(entry.bone, entry.node as number);
    return { version: 'vrm0', bones };
  }
  return null;
}

/** A HumanoidMap from a VRM's own bone map; its facing from the sides it names (the left at up × forward). */
function vrmMap(vrm: Map<string, number>, boneOfNode: Map<number, number>, positions: Float32Array, version: 'vrm0' | 'vrm1'): HumanoidMap {
  const source = CANONICAL_JOINTS.map(() => -1);
  for (const [vrmBone, node] of vrm) {
    const point = VRM_POINTS[vrmBone];
    const bone = boneOfNode.get(node);
    if (point && bone !== undefined) source[CANONICAL_JOINTS.indexOf(point)] = bone;
  }
  const missing = VRM_REQUIRED.filter((p) => source[CANONICAL_JOINTS.indexOf(p)] < 0);
  if (missing.length) throw new CharacterFileError(`its VRM humanoid map lacks ${missing.join(', ')} (or names bones without skin)`);
  const at = (p: CanonicalJoint) => source[CANONICAL_JOINTS.indexOf(p)] * 3;
  const l = at('LeftUpLeg'), r = at('RightUpLeg');
  const lx = positions[l] - positions[r], lz = positions[l + 2] - positions[r + 2];
  // forward = left × up = (−lz, 0, lx) for up = +y.
  const n = Math.hypot(lx, lz) || 1;
  let minY = Infinity, maxY = -Infinity;
  for (let k = 1; k < positions.length; k += 3) {
    minY = Math.min(minY, positions[k]);
    maxY = Math.max(maxY, positions[k]);
  }
  return { source, scheme: version === 'vrm0' ? 'VRM 0.x' : 'VRM 1.0', facing: [-lz / n, lx / n], sidesBy: 'names', height: maxY - minY };
}

// ---------------------------------------------------------------- a posed copy

/** What the viewer needs of a drawn character (the mannequin's CharacterDriver has the same shape). */
export interface CharacterView {
  readonly mannequin: { readonly mesh: THREE.Object3D; readonly vertexCount: number; setSeeThrough(on: boolean): void };
  setMotion(motion: Motion): boolean;
  update(i0: number, i1: number, a: number, dx?: number, dz?: number): void;
  dispose(): void;
}

/**
 * A copy of a character posed by a motion retargeted onto its rig: `setMotion` retargets (once per motion or live
 * window, not per frame), `update` sets each bone from the stored rotations between two frames (no allocation).
 */
export class UserCharacterDriver implements CharacterView {
  readonly mannequin: { readonly mesh: THREE.Group; readonly vertexCount: number; setSeeThrough(on: boolean): void };
  private readonly group = new THREE.Group();
  private readonly bones: THREE.Bone[];
  private readonly roots: Array<{ bone: number; parentInverse: THREE.Matrix4; parentRotationInverse: THREE.Quaternion }>;
  private readonly sceneScale: number;
  private readonly materials: THREE.Material[] = [];
  private result: RetargetResult | null = null;
  /** The motion `result` retargets. */
  private source: Motion | null = null;
  /**
   * The shown skeleton's canonical points (null: it is the canonical skeleton), found on its first window and kept
   * for the next ones: a second of a dance (arms over the head) may not map on its own.
   */
  private sourceMapping: SkeletonMapping | null = null;
  /** The stream's calibration, once measured on CALIBRATION_FRAMES (undefined before: each chunk measures its own). */
  private calibration: RetargetCalibration | undefined;
  private readonly point = new THREE.Vector3();

  /**
   * `lit`: drawn with its own materials under the scene's lights (a GPU); else, as the mannequin under software GL,
   * each material becomes a studio matcap keeping its colour and texture (no per-pixel lighting to pay for).
   */
  constructor(readonly asset: CharacterAsset, { lit = true }: { lit?: boolean } = {}) {
    const copy = cloneSkinned(asset.template);
    copy.updateMatrixWorld(true);
    // The copy's bones in rig order: the same place in the (cloned) tree as the template's.
    const pathOf = (o: THREE.Object3D) => {
      const path: number[] = [];
      for (let x = o; x.parent && x !== asset.template; x = x.parent) path.unshift(x.parent.children.indexOf(x));
      return path;
    };
    this.bones = asset.templateBones.map((b) => {
      let x: THREE.Object3D = copy;
      for (const i of pathOf(b)) x = x.children[i];
      return x as THREE.Bone;
    });
    this.roots = [];
    asset.rig.parents.forEach((p, k) => {
      if (p >= 0) return;
      const parent = this.bones[k].parent;
      const parentWorld = parent ? parent.matrixWorld.clone() : new THREE.Matrix4();
      const q = new THREE.Quaternion();
      parentWorld.decompose(new THREE.Vector3(), q, new THREE.Vector3());
      this.roots.push({ bone: k, parentInverse: parentWorld.clone().invert(), parentRotationInverse: q.invert() });
    });
    this.sceneScale = rootParentScale(this.bones, asset.rig.parents);
    let vertexCount = 0;
    const originals = new Map<THREE.Material, THREE.Material>();
    copy.traverse((o) => {
      const mesh = o as THREE.Mesh;
      if (!mesh.isMesh) return;
      mesh.castShadow = true;
      mesh.frustumCulled = false; // its bounds are the rest pose's; the figure walks away from them
      if ((mesh as THREE.SkinnedMesh).isSkinnedMesh) vertexCount += mesh.geometry.getAttribute('position')?.count ?? 0;
      // Own materials, so that see-through on one copy leaves the others as they are.
      const own = (m: THREE.Material) => {
        if (!originals.has(m)) {
          const c = lit ? m.clone() : matcapOf(m);
          originals.set(m, c);
          this.materials.push(c);
        }
        return originals.get(m)!;
      };
      mesh.material = Array.isArray(mesh.material) ? mesh.material.map(own) : own(mesh.material);
    });
    this.group.add(copy);
    this.group.name = asset.name;
    const materials = this.materials;
    this.mannequin = {
      mesh: this.group,
      vertexCount,
      setSeeThrough(on: boolean) {
        for (const m of materials) {
          m.transparent = on;
          m.opacity = on ? 0.35 : 1;
          m.depthWrite = !on;
          m.needsUpdate = true;
        }
      },
    };
  }

  /** The retargeting now shown (null before the first motion or after one that failed). */
  get retargeted(): RetargetResult | null {
    return this.result;
  }

  /** The copy's bones in rig order (the exporter animates them). */
  get rigBones(): readonly THREE.Bone[] {
    return this.bones;
  }

  /** The drawn copy's scene root (inside the metre-scaled group). */
  get scene(): THREE.Object3D {
    return this.group.children[0];
  }

  /**
   * Retargets `motion` onto the rig; false when it cannot be (the viewer then drops this character). A live
   * stream's next window (the last one less some frames at its start, plus new frames) retargets only its new frames,
   * with LIVE_CONTEXT frames before them so that planted feet carry over.
   */
  setMotion(motion: Motion): boolean {
    const old = this.source;
    const dropped = old && this.result ? liveOverlap(old, motion) : -1;
    const started = performance.now();
    try {
      if (dropped < 0) this.sourceMapping = isCanonical(motion) ? null : mapSkeleton(motion, 1);
      const canonical = (m: Motion) => this.canonicalOf(m);
      // A stream's chunks are retargeted with the numbers (retarget's calibration: scale, ankle and sole heights, foot
      // slopes) measured once on CALIBRATION_FRAMES of it, so that they do not change from chunk to chunk.
      const calibration = dropped >= 0 && this.result!.motion.frames >= CALIBRATION_FRAMES ? (this.calibration ??= this.result!.calibration) : undefined;
      if (dropped < 0) this.calibration = undefined;
      this.result = dropped >= 0 ? extendLive(this.result!, old!, motion, dropped, this.asset.rig, canonical, calibration) : retarget(canonical(motion), this.asset.rig);
    } catch {
      this.result = null;
      this.source = null;
      return false;
    }
    // Its cost, for npm run bench (performance entries named "character-retarget"; detail: frames retargeted).
    performance.measure('character-retarget', { start: started, detail: { frames: dropped >= 0 ? motion.frames - (old!.frames - dropped) : motion.frames } });
    this.source = motion;
    this.setResult(this.result);
    return true;
  }

  /** Poses the copy between frames i0 and i1 (`a` of the way), shifted by (dx, 0, dz) metres. */
  update(i0: number, i1: number, a: number, dx = 0, dz = 0): void {
    const r = this.result;
    if (!r) return;
    const B = this.bones.length;
    const R = r.rotations;
    if ((i1 + 1) * B * 4 > R.length) return;
    for (let k = 0; k < B; k++) {
      const o0 = (i0 * B + k) * 4, o1 = (i1 * B + k) * 4;
      // Normalised lerp along the shorter arc: frames are 1/30 s apart, where it and slerp agree closely.
      const sign = R[o0] * R[o1] + R[o0 + 1] * R[o1 + 1] + R[o0 + 2] * R[o1 + 2] + R[o0 + 3] * R[o1 + 3] < 0 ? -1 : 1;
      const x = R[o0] + (sign * R[o1] - R[o0]) * a, y = R[o0 + 1] + (sign * R[o1 + 1] - R[o0 + 1]) * a;
      const z = R[o0 + 2] + (sign * R[o1 + 2] - R[o0 + 2]) * a, w = R[o0 + 3] + (sign * R[o1 + 3] - R[o0 + 3]) * a;
      const n = 1 / Math.hypot(x, y, z, w);
      this.bones[k].quaternion.set(x * n, y * n, z * n, w * n);
    }
    for (const root of this.roots) {
      const bone = this.bones[root.bone];
      // Rotations of roots are relative to the scene: take the armature's rotation off.
      bone.quaternion.premultiply(root.parentRotationInverse);
      if (root.bone !== (r.rootBone ?? 0)) continue; // the root the hips hang from moves; other roots keep their rest
      const T = r.rootTranslations, o0 = i0 * 3, o1 = i1 * 3, S = this.sceneScale;
      this.point.set(
        (T[o0] + (T[o1] - T[o0]) * a) * S,
        (T[o0 + 1] + (T[o1 + 1] - T[o0 + 1]) * a) * S,
        (T[o0 + 2] + (T[o1 + 2] - T[o0 + 2]) * a) * S,
      ).applyMatrix4(root.parentInverse);
      bone.position.copy(this.point);
    }
    this.group.position.set(dx, 0, dz);
  }

  /** `m` on the canonical skeleton through the mapping kept (retarget maps a motion that is not). */
  private canonicalOf(m: Motion): Motion {
    if (!this.sourceMapping) return m;
    const positions = toCanonical(m, { ...this.sourceMapping, scale: 1 });
    return { fps: m.fps, frames: m.frames, joints: [...CANONICAL_JOINTS], parents: [...CANONICAL_PARENTS], positions, ...(m.contacts ? { contacts: m.contacts } : {}) };
  }

  /** Shows a motion already retargeted onto this rig (the exporter's copy uses the one the page shows). */
  setResult(result: RetargetResult): void {
    this.result = result;
    this.group.scale.setScalar(1 / (this.sceneScale * result.unitsPerMetre));
  }

  /** Back to the rest (bind) pose, as the file gave it. */
  rest(): void {
    this.bones.forEach((bone, k) => {
      const t = this.asset.templateBones[k];
      bone.position.copy(t.position);
      bone.quaternion.copy(t.quaternion);
      bone.scale.copy(t.scale);
    });
    this.group.position.set(0, 0, 0);
  }

  dispose(): void {
    this.group.removeFromParent();
    for (const m of this.materials) m.dispose();
    // The copy shares its geometries and textures with the asset's template (disposed with the asset).
  }
}

/** A matcap material with `m`'s colour, texture and sidedness. */
function matcapOf(m: THREE.Material): THREE.MeshMatcapMaterial {
  const s = m as THREE.MeshStandardMaterial;
  return new THREE.MeshMatcapMaterial({
    matcap: matcap(),
    color: s.color ? s.color.clone() : new THREE.Color(0xffffff),
    map: s.map ?? null,
    side: m.side,
    alphaTest: m.alphaTest,
    transparent: m.transparent,
  });
}

/** Whether the motion is on the canonical skeleton (every model's output). */
function isCanonical(m: Motion): boolean {
  return m.joints.length === CANONICAL_JOINTS.length && m.joints.every((name, k) => name === CANONICAL_JOINTS[k]);
}

/** Frames of a live stream its calibration is measured on (the window's, when it first holds this many: 5 s). */
const CALIBRATION_FRAMES = 150;

/**
 * Frames before a live window's new ones that are retargeted with them (planted feet and their lock carry over, and
 * the part's own measures of the source settle). Measured on 600 frames of a generated walk and a salsa in chunks of
 * 30, against one retargeting of the last 300: with 30 the hips drifted 7–25 cm a chunk on the dance; with 90 they
 * stayed within 7 cm, and steps at chunk boundaries were as large as the others (hips 0.8–3.2 cm a frame, median
 * elsewhere 1.9). A part of 120 frames costs about 13 ms.
 */
const LIVE_CONTEXT = 90;
/**
 * Frames at the end of the context over which the pose fades from the earlier retargeting to the new one: fewer than
 * the live modes keep ahead of the playhead (45), so the frame on screen is not changed under it.
 */
const CROSS_FADE = 30;
/** How fast the shift that joins a live chunk to the frames before it fades (s, time constant). */
const SHIFT_FADE_SECONDS = 1;

/**
 * How many frames `next` dropped from the start of `previous` when it is the same stream's next window (its
 * first frames are `previous`'s from there on, and it is longer than what is kept); -1 when it is not.
 */
function liveOverlap(previous: Motion, next: Motion): number {
  const n = previous.joints.length * 3;
  if (next.joints.length * 3 !== n || next.fps !== previous.fps) return -1;
  const P = previous.positions, N = next.positions;
  for (let d = 0; d < previous.frames; d++) {
    const kept = previous.frames - d;
    if (kept > next.frames) continue;
    let same = true;
    // The first and last kept frames match exactly (copied arrays): the same window, shifted.
    for (let k = 0; k < n && same; k++) same = N[k] === P[d * n + k] && N[(kept - 1) * n + k] === P[(previous.frames - 1) * n + k];
    if (same) return d;
  }
  return -1;
}

/**
 * The retargeting of `next` from that of `previous` (`dropped` frames off its start): its new frames retargeted with
 * the `context` frames before them. Each retarget call measures the source afresh (its leg length, hence the scale
 * of the hips' path, and the planted ankles' height), so a part retargeted on its own does not meet the frames
 * before it: measured on generated walks and dances, the hips jumped 2–45 cm at chunk boundaries. So the part is
 * shifted to meet the earlier frames at the context's last frame, over the context's last CROSS_FADE frames (not yet
 * played: the stream runs ahead of the playhead) the pose fades from the earlier retargeting to the new one, and the shift fades
 * out over the new frames (time constant SHIFT_FADE_SECONDS), so that it does not add up chunk after chunk (the first
 * frames of a part carry their own offsets: aligned there, a dance sank 7 cm a chunk).
 */
function extendLive(old: RetargetResult, previous: Motion, next: Motion, dropped: number, rig: CharacterRig, canonical: (m: Motion) => Motion, calibration?: RetargetCalibration): RetargetResult {
  const kept = previous.frames - dropped;
  const fresh = next.frames - kept;
  const B = rig.bones.length;
  const context = Math.min(kept, LIVE_CONTEXT);
  const from = kept - context;
  const stride = next.joints.length * 3;
  const out = {
    positions: new Float32Array(next.frames * B * 3),
    rotations: new Float32Array(next.frames * B * 4),
    rootTranslations: new Float32Array(next.frames * 3),
    contacts: new Uint8Array(next.frames * 2),
  };
  // The kept frames as they were.
  out.positions.set(old.motion.positions.subarray(dropped * B * 3, previous.frames * B * 3));
  out.rotations.set(old.rotations.subarray(dropped * B * 4, previous.frames * B * 4));
  out.rootTranslations.set(old.rootTranslations.subarray(dropped * 3, previous.frames * 3));
  out.contacts.set(old.contacts.subarray(dropped * 2, previous.frames * 2));
  if (fresh <= 0) return { ...old, motion: { ...old.motion, frames: next.frames, positions: out.positions, ...(old.motion.contacts ? { contacts: out.contacts } : {}) }, ...out };

  const part: Motion = {
    ...next,
    frames: context + fresh,
    positions: next.positions.subarray(from * stride, next.frames * stride),
    contacts: next.contacts?.subarray(from * 2, next.frames * 2),
  };
  const r = retarget(canonical(part), rig, calibration ? { calibration } : {});
  // The shift (rig units) that puts the part's root on the earlier one at the context's last frame.
  const shift = [0, 0, 0];
  if (context > 0) for (let i = 0; i < 3; i++) shift[i] = out.rootTranslations[(kept - 1) * 3 + i] - r.rootTranslations[(context - 1) * 3 + i];
  const fade = 1 / (SHIFT_FADE_SECONDS * next.fps);
  const metres = [0, 0, 0];
  const shifted = [0, 0, 0];
  for (let j = 0; j < context + fresh; j++) {
    const f = from + j;
    // Weight of the new retargeting: 0 until the context's last CROSS_FADE frames, 1 at its last frame and after.
    const fadeFrom = Math.max(0, context - CROSS_FADE);
    const w = j >= context - 1 ? 1 : j < fadeFrom ? 0 : (j - fadeFrom + 1) / (context - fadeFrom);
    if (w === 0) continue; // the earlier frames as they were
    const left = j < context ? 1 : Math.exp(-(j - context + 1) * fade);
    for (let i = 0; i < 3; i++) {
      shifted[i] = shift[i] * left;
      metres[i] = shifted[i] / r.unitsPerMetre;
    }
    for (let i = 0; i < 3; i++) {
      const v = r.rootTranslations[j * 3 + i] + shifted[i];
      out.rootTranslations[f * 3 + i] = w === 1 ? v : out.rootTranslations[f * 3 + i] * (1 - w) + v * w;
    }
    for (let b = 0; b < B; b++) {
      const o = (f * B + b) * 3, n = (j * B + b) * 3;
      for (let i = 0; i < 3; i++) {
        const v = r.motion.positions[n + i] + metres[i];
        out.positions[o + i] = w === 1 ? v : out.positions[o + i] * (1 - w) + v * w;
      }
      const q = (f * B + b) * 4, m = (j * B + b) * 4;
      const R = r.rotations, O = out.rotations;
      if (w === 1) {
        O.set(R.subarray(m, m + 4), q);
        continue;
      }
      // Normalised lerp along the shorter arc.
      const sign = O[q] * R[m] + O[q + 1] * R[m + 1] + O[q + 2] * R[m + 2] + O[q + 3] * R[m + 3] < 0 ? -w : w;
      let len = 0;
      for (let i = 0; i < 4; i++) {
        O[q + i] = O[q + i] * (1 - w) + R[m + i] * sign;
        len += O[q + i] * O[q + i];
      }
      len = Math.sqrt(len) || 1;
      for (let i = 0; i < 4; i++) O[q + i] /= len;
    }
  }
  out.contacts.set(r.contacts.subarray(context * 2), kept * 2);
  return { ...r, motion: { ...r.motion, frames: next.frames, positions: out.positions, ...(r.motion.contacts ? { contacts: out.contacts } : {}) }, ...out };
}

/** Frees what a character's template holds on the GPU (its geometries and textures). */
export function disposeCharacterAsset(asset: CharacterAsset): void {
  asset.template.traverse((o) => {
    const mesh = o as THREE.Mesh;
    if (!mesh.isMesh) return;
    mesh.geometry.dispose();
    for (const m of Array.isArray(mesh.material) ? mesh.material : [mesh.material]) {
      for (const v of Object.values(m)) if (v instanceof THREE.Texture) v.dispose();
      m.dispose();
    }
  });
}
