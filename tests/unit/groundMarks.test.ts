// The ground marks (web/viewer/ground.ts GroundMarks: trail, footprints, blob shadow) cost the same per
// frame however long the clip: what is drawn is what the camera can see, and playing uploads only the
// colours that changed. Checked on synthetic walks with no renderer: the update ranges stand for what
// three.js would upload, the index's draw range for what it would draw.
import * as THREE from 'three';
import { describe, expect, it } from 'vitest';
import { CHUNK_ITEMS, GroundMarks, MAX_DRAWN_CHUNKS } from '../../web/viewer/ground';
import type { Motion } from '../../web/motion/types';

const FPS = 30;
const JOINTS = ['Hips', 'LeftFoot', 'LeftToeBase', 'RightFoot', 'RightToeBase'];
const PARENTS = [-1, 0, 1, 0, 3];
const FAR = 14; // the viewer's fog far distance at default quality

/**
 * A walk along +x at `speed` m/s (0: stepping in place): each foot is planted for 15 frames and then
 * the other, so a footprint every half second; contacts given, frames × (left, right).
 */
function walk(frames: number, speed = 1.2): { motion: Motion; contacts: Uint8Array } {
  const J = JOINTS.length;
  const positions = new Float32Array(frames * J * 3);
  const contacts = new Uint8Array(frames * 2);
  for (let f = 0; f < frames; f++) {
    const x = (f / FPS) * speed, o = f * J * 3;
    positions.set([x, 0.95, 0], o);
    const left = Math.floor(f / 15) % 2 === 0;
    const put = (ankle: number, z: number, planted: boolean) => {
      const y = planted ? 0.08 : 0.2;
      positions.set([x, y, z], o + ankle * 3);
      positions.set([x + 0.15, y - 0.05, z], o + (ankle + 1) * 3);
    };
    put(1, 0.1, left);
    put(3, -0.1, !left);
    contacts[f * 2] = left ? 1 : 0;
    contacts[f * 2 + 1] = left ? 0 : 1;
  }
  return { motion: { fps: FPS, frames, joints: JOINTS, parents: PARENTS, positions }, contacts };
}

function built(frames: number, speed?: number): GroundMarks {
  const { motion, contacts } = walk(frames, speed);
  const marks = new GroundMarks();
  marks.build(motion, contacts, 0);
  return marks;
}

/**
 * A view of the root at `frame` of walk(…, speed) as the viewer's camera has it: from the side (the
 * default three-quarter view, the walk crossing the screen), or from behind, the walk ahead running into
 * the fog.
 */
function cameraAt(frame: number, speed = 1.2, from: 'side' | 'behind' = 'side'): THREE.PerspectiveCamera {
  const camera = new THREE.PerspectiveCamera(38, 16 / 9, 0.1, 200);
  const x = (frame / FPS) * speed;
  if (from === 'side') camera.position.set(x + 3.2, 1.9, 4.6);
  else camera.position.set(x - 4, 1.5, 0.5);
  camera.lookAt(x, 0.9, 0);
  camera.updateMatrixWorld();
  return camera;
}

const VIEWS = [
  { frame: 0, from: 'side' },
  { frame: 300, from: 'side' },
  { frame: 700, from: 'side' },
  { frame: 0, from: 'behind' },
  { frame: 300, from: 'behind' },
] as const;

function showFrame(marks: GroundMarks, frame: number, camera = cameraAt(frame), far = FAR): void {
  marks.setProgress(frame, frame);
  marks.drawFor(camera, far);
}

/** The triangles three.js would draw, each as its vertex indices (a short clip's and a long one's differ). */
function drawnIndices(marks: GroundMarks): number[][] {
  const g = marks.mesh.geometry, index = g.index!.array;
  const end = Math.min(g.drawRange.start + g.drawRange.count, g.index!.count);
  const out: number[][] = [];
  for (let i = g.drawRange.start; i + 2 < end; i += 3) out.push([index[i], index[i + 1], index[i + 2]]);
  return out;
}

/** The triangles three.js would draw, each as its corners' positions (mm) and colours, e.g. "1200,3,-14,…". */
function drawnTriangles(marks: GroundMarks): string[] {
  const pos = marks.mesh.geometry.getAttribute('position'), col = marks.mesh.geometry.getAttribute('color');
  const corner = (v: number) => [pos.getX(v), pos.getY(v), pos.getZ(v)].map((x) => Math.round(x * 1000)).concat([col.getX(v), col.getY(v), col.getZ(v), col.getW(v)]);
  return drawnIndices(marks).map((t) => t.flatMap(corner).join(','));
}

const SHADOW_TRIANGLES = 24 + 3 * 2 * 24; // the blob shadow's disc: 4 rings of 24 segments

describe('GroundMarks', () => {
  it('draws the same triangles for a 100,000-frame clip as for its first 1,000 frames', () => {
    const short = built(1_000), long = built(100_000);
    for (const { frame, from } of VIEWS) {
      showFrame(short, frame, cameraAt(frame, 1.2, from));
      showFrame(long, frame, cameraAt(frame, 1.2, from));
      const drawn = drawnTriangles(long);
      expect(drawn).toEqual(drawnTriangles(short));
      expect(drawn.length).toBeGreaterThan(SHADOW_TRIANGLES + 100); // trail and footprints around the figure
    }
  });

  it('leaves out no mark the camera can see', () => {
    // The whole 1,000-frame walk from high above with no distance limit is every triangle there is.
    const marks = built(1_000);
    const above = new THREE.PerspectiveCamera(60, 1, 0.1, 1000);
    above.position.set(20, 60, 0.01);
    above.lookAt(20, 0, 0);
    showFrame(marks, 300, above, Infinity);
    const all = drawnIndices(marks);
    expect(all.length).toBeGreaterThan(1000);
    const pos = marks.mesh.geometry.getAttribute('position');
    for (const { frame, from } of [...VIEWS, { frame: 999, from: 'side' } as const]) {
      const camera = cameraAt(frame, 1.2, from);
      showFrame(marks, frame, camera);
      const drawn = new Set(drawnIndices(marks).map((t) => t.join()));
      const p = new THREE.Vector3(), view = new THREE.Vector3();
      const seen = (v: number) => {
        p.fromBufferAttribute(pos, v);
        const depth = -view.copy(p).applyMatrix4(camera.matrixWorldInverse).z;
        p.project(camera);
        return depth > camera.near && depth < FAR && Math.abs(p.x) <= 1 && Math.abs(p.y) <= 1;
      };
      let visible = 0;
      for (const t of all) {
        if (!t.some(seen)) continue;
        visible++;
        expect(drawn.has(t.join()), `triangle ${t} is in view at frame ${frame} from the ${from} but not drawn`).toBe(true);
      }
      expect(visible).toBeGreaterThan(100);
    }
  });

  it('draws a bounded number of marks for a clip that stays in one place', () => {
    const bound = SHADOW_TRIANGLES + (MAX_DRAWN_CHUNKS * CHUNK_ITEMS * (2 + 22));
    const a = built(100_000, 0), b = built(200_000, 0);
    showFrame(a, 50_000, cameraAt(0, 0));
    showFrame(b, 50_000, cameraAt(0, 0));
    expect(drawnTriangles(a).length).toBeLessThanOrEqual(bound);
    expect(drawnTriangles(b)).toEqual(drawnTriangles(a));
  });

  it('uploads no more colour while playing a 100,000-frame clip than a 1,000-frame one', () => {
    /** Colour values three.js would upload while playing frames 1…900, one display frame per clip frame. */
    const uploadedWhilePlaying = (marks: GroundMarks) => {
      const color = marks.mesh.geometry.getAttribute('color') as THREE.BufferAttribute;
      let version = color.version, uploaded = 0;
      color.clearUpdateRanges(); // the first render uploads the new buffer whole
      for (let f = 1; f <= 900; f++) {
        marks.setProgress(f, f);
        if (color.version === version) continue;
        version = color.version;
        uploaded += color.updateRanges.length ? color.updateRanges.reduce((a, r) => a + r.count, 0) : color.array.length;
        color.clearUpdateRanges(); // as three.js does after uploading
      }
      return uploaded;
    };
    const short = uploadedWhilePlaying(built(1_000));
    expect(short).toBeGreaterThan(0);
    expect(uploadedWhilePlaying(built(100_000))).toBe(short);
  });

  it('colours the marks after a jump back the same as when shown there directly', () => {
    const played = built(3_000), direct = built(3_000);
    for (let f = 0; f <= 2_500; f += 7) played.setProgress(f, f);
    played.setProgress(100.5, 100);
    direct.setProgress(100.5, 100);
    expect(played.mesh.geometry.getAttribute('color').array).toEqual(direct.mesh.geometry.getAttribute('color').array);
  });

  it('draws only the layers turned on', () => {
    const marks = built(1_000);
    showFrame(marks, 300);
    const both = drawnTriangles(marks).length;
    marks.setLayers({ trail: false });
    showFrame(marks, 300);
    const prints = drawnTriangles(marks).length;
    marks.setLayers({ trail: true, footprints: false });
    showFrame(marks, 300);
    const trail = drawnTriangles(marks).length;
    marks.setLayers({ trail: false });
    showFrame(marks, 300);
    expect(drawnTriangles(marks).length).toBe(SHADOW_TRIANGLES);
    expect(prints).toBeGreaterThan(SHADOW_TRIANGLES);
    expect(trail).toBeGreaterThan(SHADOW_TRIANGLES);
    expect(both - SHADOW_TRIANGLES).toBe(prints - SHADOW_TRIANGLES + (trail - SHADOW_TRIANGLES));
  });
});
