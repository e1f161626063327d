// exportGLB (web/motion/gltf.ts) read back by three.js's GLTFLoader: the file parses, holds a SkinnedMesh over a
// skin of every joint node, and the animation played with AnimationMixer puts every joint node where the motion
// has that joint, within 1 mm, on every frame checked. Clips: CMU BVH 07_04 (all 450 frames), CMU ASF/AMC 16_11
// (its first 300 frames), acLSTM salsa 01 (300 frames from frame 600: the file is minutes long at 60 fps), each
// with both rest poses; and the CMU clip with a joint renamed to markup and reserved characters.
import { describe, expect, it } from 'vitest';
import * as THREE from 'three';
import { GLTFLoader, type GLTF } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { exportGLB, gltfJointNames } from '../../web/motion/gltf';
import { parseBVH } from '../../web/motion/bvh';
import { parseAMC } from '../../web/motion/asfamc';
import type { RestPose } from '../../web/motion/restPose';
import type { Motion } from '../../web/motion/types';
import { readCorpus } from './corpus';

const TOLERANCE_M = 0.001;

/** Frames [start, start + count) of a motion, as a motion of their own. */
function frameRange(m: Motion, start: number, count: number): Motion {
  const n = Math.min(count, m.frames - start);
  const J = m.joints.length;
  return { ...m, frames: n, positions: m.positions.slice(start * J * 3, (start + n) * J * 3), contacts: undefined };
}

/** GLTFLoader.parse as a promise. Node has everything it needs for a GLB without textures (TextDecoder, no DOM). */
function loadGLB(bytes: Uint8Array): Promise<GLTF> {
  const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength) as ArrayBuffer;
  return new Promise((resolve, reject) => new GLTFLoader().parse(buffer, '', resolve, reject));
}

interface Replay {
  gltf: GLTF;
  skinned: THREE.SkinnedMesh[];
  /** Per joint of the motion, the scene's node for it. */
  jointNodes: THREE.Object3D[];
  maxErrorM: number;
  worst: { frame: number; joint: string };
}

/** Exports, re-imports and plays the motion; measures each joint node's world position against the motion. */
async function replay(m: Motion, restPose: RestPose): Promise<Replay> {
  const gltf = await loadGLB(exportGLB(m, { restPose, name: 'clip' }));
  const scene = gltf.scene;
  const skinned: THREE.SkinnedMesh[] = [];
  scene.traverse((o) => {
    if ((o as THREE.SkinnedMesh).isSkinnedMesh) skinned.push(o as THREE.SkinnedMesh);
  });
  // GLTFLoader names nodes PropertyBinding.sanitizeNodeName(name) (its animation tracks address them so).
  const names = gltfJointNames(m.joints).map((n) => THREE.PropertyBinding.sanitizeNodeName(n));
  const jointNodes = names.map((n) => {
    const node = scene.getObjectByName(n);
    if (!node) throw new Error(`no node named ${n} in the loaded scene`);
    return node;
  });
  const mixer = new THREE.AnimationMixer(scene);
  const action = mixer.clipAction(gltf.animations[0]);
  action.setLoop(THREE.LoopOnce, 1);
  action.clampWhenFinished = true; // the last frame is at the clip's duration: hold it, do not wrap to frame 0
  action.play();
  const J = m.joints.length;
  const at = new THREE.Vector3();
  let maxErrorM = 0;
  let worst = { frame: -1, joint: '' };
  for (let f = 0; f < m.frames; f++) {
    mixer.setTime(f / m.fps);
    scene.updateMatrixWorld(true);
    for (let j = 0; j < J; j++) {
      jointNodes[j].getWorldPosition(at);
      const b = (f * J + j) * 3;
      const e = Math.hypot(at.x - m.positions[b], at.y - m.positions[b + 1], at.z - m.positions[b + 2]);
      if (e > maxErrorM) {
        maxErrorM = e;
        worst = { frame: f, joint: m.joints[j] };
      }
    }
  }
  return { gltf, skinned, jointNodes, maxErrorM, worst };
}

const CLIPS: Array<{ name: string; motion: () => Motion }> = [
  { name: 'CMU BVH 07_04', motion: () => parseBVH(readCorpus('cmu/bvh/07_04.bvh.gz')) },
  { name: 'CMU ASF/AMC 16_11 (first 300 frames)', motion: () => frameRange(parseAMC(readCorpus('cmu/amc/16_11.amc.gz'), readCorpus('cmu/asf/16.asf')), 0, 300) },
  { name: 'acLSTM salsa 01 (frames 600–899)', motion: () => frameRange(parseBVH(readCorpus('aclstm/salsa/01.bvh.gz')), 600, 300) },
];

describe.each(CLIPS)('exportGLB → GLTFLoader: $name', ({ motion }) => {
  const m = motion();

  it.each(['tpose', 'clip'] as const)('restPose %s: a SkinnedMesh over every joint node; each joint within 1 mm on every frame', async (restPose) => {
    const r = await replay(m, restPose);
    expect(r.skinned).toHaveLength(1);
    const skin = r.skinned[0].skeleton;
    expect(r.gltf.parser.json.skins).toHaveLength(1);
    for (const node of r.jointNodes) {
      expect((node as THREE.Bone).isBone).toBe(true);
      expect(skin.bones).toContain(node);
    }
    const boneNames = skin.bones.map((b) => b.name);
    expect(new Set(boneNames).size).toBe(boneNames.length);
    expect(r.gltf.animations).toHaveLength(1);
    expect(r.gltf.animations[0].duration).toBeCloseTo((m.frames - 1) / m.fps, 5);
    expect(r.maxErrorM, `worst at frame ${r.worst.frame}, joint ${r.worst.joint}`).toBeLessThan(TOLERANCE_M);
  });
});

describe('exportGLB joint names', () => {
  const cmu = parseBVH(readCorpus('cmu/bvh/07_04.bvh.gz'));
  const odd = '<b>x</b>.y:z';
  const renamed = (j: number): Motion => {
    const m = frameRange(cmu, 0, 60);
    return { ...m, joints: m.joints.map((n, k) => (k === j ? odd : n)) };
  };

  it('a joint named with markup and reserved characters keeps a node of its own that GLTFLoader accepts and animates', async () => {
    for (const j of [cmu.joints.indexOf('LeftToeBase'), cmu.joints.indexOf('LeftHandIndex1'), 0]) {
      const m = renamed(j);
      const names = gltfJointNames(m.joints);
      expect(names[j]).toBe('<b>x<_b>_y_z');
      expect(THREE.PropertyBinding.sanitizeNodeName(names[j])).toBe(names[j]); // nothing left for the loader to strip
      const r = await replay(m, 'tpose');
      expect(r.jointNodes[j].name).toBe(names[j]);
      expect(r.maxErrorM).toBeLessThan(TOLERANCE_M);
    }
  });

  it('names stay unique when cleaning makes two alike', async () => {
    const m = frameRange(cmu, 0, 30);
    const joints = m.joints.slice();
    joints[1] = 'a b';
    joints[2] = 'a.b';
    joints[3] = 'a_b';
    const names = gltfJointNames(joints);
    expect(names.slice(1, 4)).toEqual(['a_b_2', 'a_b_3', 'a_b']);
    expect(new Set(names).size).toBe(names.length);
    const r = await replay({ ...m, joints }, 'clip');
    const all = r.skinned[0].skeleton.bones.map((b) => b.name);
    expect(new Set(all).size).toBe(all.length);
    expect(r.maxErrorM).toBeLessThan(TOLERANCE_M);
  });
});
