// Issue 43 #11: joints named like Object.prototype's properties (__proto__, constructor, toString, …) are exported to
// glTF under node names three.js's GLTFLoader keeps (its createUniqueName counts names in a plain object, so those
// came back as "constructor_NaN"), with the original name in the node's extras; loaded with GLTFLoader in Node,
// every joint's animation tracks bind to the node of that joint.
import { describe, expect, it } from 'vitest';
import { AnimationMixer, PropertyBinding, type Object3D } from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { exportGLB, gltfJointNames } from '../../web/motion/gltf';
import type { Motion } from '../../web/motion/types';

const JOINTS = ['Hips', '__proto__', 'constructor', 'toString', 'hasOwnProperty', 'valueOf', 'Head', 'constructor_2'];
const PARENTS = [-1, 0, 1, 2, 0, 4, 2, 0];

function motion(): Motion {
  const frames = 3, J = JOINTS.length;
  const positions = new Float32Array(frames * J * 3);
  const rest: [number, number, number][] = [[0, 1, 0], [0, 1.2, 0], [0, 1.4, 0], [0.1, 1.6, 0], [0.2, 0.5, 0], [0.2, 0.05, 0.1], [-0.1, 1.6, 0], [-0.2, 0.5, 0]];
  for (let f = 0; f < frames; f++) for (let j = 0; j < J; j++) positions.set([rest[j][0] + 0.01 * f * (j % 3), rest[j][1], rest[j][2] + 0.1 * f], (f * J + j) * 3);
  return { fps: 30, frames, joints: JOINTS, parents: PARENTS, positions };
}

function load(glb: Uint8Array): Promise<{ scene: Object3D; animations: import('three').AnimationClip[] }> {
  const buffer = glb.buffer.slice(glb.byteOffset, glb.byteOffset + glb.byteLength) as ArrayBuffer;
  return new Promise((resolve, reject) => new GLTFLoader().parse(buffer, '', (g) => resolve(g as never), reject));
}

describe('glTF joint names GLTFLoader binds', () => {
  it('every joint, __proto__ and constructor included, is found by its node name and its tracks bind to it', async () => {
    const names = gltfJointNames(JOINTS);
    const { scene, animations } = await load(exportGLB(motion(), { restPose: 'clip' }));
    const [clip] = animations;
    for (let j = 0; j < JOINTS.length; j++) {
      const node = scene.getObjectByName(names[j]);
      expect(node, `joint ${JOINTS[j]} as node ${names[j]}`).toBeDefined();
      // The original name travels in the node's extras where the node name differs.
      if (names[j] !== JOINTS[j]) expect(node!.userData.name).toBe(JOINTS[j]);
      const tracks = clip.tracks.filter((t) => PropertyBinding.parseTrackName(t.name).nodeName === names[j]);
      expect(tracks.length, `tracks of ${JOINTS[j]}`).toBeGreaterThan(0);
      for (const t of tracks) expect(PropertyBinding.findNode(scene, PropertyBinding.parseTrackName(t.name).nodeName)).toBe(node);
    }
    // Every track of the clip binds (a mixer finds its node) and moves it.
    const mixer = new AnimationMixer(scene);
    mixer.clipAction(clip).play();
    mixer.setTime(1 / 30);
    for (const t of clip.tracks) {
      const binding = new PropertyBinding(scene, t.name);
      binding.bind();
      expect(binding.node, t.name).toBeDefined();
    }
  });

  it('names stay unique and safe: no name Object.prototype has, no clash with a joint named like the renamed one', () => {
    const names = gltfJointNames(JOINTS);
    expect(new Set(names).size).toBe(JOINTS.length);
    for (const n of names) expect(n in Object.prototype).toBe(false);
    expect(names[0]).toBe('Hips');
    expect(names[6]).toBe('Head');
  });
});
