// Test characters made in the page (issue 40): humanoid rigs of several namings built as three.js scenes and written
// as GLB by three.js's GLTFExporter, as a user's tool would write them. Loaded in the page through the dev server:
//   const rigs = await import(`/@fs${ROOT}tests/support/characterRigs.mjs`);
//   const bytes = await rigs.makeRig({ naming: 'mixamo', scale: 0.01, pose: 'A' });
// Every rig is the same body (hips 0.95 m up, legs 0.85 m, arms 0.55 m), so results can be compared across namings.
import * as THREE from 'three';
import { GLTFExporter } from 'three/examples/jsm/exporters/GLTFExporter.js';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';

/** The body: each point, its parent, and its position relative to the parent in metres (the rig faces +z, left at +x). */
const BODY = [
  ['hips', null, [0, 0.95, 0]],
  ['spine', 'hips', [0, 0.1, 0]],
  ['chest', 'spine', [0, 0.15, 0]],
  ['neck', 'chest', [0, 0.22, 0]],
  ['head', 'neck', [0, 0.1, 0.01]],
  ['headTop', 'head', [0, 0.2, 0]],
  ['leftUpperLeg', 'hips', [0.1, -0.05, 0]],
  ['leftLowerLeg', 'leftUpperLeg', [0, -0.43, 0.01]],
  ['leftFoot', 'leftLowerLeg', [0, -0.42, -0.02]],
  ['leftToes', 'leftFoot', [0, -0.05, 0.13]],
  ['leftToesEnd', 'leftToes', [0, 0, 0.06]],
  ['rightUpperLeg', 'hips', [-0.1, -0.05, 0]],
  ['rightLowerLeg', 'rightUpperLeg', [0, -0.43, 0.01]],
  ['rightFoot', 'rightLowerLeg', [0, -0.42, -0.02]],
  ['rightToes', 'rightFoot', [0, -0.05, 0.13]],
  ['rightToesEnd', 'rightToes', [0, 0, 0.06]],
  ['leftShoulder', 'chest', [0.04, 0.18, 0]],
  ['leftUpperArm', 'leftShoulder', [0.14, 0, 0]],
  ['leftLowerArm', 'leftUpperArm', [0.28, 0, 0]],
  ['leftHand', 'leftLowerArm', [0.25, 0, 0]],
  ['leftMiddleProximal', 'leftHand', [0.1, 0, 0]],
  ['rightShoulder', 'chest', [-0.04, 0.18, 0]],
  ['rightUpperArm', 'rightShoulder', [-0.14, 0, 0]],
  ['rightLowerArm', 'rightUpperArm', [-0.28, 0, 0]],
  ['rightHand', 'rightLowerArm', [-0.25, 0, 0]],
  ['rightMiddleProximal', 'rightHand', [-0.1, 0, 0]],
];

const MIXAMO = {
  hips: 'Hips', spine: 'Spine1', chest: 'Spine2', neck: 'Neck', head: 'Head', headTop: 'HeadTop_End',
  UpperLeg: 'UpLeg', LowerLeg: 'Leg', Foot: 'Foot', Toes: 'ToeBase', ToesEnd: 'Toe_End',
  Shoulder: 'Shoulder', UpperArm: 'Arm', LowerArm: 'ForeArm', Hand: 'Hand', MiddleProximal: 'HandMiddle1',
};

/** The bone name of a body point in a naming: 'vrm' (the points' own names), 'mixamo' (mixamorig: prefixed). */
function boneName(point, naming) {
  if (naming !== 'mixamo') return point;
  const side = /^(left|right)/.exec(point)?.[1];
  const rest = side ? point.slice(side.length) : point;
  return `mixamorig:${side ? (side === 'left' ? 'Left' : 'Right') : ''}${MIXAMO[rest] ?? rest}`;
}

/**
 * A rigged humanoid as GLB bytes (Uint8Array). Options:
 *   naming 'vrm' | 'mixamo'; scale: the armature's scale (Mixamo's 0.01: bones in centimetres under a 0.01 node);
 *   pose 'T' | 'A' (arms 45° down); facing 1 (+z) or -1 (−z: the armature turned 180°); vrm: 0 or 1 writes a VRM 0.x
 *   or 1.0 humanoid map into the file's extensions; legs: false leaves the legs out (not a humanoid); skin: false
 *   writes a plain mesh; vertices: about how many the skinned mesh has (default ~2,000); helperRoot: a bone of its
 *   own before the hips' tree (the rig's first bone is then not the hips' root).
 */
export async function makeRig({ naming = 'vrm', scale = 1, pose = 'T', facing = 1, vrm = null, legs = true, skin = true, vertices = 2000, helperRoot = false } = {}) {
  const points = BODY.filter(([p]) => legs || !/Leg|Foot|Toes/.test(p));
  const unit = 1 / scale;
  const bones = new Map();
  for (const [point, parent, offset] of points) {
    const bone = new THREE.Bone();
    bone.name = boneName(point, naming);
    bone.position.fromArray(offset).multiplyScalar(unit);
    if (parent) bones.get(parent).add(bone);
    bones.set(point, bone);
  }
  if (pose === 'A') {
    // Upper arms turned 45° down about the forward axis; children's offsets follow.
    bones.get('leftUpperArm').quaternion.setFromAxisAngle(new THREE.Vector3(0, 0, 1), -Math.PI / 4);
    bones.get('rightUpperArm').quaternion.setFromAxisAngle(new THREE.Vector3(0, 0, 1), Math.PI / 4);
  }
  const armature = new THREE.Group();
  armature.name = 'Armature';
  armature.scale.setScalar(scale);
  if (facing < 0) armature.rotation.y = Math.PI;
  if (helperRoot) {
    // A root bone of its own before the hips (an engine's IK root, say), a sibling of the hips' tree.
    const helper = new THREE.Bone();
    helper.name = 'ik_root';
    armature.add(helper);
    bones.set('ikRoot', helper);
  }
  armature.add(bones.get('hips'));
  const scene = new THREE.Scene();
  scene.add(armature);
  armature.updateMatrixWorld(true);
  const list = [...bones.values()].sort((a, b) => (a.name === 'ik_root' ? -1 : b.name === 'ik_root' ? 1 : 0));
  const geometry = limbGeometry(list, vertices, armature);
  const material = new THREE.MeshStandardMaterial({ color: 0x7fa0d0, roughness: 0.7 });
  if (skin) {
    const mesh = new THREE.SkinnedMesh(geometry, material);
    mesh.name = 'Body';
    armature.add(mesh);
    scene.updateMatrixWorld(true);
    mesh.bind(new THREE.Skeleton(list), mesh.matrixWorld);
  } else {
    geometry.deleteAttribute('skinIndex');
    geometry.deleteAttribute('skinWeight');
    const mesh = new THREE.Mesh(geometry, material);
    armature.add(mesh);
  }
  const glb = new Uint8Array(await new GLTFExporter().parseAsync(scene, { binary: true }));
  return vrm === null ? glb : withVrmMap(glb, vrm, naming);
}

/**
 * One skinned mesh: a tube along each bone from its parent (in the armature's space), weighted to the parent bone,
 * subdivided to about `vertices` in all.
 */
function limbGeometry(bones, vertices, armature) {
  const segments = bones.filter((b) => b.parent && b.parent.isBone);
  const rings = Math.max(2, Math.round(Math.sqrt(vertices / segments.length / 2)));
  const around = Math.max(4, Math.round(vertices / segments.length / rings));
  const toLocal = armature.matrixWorld.clone().invert();
  const pos = [], skinIndex = [], skinWeight = [], index = [];
  const a = new THREE.Vector3(), b = new THREE.Vector3(), d = new THREE.Vector3(), u = new THREE.Vector3(), v = new THREE.Vector3();
  for (const bone of segments) {
    a.setFromMatrixPosition(bone.parent.matrixWorld).applyMatrix4(toLocal);
    b.setFromMatrixPosition(bone.matrixWorld).applyMatrix4(toLocal);
    d.subVectors(b, a);
    const len = d.length();
    if (len < 1e-9) continue;
    d.normalize();
    u.set(0, 1, 0);
    if (Math.abs(u.dot(d)) > 0.9) u.set(1, 0, 0);
    u.cross(d).normalize();
    v.crossVectors(d, u);
    const radius = len * 0.18;
    const k = bones.indexOf(bone.parent);
    const base = pos.length / 3;
    for (let r = 0; r < rings; r++) {
      const t = r / (rings - 1);
      for (let s = 0; s < around; s++) {
        const ang = (s / around) * Math.PI * 2;
        pos.push(...a.clone().addScaledVector(d, len * t).addScaledVector(u, Math.cos(ang) * radius).addScaledVector(v, Math.sin(ang) * radius).toArray());
        skinIndex.push(k, 0, 0, 0);
        skinWeight.push(1, 0, 0, 0);
      }
    }
    for (let r = 0; r + 1 < rings; r++) {
      for (let s = 0; s < around; s++) {
        const i0 = base + r * around + s, i1 = base + r * around + ((s + 1) % around);
        index.push(i0, i0 + around, i1, i1, i0 + around, i1 + around);
      }
    }
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
  g.setAttribute('skinIndex', new THREE.Uint16BufferAttribute(skinIndex, 4));
  g.setAttribute('skinWeight', new THREE.Float32BufferAttribute(skinWeight, 4));
  g.setIndex(index);
  g.computeVertexNormals();
  return g;
}

/** The GLB with a VRM humanoid map (0.x: extensions.VRM, 1.0: extensions.VRMC_vrm) naming its bones' nodes. */
function withVrmMap(glb, version, naming) {
  const view = new DataView(glb.buffer, glb.byteOffset, glb.byteLength);
  const jsonLength = view.getUint32(12, true);
  const json = JSON.parse(new TextDecoder().decode(glb.subarray(20, 20 + jsonLength)));
  const nodeOf = (point) => json.nodes.findIndex((n) => n.name === boneName(point, naming));
  const vrmBones = BODY.map(([p]) => p).filter((p) => !/End$|Top$/.test(p) && nodeOf(p) >= 0);
  json.extensionsUsed = [...(json.extensionsUsed ?? []), version === 0 ? 'VRM' : 'VRMC_vrm'];
  json.extensions = json.extensions ?? {};
  if (version === 0) json.extensions.VRM = { specVersion: '0.0', humanoid: { humanBones: vrmBones.map((bone) => ({ bone, node: nodeOf(bone) })) } };
  else json.extensions.VRMC_vrm = { specVersion: '1.0', humanoid: { humanBones: Object.fromEntries(vrmBones.map((bone) => [bone, { node: nodeOf(bone) }])) } };
  let text = JSON.stringify(json);
  while (text.length % 4) text += ' ';
  const jsonBytes = new TextEncoder().encode(text);
  const bin = glb.subarray(20 + jsonLength);
  const out = new Uint8Array(20 + jsonBytes.length + bin.length);
  const o = new DataView(out.buffer);
  o.setUint32(0, 0x46546c67, true);
  o.setUint32(4, 2, true);
  o.setUint32(8, out.length, true);
  o.setUint32(12, jsonBytes.length, true);
  o.setUint32(16, 0x4e4f534a, true); // JSON
  out.set(jsonBytes, 20);
  out.set(bin, 20 + jsonBytes.length);
  return out;
}

/**
 * Reads a GLB back with three.js's GLTFLoader and plays its first animation: each named node's world position at
 * every frame (`fps`), { name: Float32Array(frames × 3) }, and what the file holds (skinned meshes, bones, clips).
 */
export async function playBack(bytes, fps, frames, names) {
  const gltf = await new GLTFLoader().parseAsync(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength), '');
  const skinned = [];
  gltf.scene.traverse((o) => o.isSkinnedMesh && skinned.push(o));
  const mixer = new THREE.AnimationMixer(gltf.scene);
  const clip = gltf.animations[0];
  mixer.clipAction(clip).play();
  const nodes = names.map((n) => gltf.scene.getObjectByName(THREE.PropertyBinding.sanitizeNodeName(n)));
  const out = names.map(() => new Float32Array(frames * 3));
  const p = new THREE.Vector3();
  for (let f = 0; f < frames; f++) {
    mixer.setTime(f / fps);
    gltf.scene.updateMatrixWorld(true);
    nodes.forEach((node, k) => node && p.setFromMatrixPosition(node.matrixWorld).toArray(out[k], f * 3));
  }
  return {
    skinnedMeshes: skinned.length,
    bones: skinned[0]?.skeleton.bones.length ?? 0,
    clips: gltf.animations.length,
    tracks: clip?.tracks.length ?? 0,
    found: nodes.map((n) => !!n),
    positions: out,
  };
}

/** The name a node of `name` has after three.js's GLTFLoader (and so in a GLB three.js writes back). */
export function threeNodeName(name) {
  return THREE.PropertyBinding.sanitizeNodeName(name);
}
