// The animated character as one binary glTF (issue 40): the user's mesh, skin and materials as the file gave them,
// and one animation of the motion retargeted onto its rig (each bone's rotation, the root bone's translation, one
// key per frame at frame / fps, LINEAR), written by three.js's GLTFExporter. The scene sits in a node scaled to
// metres (userCharacter.ts), so a reader's bone heads are where the page draws them.

import * as THREE from 'three';
import { GLTFExporter } from 'three/examples/jsm/exporters/GLTFExporter.js';
import type { RetargetResult } from '../motion/retarget';
import { UserCharacterDriver, type CharacterAsset } from './userCharacter';

/** GLB bytes of `asset` animated by `result` (a retargeting onto its rig) at `fps`; `name` names the scene and animation. */
export async function exportCharacterGLB(asset: CharacterAsset, result: RetargetResult, fps: number, name: string): Promise<Uint8Array<ArrayBuffer>> {
  const copy = new UserCharacterDriver(asset);
  try {
    copy.setResult(result);
    const bones = copy.rigBones;
    const B = bones.length;
    const frames = result.motion.frames;
    const times = new Float32Array(frames);
    const rotations = bones.map(() => new Float32Array(frames * 4));
    const rootPositions = new Float32Array(frames * 3);
    const rootBone = bones[result.rootBone ?? 0]; // the root the hips hang from (retarget.ts)
    for (let f = 0; f < frames; f++) {
      times[f] = f / fps;
      copy.update(f, f, 0);
      for (let k = 0; k < B; k++) bones[k].quaternion.toArray(rotations[k], f * 4);
      rootBone.position.toArray(rootPositions, f * 3);
    }
    copy.rest(); // the nodes' own transforms in the file are the rest pose the skin was bound in
    // Tracks name their bones by uuid: bone names need not be unique in three.js (GLTFLoader cleans them).
    const tracks: THREE.KeyframeTrack[] = bones.map((bone, k) => new THREE.QuaternionKeyframeTrack(`${bone.uuid}.quaternion`, times, rotations[k]));
    tracks.push(new THREE.VectorKeyframeTrack(`${rootBone.uuid}.position`, times, rootPositions));
    const clip = new THREE.AnimationClip(name, frames > 1 ? (frames - 1) / fps : 0, tracks);
    const root = copy.mannequin.mesh;
    root.name = name;
    root.updateMatrixWorld(true);
    const glb = await new GLTFExporter().parseAsync(root, { binary: true, animations: [clip], onlyVisible: false });
    return new Uint8Array(glb as ArrayBuffer);
  } finally {
    copy.dispose();
  }
}
