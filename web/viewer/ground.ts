// Things drawn on the ground plane (x–z): the grid, a glow on the floor around the figure (GPU tier
// only), and in one mesh the blob shadow, the root trajectory ribbon and the footprints.

import * as THREE from 'three';
import { PALETTE } from './palette';
import type { Motion } from '../motion/types';
import { findFootJoints } from '../motion/contacts';

export const BACKGROUND = PALETTE.background;
export const FLOOR_COLOR = PALETTE.floor;

/**
 * The floor grid: 1 m lines, brighter every 5 m, faded into the background by the scene fog. There is
 * no filled floor plane: under software GL (headless Chromium) every filled pixel costs, so the floor
 * is the background colour itself, lit around the figure by FloorGlow when a GPU can afford it.
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
const SHADOW_RINGS = 4;
const SHADOW_SEGMENTS = 24;

/** One flat sole mark, +y forward: a forefoot pad and a heel pad (x lateral, y forward, metres). */
const SOLE_PADS: ReadonlyArray<{ cx: number; cy: number; rx: number; ry: number; n: number }> = [
  { cx: 0, cy: 0.045, rx: 0.042, ry: 0.068, n: 12 },
  { cx: 0.004, cy: -0.078, rx: 0.032, ry: 0.04, n: 10 },
];
const SOLE_VERTS = SOLE_PADS.reduce((a, p) => a + p.n + 1, 0);

interface Footprint {
  frame: number;
  side: 0 | 1;
}

/**
 * Everything drawn flat on the ground for the shown motion, in ONE mesh and draw call (software GL
 * pays a fixed price per draw): a soft blob shadow under the figure, the root trajectory as a ribbon
 * (bright up to the current frame, faint after), and footprints: a sole mark at the foot joint's x–z
 * at each contact onset, blue for the left foot and orange for the right, faded until reached.
 * Colours are per vertex with alpha; nothing is textured.
 */
export class GroundMarks {
  readonly mesh: THREE.Mesh;
  private readonly geometry = new THREE.BufferGeometry();
  private pos = new Float32Array(0);
  private col = new Float32Array(0);
  private shadowUnit = new Float32Array(0);
  /** Index ranges of each layer, to rebuild the index when layers are hidden. */
  private sections: Record<'shadow' | 'trail' | 'footprints', number[]> = { shadow: [], trail: [], footprints: [] };
  private visibleLayers = { trail: true, footprints: true };
  private trailStart = 0;
  private trailPoints = 0;
  private trailStep = 1;
  private trailDone = -1;
  private printStart = 0;
  private prints: Footprint[] = [];
  private printsShown = -1;
  private readonly trailColor = PALETTE.trail;
  private readonly past = [PALETTE.left, PALETTE.right];
  private readonly future = [PALETTE.left.clone().lerp(PALETTE.background, 0.7), PALETTE.right.clone().lerp(PALETTE.background, 0.7)];

  constructor() {
    this.mesh = new THREE.Mesh(
      this.geometry,
      new THREE.MeshBasicMaterial({ vertexColors: true, transparent: true, depthWrite: false, side: THREE.DoubleSide }),
    );
    this.mesh.renderOrder = 1;
    this.mesh.frustumCulled = false;
    this.mesh.visible = false;
  }

  get footprintCount(): number {
    return this.prints.length;
  }

  build(motion: Motion, contacts: Uint8Array | undefined, root: number): void {
    const J = motion.joints.length;
    const P = motion.positions;

    // Trail samples: ~15 a second is smooth enough and keeps the vertex count low.
    this.trailStep = Math.max(1, Math.round(motion.fps / 15));
    const idx: number[] = [];
    for (let f = 0; f < motion.frames; f += this.trailStep) idx.push(f);
    if (idx[idx.length - 1] !== motion.frames - 1) idx.push(motion.frames - 1);

    // Footprints at contact onsets.
    const items: (Footprint & { x: number; z: number; dx: number; dz: number })[] = [];
    if (contacts && contacts.length >= motion.frames * 2) {
      const feet = [findFootJoints(motion.joints, 'left'), findFootJoints(motion.joints, 'right')];
      for (const side of [0, 1] as const) {
        const ft = feet[side];
        if (!ft) continue;
        for (let f = 0; f < motion.frames; f++) {
          if (!contacts[f * 2 + side] || (f > 0 && contacts[(f - 1) * 2 + side])) continue;
          const o = (f * J + ft.ankle) * 3, t = (f * J + ft.toe) * 3;
          let dx = P[t] - P[o], dz = P[t + 2] - P[o + 2];
          const l = Math.hypot(dx, dz);
          if (l > 1e-4) { dx /= l; dz /= l; } else { dx = 0; dz = 1; }
          // The sole is centred a little ahead of the ankle, so its heel lands under the ankle.
          items.push({ frame: f, side, x: P[o] + 0.05 * dx, z: P[o + 2] + 0.05 * dz, dx, dz });
        }
      }
    }
    items.sort((a, b) => a.frame - b.frame);

    const shadowVerts = 1 + SHADOW_RINGS * SHADOW_SEGMENTS;
    const n = shadowVerts + idx.length * 2 + items.length * SOLE_VERTS;
    this.pos = new Float32Array(n * 3);
    this.col = new Float32Array(n * 4);

    // Shadow: a unit disc (radius 0.5), placed every frame; black with alpha falling off outwards.
    this.shadowUnit = new Float32Array(shadowVerts * 3);
    this.col[3] = 0.5;
    for (let k = 1, v = 1; k <= SHADOW_RINGS; k++) {
      const t = k / SHADOW_RINGS;
      for (let i = 0; i < SHADOW_SEGMENTS; i++, v++) {
        const a = (i / SHADOW_SEGMENTS) * Math.PI * 2;
        this.shadowUnit[v * 3] = Math.cos(a) * 0.5 * t;
        this.shadowUnit[v * 3 + 2] = Math.sin(a) * 0.5 * t;
        this.col[v * 4 + 3] = 0.5 * (1 - t) * (1 - t);
      }
    }
    this.sections.shadow = discIndex(SHADOW_RINGS, SHADOW_SEGMENTS);

    // Trail ribbon.
    this.trailStart = shadowVerts;
    this.trailPoints = idx.length;
    let nx = 1, nz = 0; // last good normal, for standing still
    const trail: number[] = [];
    for (let i = 0; i < idx.length; i++) {
      const o = (idx[i] * J + root) * 3;
      const a = (idx[Math.max(i - 1, 0)] * J + root) * 3, b = (idx[Math.min(i + 1, idx.length - 1)] * J + root) * 3;
      const tx = P[b] - P[a], tz = P[b + 2] - P[a + 2], tl = Math.hypot(tx, tz);
      if (tl > 1e-5) { nx = -tz / tl; nz = tx / tl; }
      const h = TRAIL_WIDTH / 2, v = this.trailStart + i * 2;
      this.pos.set([P[o] + nx * h, 0.003, P[o + 2] + nz * h, P[o] - nx * h, 0.003, P[o + 2] - nz * h], v * 3);
      for (const w of [v, v + 1]) this.trailColor.toArray(this.col, w * 4);
      if (i < idx.length - 1) trail.push(v, v + 1, v + 2, v + 1, v + 3, v + 2);
    }
    this.sections.trail = trail;

    // Footprints.
    this.printStart = this.trailStart + idx.length * 2;
    const prints: number[] = [];
    items.forEach((it, k) => {
      let v = this.printStart + k * SOLE_VERTS;
      const px = it.dz, pz = -it.dx; // lateral direction
      for (const pad of SOLE_PADS) {
        const c = v;
        this.pos.set([it.x + px * pad.cx + it.dx * pad.cy, 0.005, it.z + pz * pad.cx + it.dz * pad.cy], c * 3);
        for (let i = 0; i < pad.n; i++) {
          const a = (i / pad.n) * Math.PI * 2;
          const lx = pad.cx + Math.cos(a) * pad.rx, ly = pad.cy + Math.sin(a) * pad.ry;
          this.pos.set([it.x + px * lx + it.dx * ly, 0.005, it.z + pz * lx + it.dz * ly], (c + 1 + i) * 3);
          prints.push(c, c + 1 + i, c + 1 + ((i + 1) % pad.n));
        }
        v += pad.n + 1;
      }
    });
    this.sections.footprints = prints;
    this.prints = items.map(({ frame, side }) => ({ frame, side }));

    this.geometry.setAttribute('position', new THREE.BufferAttribute(this.pos, 3).setUsage(THREE.DynamicDrawUsage));
    this.geometry.setAttribute('color', new THREE.BufferAttribute(this.col, 4).setUsage(THREE.DynamicDrawUsage));
    this.trailDone = -1;
    this.printsShown = -1;
    this.updateIndex();
    this.setProgress(0, 0);
    this.mesh.visible = true;
  }

  setLayers(l: { trail?: boolean; footprints?: boolean }): void {
    if (l.trail !== undefined) this.visibleLayers.trail = l.trail;
    if (l.footprints !== undefined) this.visibleLayers.footprints = l.footprints;
    this.updateIndex();
  }

  layers(): { trail: boolean; footprints: boolean } {
    return { ...this.visibleLayers };
  }

  /** Places the blob shadow (centre on the ground, diameter in metres). */
  setShadow(x: number, z: number, size: number): void {
    const U = this.shadowUnit, p = this.pos;
    for (let v = 0; v < U.length; v += 3) {
      p[v] = x + U[v] * size;
      p[v + 1] = 0.004;
      p[v + 2] = z + U[v + 2] * size;
    }
    const attr = this.geometry.getAttribute('position') as THREE.BufferAttribute | undefined;
    if (attr) {
      attr.clearUpdateRanges();
      attr.addUpdateRange(0, U.length);
      attr.needsUpdate = true;
    }
  }

  /** Trail bright up to `frameFloat`; footprints whose onset is at or before `frame` in full colour. */
  setProgress(frameFloat: number, frame: number): void {
    const col = this.geometry.getAttribute('color') as THREE.BufferAttribute | undefined;
    if (!col) return;
    let changed = false;
    const done = Math.min(Math.floor(frameFloat / this.trailStep), this.trailPoints - 1);
    if (done !== this.trailDone) {
      const from = this.trailDone < 0 ? 0 : Math.min(done, this.trailDone);
      const to = this.trailDone < 0 ? this.trailPoints - 1 : Math.max(done, this.trailDone);
      for (let i = from; i <= to; i++) {
        const a = i <= done ? 0.95 : 0.28, v = this.trailStart + i * 2;
        this.col[v * 4 + 3] = a;
        this.col[v * 4 + 7] = a;
      }
      this.trailDone = done;
      changed = true;
    }
    let shown = 0;
    while (shown < this.prints.length && this.prints[shown].frame <= frame) shown++;
    if (shown !== this.printsShown) {
      this.prints.forEach((p, k) => {
        const c = k < shown ? this.past[p.side] : this.future[p.side];
        for (let v = this.printStart + k * SOLE_VERTS, e = v + SOLE_VERTS; v < e; v++) {
          c.toArray(this.col, v * 4);
          this.col[v * 4 + 3] = 0.92;
        }
      });
      this.printsShown = shown;
      changed = true;
    }
    if (changed) col.needsUpdate = true;
  }

  private updateIndex(): void {
    const index = [
      ...this.sections.shadow,
      ...(this.visibleLayers.trail ? this.sections.trail : []),
      ...(this.visibleLayers.footprints ? this.sections.footprints : []),
    ];
    this.geometry.setIndex(index);
  }
}

/**
 * A soft blob shadow on its own (a second figure's; the main figure's is part of GroundMarks): the same
 * disc as GroundMarks', placed by the mesh's transform. One small extra draw call while it is shown.
 */
export class BlobShadow {
  readonly mesh: THREE.Mesh;

  constructor() {
    const verts = 1 + SHADOW_RINGS * SHADOW_SEGMENTS;
    const pos = new Float32Array(verts * 3);
    const col = new Float32Array(verts * 4);
    col[3] = 0.5;
    for (let k = 1, v = 1; k <= SHADOW_RINGS; k++) {
      const t = k / SHADOW_RINGS;
      for (let i = 0; i < SHADOW_SEGMENTS; i++, v++) {
        const a = (i / SHADOW_SEGMENTS) * Math.PI * 2;
        pos[v * 3] = Math.cos(a) * 0.5 * t;
        pos[v * 3 + 2] = Math.sin(a) * 0.5 * t;
        col[v * 4 + 3] = 0.5 * (1 - t) * (1 - t);
      }
    }
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    geometry.setAttribute('color', new THREE.BufferAttribute(col, 4));
    geometry.setIndex(discIndex(SHADOW_RINGS, SHADOW_SEGMENTS));
    this.mesh = new THREE.Mesh(geometry, new THREE.MeshBasicMaterial({ vertexColors: true, transparent: true, depthWrite: false, side: THREE.DoubleSide }));
    this.mesh.renderOrder = 1;
    this.mesh.frustumCulled = false;
    this.mesh.visible = false;
  }

  /** Centre on the ground and diameter in metres. */
  set(x: number, z: number, size: number): void {
    this.mesh.position.set(x, 0.004, z);
    this.mesh.scale.set(size, 1, size);
  }
}
