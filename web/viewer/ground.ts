// Things drawn on the ground plane (x–z): the floor with its grid, a soft blob shadow under the
// figure, the root trajectory as a flat ribbon, and footprints at each foot-contact onset.

import * as THREE from 'three';
import { PALETTE } from './palette';
import type { Motion } from '../motion/types';
import { COLORS } from './figure';
import { findFootJoints } from '../motion/contacts';

export const BACKGROUND = PALETTE.background;
export const FLOOR_COLOR = PALETTE.floor;

/**
 * The floor: an opaque plane a shade lighter than the background plus a 1 m line grid (brighter every
 * 5 m). Both use the scene fog, which fades them into the background with distance. Deliberately
 * cheap per pixel: software GL (headless Chromium) spends most of its time filling the floor.
 */
export class Floor {
  readonly group = new THREE.Group();
  private readonly grid: THREE.LineSegments;

  constructor(private readonly half = 12) {
    const minor = PALETTE.gridMinor, major = PALETTE.gridMajor;
    const pos: number[] = [], col: number[] = [];
    // Lines are cut into 4 m pieces: software GL drops long lines that cross the camera's near plane
    // (and every piece costs, so not shorter).
    for (let i = -half; i <= half; i++) {
      const c = i % 5 === 0 ? major : minor;
      for (let k = -half; k < half; k += 4) {
        pos.push(i, 0, k, i, 0, k + 4, k, 0, i, k + 4, 0, i);
        for (let v = 0; v < 4; v++) col.push(c.r, c.g, c.b);
      }
    }
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
    geo.setAttribute('color', new THREE.Float32BufferAttribute(col, 3));
    this.grid = new THREE.LineSegments(geo, new THREE.LineBasicMaterial({ vertexColors: true }));
    this.grid.position.y = 0.001;
    this.grid.renderOrder = -1;
    this.group.add(this.grid);
  }

  /** Keeps the floor around a ground point; the grid moves in whole 5 m steps so its lines stay put. */
  setCenter(x: number, z: number): void {
    const gx = Math.round(x / 5) * 5, gz = Math.round(z / 5) * 5;
    this.group.position.set(gx, 0, gz);
  }
}

/**
 * A soft pool of light on the floor around the figure: an opaque disc whose vertex colours fall off
 * to exactly the background colour at its rim, so it needs no blending and has no visible edge.
 */
export class FloorGlow {
  readonly mesh: THREE.Mesh;

  constructor(radius = 4, rings = 4, segments = 32) {
    const pos: number[] = [0, 0, 0];
    const col: number[] = [];
    const c = new THREE.Color();
    const colorAt = (t: number) => c.copy(BACKGROUND).lerp(FLOOR_COLOR, 1 - t * t * (3 - 2 * t));
    colorAt(0).toArray(col, 0);
    for (let k = 1; k <= rings; k++) {
      const t = k / rings;
      colorAt(t);
      for (let i = 0; i < segments; i++) {
        const a = (i / segments) * Math.PI * 2;
        pos.push(Math.cos(a) * radius * t, 0, Math.sin(a) * radius * t);
        col.push(c.r, c.g, c.b);
      }
    }
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
    geo.setAttribute('color', new THREE.Float32BufferAttribute(col, 3));
    geo.setIndex(discIndex(rings, segments));
    this.mesh = new THREE.Mesh(geo, new THREE.MeshBasicMaterial({ vertexColors: true, depthWrite: false, fog: false }));
    this.mesh.renderOrder = -2; // drawn first and without depth, so nothing on the ground z-fights with it
  }

  setCenter(x: number, z: number): void {
    this.mesh.position.set(x, 0, z);

  }
}

/** A stylised sole (forefoot pad and heel pad) in white on transparent, pointing up the texture. */
function soleTexture(): THREE.Texture {
  const c = document.createElement('canvas');
  c.width = 64;
  c.height = 144;
  const g = c.getContext('2d')!;
  g.fillStyle = '#fff';
  g.beginPath();
  g.ellipse(32, 46, 24, 40, 0, 0, Math.PI * 2); // forefoot (top of the texture = toes)
  g.fill();
  g.beginPath();
  g.ellipse(33, 116, 18, 23, 0, 0, Math.PI * 2); // heel
  g.fill();
  const t = new THREE.CanvasTexture(c);
  // Bilinear, no mipmaps: the marks are small, and mipmapped sampling is costly under software GL.
  t.generateMipmaps = false;
  t.minFilter = THREE.LinearFilter;
  return t;
}

/**
 * A soft dark disc under the figure (cheaper than real shadows under software GL): darkness falls off
 * through per-vertex alpha, so no texture is sampled.
 */
export class BlobShadow {
  readonly mesh: THREE.Mesh;
  constructor(rings = 4, segments = 24) {
    const pos: number[] = [0, 0, 0];
    const col: number[] = [0, 0, 0, 0.5];
    for (let k = 1; k <= rings; k++) {
      const t = k / rings;
      const alpha = 0.5 * (1 - t) * (1 - t);
      for (let i = 0; i < segments; i++) {
        const a = (i / segments) * Math.PI * 2;
        pos.push(Math.cos(a) * 0.5 * t, 0, Math.sin(a) * 0.5 * t);
        col.push(0, 0, 0, alpha);
      }
    }
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
    geo.setAttribute('color', new THREE.Float32BufferAttribute(col, 4));
    geo.setIndex(discIndex(rings, segments));
    const mat = new THREE.MeshBasicMaterial({ vertexColors: true, transparent: true, depthWrite: false });
    this.mesh = new THREE.Mesh(geo, mat);
    this.mesh.position.y = 0.004;
    this.mesh.renderOrder = 3;
  }
  update(x: number, z: number, size: number): void {
    this.mesh.position.x = x;
    this.mesh.position.z = z;
    this.mesh.scale.setScalar(size);
  }
}

/** Triangle indices of a disc: a centre vertex, then `rings` rings of `segments` vertices. */
function discIndex(rings: number, segments: number): number[] {
  const index: number[] = [];
  for (let i = 0; i < segments; i++) index.push(0, 1 + ((i + 1) % segments), 1 + i);
  for (let k = 1; k < rings; k++) {
    const a0 = 1 + (k - 1) * segments, b0 = 1 + k * segments;
    for (let i = 0; i < segments; i++) {
      const i1 = (i + 1) % segments;
      index.push(a0 + i, a0 + i1, b0 + i, a0 + i1, b0 + i1, b0 + i);
    }
  }
  return index;
}

const TRAIL_WIDTH = 0.028;

/** The root's ground track as a flat ribbon: faint for the whole clip, bright up to the current frame. */
export class Trail {
  readonly group = new THREE.Group();
  private readonly full: THREE.Mesh;
  private readonly done: THREE.Mesh;
  private step = 1;
  private segments = 0;

  constructor() {
    const color = PALETTE.trail;
    const mk = (opacity: number, order: number) => {
      const m = new THREE.Mesh(
        new THREE.BufferGeometry(),
        new THREE.MeshBasicMaterial({ color, transparent: true, opacity, depthWrite: false, side: THREE.DoubleSide }),
      );
      m.renderOrder = order;
      m.frustumCulled = false;
      this.group.add(m);
      return m;
    };
    this.full = mk(0.28, 1);
    this.done = mk(0.95, 2);
  }

  build(motion: Motion, root = 0): void {
    const { frames, positions } = motion;
    const J = motion.joints.length;
    this.step = Math.max(1, Math.round(motion.fps / 15)); // ~15 samples a second: smooth enough, few triangles
    const idx: number[] = [];
    for (let f = 0; f < frames; f += this.step) idx.push(f);
    if (idx[idx.length - 1] !== frames - 1) idx.push(frames - 1);
    const n = idx.length;
    const verts = new Float32Array(n * 2 * 3);
    let nx = 1, nz = 0; // last good normal
    for (let i = 0; i < n; i++) {
      const f = idx[i];
      const o = (f * J + root) * 3;
      const x = positions[o], z = positions[o + 2];
      const fa = idx[Math.max(i - 1, 0)], fb = idx[Math.min(i + 1, n - 1)];
      const tx = positions[(fb * J + root) * 3] - positions[(fa * J + root) * 3];
      const tz = positions[(fb * J + root) * 3 + 2] - positions[(fa * J + root) * 3 + 2];
      const tl = Math.hypot(tx, tz);
      if (tl > 1e-5) { nx = -tz / tl; nz = tx / tl; }
      const h = TRAIL_WIDTH / 2;
      verts.set([x + nx * h, 0.003, z + nz * h, x - nx * h, 0.003, z - nz * h], i * 6);
    }
    const index: number[] = [];
    for (let i = 0; i < n - 1; i++) {
      const a = 2 * i;
      index.push(a, a + 1, a + 2, a + 1, a + 3, a + 2);
    }
    const attr = new THREE.BufferAttribute(verts, 3);
    const indexAttr = new THREE.Uint32BufferAttribute(index, 1);
    for (const m of [this.full, this.done]) {
      m.geometry.dispose();
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', attr);
      g.setIndex(indexAttr);
      m.geometry = g;
    }
    this.segments = n - 1;
    this.setProgress(0);
  }

  setProgress(frameFloat: number): void {
    const k = Math.min(Math.floor(frameFloat / this.step), this.segments);
    this.done.geometry.setDrawRange(0, k * 6);
  }
}

/** Footprints: a flat sole mark at the foot joint's x–z at each contact onset; left and right coloured apart. */
export class Footprints {
  readonly group = new THREE.Group();
  private mesh: THREE.InstancedMesh | null = null;
  private onsets: { frame: number; side: 0 | 1 }[] = [];
  private shown = -1;
  private readonly past = [COLORS.left.clone(), COLORS.right.clone()];
  private readonly future = [
    COLORS.left.clone().lerp(FLOOR_COLOR, 0.72),
    COLORS.right.clone().lerp(FLOOR_COLOR, 0.72),
  ];
  private readonly geometry: THREE.PlaneGeometry;
  private readonly material = new THREE.MeshBasicMaterial({ map: soleTexture(), transparent: true, opacity: 0.92, depthWrite: false });

  constructor() {
    // One textured quad per footprint (two triangles), 25 cm long, +y forward before laying it flat.
    this.geometry = new THREE.PlaneGeometry(0.11, 0.25);
    this.geometry.rotateX(-Math.PI / 2); // +y → world −z; instances rotate it to face the foot
  }

  /** Number of footprints placed for the current motion. */
  get count(): number {
    return this.onsets.length;
  }

  build(motion: Motion, contacts: Uint8Array | undefined): void {
    if (this.mesh) {
      this.group.remove(this.mesh);
      this.mesh.dispose();
      this.mesh = null;
    }
    this.onsets = [];
    this.shown = -1;
    if (!contacts || contacts.length < motion.frames * 2) return;
    const J = motion.joints.length;
    const feet = [findFootJoints(motion.joints, 'left'), findFootJoints(motion.joints, 'right')];
    const P = motion.positions;
    const items: { frame: number; side: 0 | 1; x: number; z: number; dx: number; dz: number }[] = [];
    for (const side of [0, 1] as const) {
      const ft = feet[side];
      if (!ft) continue;
      const foot = ft.ankle, toe = ft.toe;
      for (let f = 0; f < motion.frames; f++) {
        if (!contacts[f * 2 + side] || (f > 0 && contacts[(f - 1) * 2 + side])) continue;
        const o = (f * J + foot) * 3;
        let dx = 0, dz = 1;
        if (toe >= 0) {
          const t = (f * J + toe) * 3;
          const l = Math.hypot(P[t] - P[o], P[t + 2] - P[o + 2]);
          if (l > 1e-4) { dx = (P[t] - P[o]) / l; dz = (P[t + 2] - P[o + 2]) / l; }
        }
        // Centre the sole a little ahead of the ankle so the heel lands under it.
        items.push({ frame: f, side, x: P[o] + 0.05 * dx, z: P[o + 2] + 0.05 * dz, dx, dz });
      }
    }
    items.sort((a, b) => a.frame - b.frame);
    if (items.length === 0) return;
    const mesh = new THREE.InstancedMesh(this.geometry, this.material, items.length);
    const m = new THREE.Matrix4();
    items.forEach((it, i) => {
      m.makeRotationY(Math.atan2(-it.dx, -it.dz));
      m.setPosition(it.x, 0.005, it.z);
      mesh.setMatrixAt(i, m);
      mesh.setColorAt(i, this.future[it.side]);
    });
    mesh.renderOrder = 2;
    mesh.frustumCulled = false;
    this.mesh = mesh;
    this.onsets = items.map(({ frame, side }) => ({ frame, side }));
    this.group.add(mesh);
    this.setProgress(0);
  }

  /** Footprints up to the current frame are drawn in full colour, later ones faded. */
  setProgress(frame: number): void {
    if (!this.mesh) return;
    let n = 0;
    while (n < this.onsets.length && this.onsets[n].frame <= frame) n++;
    if (n === this.shown) return;
    this.onsets.forEach((o, i) => this.mesh!.setColorAt(i, i < n ? this.past[o.side] : this.future[o.side]));
    this.mesh.instanceColor!.needsUpdate = true;
    this.shown = n;
  }
}
