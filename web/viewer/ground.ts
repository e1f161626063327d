// Things drawn on the ground plane (x–z): the grid, a glow on the floor around the figure (GPU tier
// only), and in one mesh the blob shadow, the root trajectory ribbon and the footprints.

import * as THREE from 'three';
import { PALETTE } from './palette';
import type { Motion } from '../motion/types';
import { footJointsOf } from '../motion/contacts';

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
const SHADOW_VERTS = 1 + SHADOW_RINGS * SHADOW_SEGMENTS;

/** One flat sole mark, +y forward: a forefoot pad and a heel pad (x lateral, y forward, metres). */
const SOLE_PADS: ReadonlyArray<{ cx: number; cy: number; rx: number; ry: number; n: number }> = [
  { cx: 0, cy: 0.045, rx: 0.042, ry: 0.068, n: 12 },
  { cx: 0.004, cy: -0.078, rx: 0.032, ry: 0.04, n: 10 },
];
const SOLE_VERTS = SOLE_PADS.reduce((a, p) => a + p.n + 1, 0);
/** Index entries of one footprint (a triangle fan per pad) and of one trail segment (two triangles). */
const SOLE_INDICES = SOLE_PADS.reduce((a, p) => a + p.n * 3, 0);
const SEGMENT_INDICES = 6;

/**
 * The marks are cut into chunks, consecutive in time, of at most this many trail segments and this many
 * footprints (about 4 s of walking): the unit in which they are culled and drawn.
 */
export const CHUNK_ITEMS = 64;
/**
 * At most this many chunks are drawn, those nearest in time to the playhead: a long clip that stays in
 * one place (or keeps coming back to it) would otherwise draw all its marks on top of each other.
 */
export const MAX_DRAWN_CHUNKS = 32;

/** The shadow disc (radius 0.5, centred on the origin): positions (xyz) and black with alpha falling off outwards (rgba). */
function shadowDisc(): { pos: Float32Array; col: Float32Array } {
  const pos = new Float32Array(SHADOW_VERTS * 3);
  const col = new Float32Array(SHADOW_VERTS * 4);
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
  return { pos, col };
}

/** First index in the ascending `sorted` whose value is greater than `x`. */
function upperBound(sorted: ArrayLike<number>, x: number): number {
  let lo = 0, hi = sorted.length;
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if (sorted[mid] <= x) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

/** Where the footprints go: a sole mark at each contact onset, sorted by frame. */
interface Footprint {
  frame: number;
  side: 0 | 1;
  /** Centre on the ground and the unit direction the foot points in. */
  x: number;
  z: number;
  dx: number;
  dz: number;
}

function findFootprints(motion: Motion, contacts: Uint8Array | undefined): Footprint[] {
  const prints: Footprint[] = [];
  if (!contacts || contacts.length < motion.frames * 2) return prints;
  const J = motion.joints.length, P = motion.positions;
  const feet = footJointsOf(motion) ?? [undefined, undefined];
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
      prints.push({ frame: f, side, x: P[o] + 0.05 * dx, z: P[o + 2] + 0.05 * dz, dx, dz });
    }
  }
  return prints.sort((a, b) => a.frame - b.frame);
}

/**
 * Everything drawn flat on the ground for the shown motion, in ONE mesh and draw call (software GL
 * pays a fixed price per draw): a soft blob shadow under the figure, the root trajectory as a ribbon
 * (bright up to the current frame, faint after), and footprints: a sole mark at the foot joint's x–z
 * at each contact onset, blue for the left foot and orange for the right, faded until reached.
 * Colours are per vertex with alpha; nothing is textured.
 *
 * Per frame the work does not grow with the clip's length: the whole clip's vertices are built once
 * (`build`), playing recolours and uploads only the trail points and footprints the playhead passed,
 * and `drawFor` draws only the chunks the camera can see before the fog hides them (software GL pays for
 * every triangle drawn, on screen or not).
 */
export class GroundMarks {
  readonly mesh: THREE.Mesh;
  private readonly geometry = new THREE.BufferGeometry();
  private pos = new Float32Array(0);
  private col = new Float32Array(0);
  private colorAttr: THREE.BufferAttribute | null = null;
  private indexAttr: THREE.BufferAttribute | null = null;
  private readonly shadowUnit = shadowDisc();
  private readonly shadowIndex = discIndex(SHADOW_RINGS, SHADOW_SEGMENTS);
  private visibleLayers = { trail: true, footprints: true };
  private trailStart = 0;
  private trailPoints = 0;
  private trailStep = 1;
  private trailDone = -1;
  private printStart = 0;
  /** Onset frame and side (0 left, 1 right) of each footprint, ascending by frame. */
  private printFrames = new Int32Array(0);
  private printSides = new Uint8Array(0);
  private printsShown = -1;
  /** Triangles of the whole trail and of all footprints, in time order. */
  private trailIndex = new Uint32Array(0);
  private printIndex = new Uint32Array(0);
  /** Chunk c holds trail segments chunkSegments[c]…[c+1]−1 and footprints chunkPrints[c]…[c+1]−1. */
  private chunkSegments = new Int32Array(1);
  private chunkPrints = new Int32Array(1);
  /** First frame of each chunk (ascending) and its ground box: min x, min z, max x, max z. */
  private chunkFrames = new Int32Array(0);
  private chunkBoxes = new Float32Array(0);
  /** The playhead's chunk, and the chunks now in the index (ascending; null: the index needs writing). */
  private playheadChunk = 0;
  private drawn: number[] | null = null;
  private readonly viewDir = new THREE.Vector3();
  private readonly box = new THREE.Box3();
  private readonly frustum = new THREE.Frustum();
  private readonly viewProjection = new THREE.Matrix4();
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
    return this.printFrames.length;
  }

  build(motion: Motion, contacts: Uint8Array | undefined, root: number): void {
    const J = motion.joints.length;
    const P = motion.positions;

    // Trail samples: ~15 a second is smooth enough and keeps the vertex count low.
    this.trailStep = Math.max(1, Math.round(motion.fps / 15));
    const points = Math.ceil(motion.frames / this.trailStep) + ((motion.frames - 1) % this.trailStep === 0 ? 0 : 1);
    const trailFrames = new Int32Array(points);
    for (let i = 0; i < points; i++) trailFrames[i] = Math.min(i * this.trailStep, motion.frames - 1);
    const prints = findFootprints(motion, contacts);

    this.trailStart = SHADOW_VERTS;
    this.trailPoints = points;
    this.printStart = this.trailStart + points * 2;
    const n = this.printStart + prints.length * SOLE_VERTS;
    this.pos = new Float32Array(n * 3);
    this.col = new Float32Array(n * 4);
    this.col.set(this.shadowUnit.col);

    // Trail ribbon.
    const segments = Math.max(points - 1, 0);
    this.trailIndex = new Uint32Array(segments * SEGMENT_INDICES);
    let nx = 1, nz = 0; // last good normal, for standing still
    for (let i = 0; i < points; i++) {
      const o = (trailFrames[i] * J + root) * 3;
      const a = (trailFrames[Math.max(i - 1, 0)] * J + root) * 3, b = (trailFrames[Math.min(i + 1, points - 1)] * J + root) * 3;
      const tx = P[b] - P[a], tz = P[b + 2] - P[a + 2], tl = Math.hypot(tx, tz);
      if (tl > 1e-5) { nx = -tz / tl; nz = tx / tl; }
      const h = TRAIL_WIDTH / 2, v = this.trailStart + i * 2;
      this.pos.set([P[o] + nx * h, 0.003, P[o + 2] + nz * h, P[o] - nx * h, 0.003, P[o + 2] - nz * h], v * 3);
      for (const w of [v, v + 1]) this.trailColor.toArray(this.col, w * 4);
      if (i < segments) this.trailIndex.set([v, v + 1, v + 2, v + 1, v + 3, v + 2], i * SEGMENT_INDICES);
    }

    // Footprints.
    this.printIndex = new Uint32Array(prints.length * SOLE_INDICES);
    let t = 0;
    prints.forEach((it, k) => {
      let v = this.printStart + k * SOLE_VERTS;
      const px = it.dz, pz = -it.dx; // lateral direction
      for (const pad of SOLE_PADS) {
        const c = v;
        this.pos.set([it.x + px * pad.cx + it.dx * pad.cy, 0.005, it.z + pz * pad.cx + it.dz * pad.cy], c * 3);
        for (let i = 0; i < pad.n; i++) {
          const a = (i / pad.n) * Math.PI * 2;
          const lx = pad.cx + Math.cos(a) * pad.rx, ly = pad.cy + Math.sin(a) * pad.ry;
          this.pos.set([it.x + px * lx + it.dx * ly, 0.005, it.z + pz * lx + it.dz * ly], (c + 1 + i) * 3);
          this.printIndex.set([c, c + 1 + i, c + 1 + ((i + 1) % pad.n)], t);
          t += 3;
        }
        v += pad.n + 1;
      }
    });
    this.printFrames = Int32Array.from(prints, (p) => p.frame);
    this.printSides = Uint8Array.from(prints, (p) => p.side);
    this.buildChunks(trailFrames);

    // Drawn: the shadow, then the chosen chunks' trail, then their footprints (so footprints lie on the trail).
    const largest = CHUNK_ITEMS * (SEGMENT_INDICES + SOLE_INDICES) * MAX_DRAWN_CHUNKS;
    const capacity = this.shadowIndex.length + Math.min(this.trailIndex.length + this.printIndex.length, largest);
    const index = new Uint32Array(capacity);
    index.set(this.shadowIndex);
    this.indexAttr = new THREE.BufferAttribute(index, 1).setUsage(THREE.DynamicDrawUsage);
    this.colorAttr = new THREE.BufferAttribute(this.col, 4).setUsage(THREE.DynamicDrawUsage);
    this.geometry.setAttribute('position', new THREE.BufferAttribute(this.pos, 3).setUsage(THREE.DynamicDrawUsage));
    this.geometry.setAttribute('color', this.colorAttr);
    this.geometry.setIndex(this.indexAttr);
    this.geometry.setDrawRange(0, this.shadowIndex.length);
    this.drawn = null;
    this.trailDone = -1;
    this.printsShown = -1;
    this.setProgress(0, 0);
    this.mesh.visible = true;
  }

  /**
   * Cuts the trail segments and footprints, in time order, into chunks of at most CHUNK_ITEMS of each,
   * each with its box on the ground (from the vertices, so it holds the whole ribbon and soles).
   */
  private buildChunks(trailFrames: Int32Array): void {
    const segments = Math.max(trailFrames.length - 1, 0), prints = this.printFrames;
    const segmentStarts = [0], printStarts = [0], frames: number[] = [], boxes: number[] = [];
    let s = 0, k = 0;
    while (s < segments || k < prints.length) {
      const s0 = s, k0 = k;
      frames.push(Math.min(s < segments ? trailFrames[s] : Infinity, k < prints.length ? prints[k] : Infinity));
      while ((s < segments || k < prints.length) && s - s0 < CHUNK_ITEMS && k - k0 < CHUNK_ITEMS) {
        if (k >= prints.length || (s < segments && trailFrames[s] <= prints[k])) s++;
        else k++;
      }
      segmentStarts.push(s);
      printStarts.push(k);
      const box = [Infinity, Infinity, -Infinity, -Infinity];
      // A segment joins point i to point i + 1: both ends' vertices.
      if (s > s0) this.extendBox(box, this.trailStart + s0 * 2, this.trailStart + (s + 1) * 2);
      this.extendBox(box, this.printStart + k0 * SOLE_VERTS, this.printStart + k * SOLE_VERTS);
      boxes.push(...box);
    }
    this.chunkSegments = Int32Array.from(segmentStarts);
    this.chunkPrints = Int32Array.from(printStarts);
    this.chunkFrames = Int32Array.from(frames);
    this.chunkBoxes = Float32Array.from(boxes);
  }

  /** Grows a ground box (min x, min z, max x, max z) over vertices from…to−1. */
  private extendBox(box: number[], from: number, to: number): void {
    for (let v = from; v < to; v++) {
      const x = this.pos[v * 3], z = this.pos[v * 3 + 2];
      box[0] = Math.min(box[0], x);
      box[1] = Math.min(box[1], z);
      box[2] = Math.max(box[2], x);
      box[3] = Math.max(box[3], z);
    }
  }

  setLayers(l: { trail?: boolean; footprints?: boolean }): void {
    if (l.trail !== undefined) this.visibleLayers.trail = l.trail;
    if (l.footprints !== undefined) this.visibleLayers.footprints = l.footprints;
    this.drawn = null;
  }

  layers(): { trail: boolean; footprints: boolean } {
    return { ...this.visibleLayers };
  }

  /** Places the blob shadow (centre on the ground, diameter in metres). */
  setShadow(x: number, z: number, size: number): void {
    const U = this.shadowUnit.pos, p = this.pos;
    if (p.length < U.length) return; // nothing built yet
    for (let v = 0; v < U.length; v += 3) {
      p[v] = x + U[v] * size;
      p[v + 1] = 0.004;
      p[v + 2] = z + U[v + 2] * size;
    }
    const attr = this.geometry.getAttribute('position') as THREE.BufferAttribute;
    attr.clearUpdateRanges();
    attr.addUpdateRange(0, U.length);
    attr.needsUpdate = true;
  }

  /**
   * Trail bright up to `frameFloat`; footprints whose onset is at or before `frame` in full colour. Only
   * what changed since the last call is recoloured and uploaded.
   */
  setProgress(frameFloat: number, frame: number): void {
    if (!this.colorAttr) return;
    const col = this.col;
    const done = Math.min(Math.floor(frameFloat / this.trailStep), this.trailPoints - 1);
    if (done !== this.trailDone) {
      const from = this.trailDone < 0 ? 0 : Math.min(done, this.trailDone);
      const to = this.trailDone < 0 ? this.trailPoints - 1 : Math.max(done, this.trailDone);
      for (let i = from; i <= to; i++) {
        const a = i <= done ? 0.95 : 0.28, v = this.trailStart + i * 2;
        col[v * 4 + 3] = a;
        col[v * 4 + 7] = a;
      }
      this.colorsChanged(this.trailStart + from * 2, (to - from + 1) * 2);
      this.trailDone = done;
    }
    const shown = upperBound(this.printFrames, frame);
    if (shown !== this.printsShown) {
      const from = this.printsShown < 0 ? 0 : Math.min(shown, this.printsShown);
      const to = this.printsShown < 0 ? this.printFrames.length : Math.max(shown, this.printsShown);
      for (let k = from; k < to; k++) {
        const c = (k < shown ? this.past : this.future)[this.printSides[k]];
        for (let v = this.printStart + k * SOLE_VERTS, e = v + SOLE_VERTS; v < e; v++) {
          c.toArray(col, v * 4);
          col[v * 4 + 3] = 0.92;
        }
      }
      this.colorsChanged(this.printStart + from * SOLE_VERTS, (to - from) * SOLE_VERTS);
      this.printsShown = shown;
    }
    this.playheadChunk = Math.max(upperBound(this.chunkFrames, frame) - 1, 0);
  }

  /** Uploads the colours of `count` vertices from `first` at the next render. */
  private colorsChanged(first: number, count: number): void {
    if (count <= 0 || !this.colorAttr) return;
    this.colorAttr.addUpdateRange(first * 4, count * 4);
    this.colorAttr.needsUpdate = true;
  }

  /**
   * Chooses what to draw for `camera` (call before each render): the chunks that are in its view and
   * nearer along its view direction than `farthest` (the fog's far distance: beyond it a mark is the
   * background colour), at most MAX_DRAWN_CHUNKS of them, nearest in time to the playhead first. The
   * index is rewritten only when that choice (or a layer) changes.
   */
  drawFor(camera: THREE.Camera, farthest: number): void {
    if (!this.indexAttr) return;
    camera.updateMatrixWorld();
    this.frustum.setFromProjectionMatrix(this.viewProjection.multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse));
    const eye = camera.position, d = camera.getWorldDirection(this.viewDir);
    const B = this.chunkBoxes, chunks = this.chunkFrames.length, now = this.playheadChunk;
    const chosen: number[] = [];
    // Chunks in order of time from the playhead: now, now + 1, now − 1, now + 2, …
    for (let step = 0; chosen.length < MAX_DRAWN_CHUNKS && step < 2 * chunks; step++) {
      const c = step % 2 === 0 ? now + step / 2 : now - (step + 1) / 2;
      if (c < 0 || c >= chunks) continue;
      const minX = B[c * 4], minZ = B[c * 4 + 1], maxX = B[c * 4 + 2], maxZ = B[c * 4 + 3];
      // The box's nearest and farthest depth along the view direction (its height, 0–6 mm, is negligible):
      // a box beyond the fog or wholly behind the camera is out without the frustum test.
      const nearest = d.x * ((d.x > 0 ? minX : maxX) - eye.x) - d.y * eye.y + d.z * ((d.z > 0 ? minZ : maxZ) - eye.z);
      const deepest = d.x * ((d.x > 0 ? maxX : minX) - eye.x) - d.y * eye.y + d.z * ((d.z > 0 ? maxZ : minZ) - eye.z);
      if (nearest > farthest || deepest < 0) continue;
      this.box.min.set(minX, 0, minZ);
      this.box.max.set(maxX, 0.01, maxZ);
      if (this.frustum.intersectsBox(this.box)) chosen.push(c);
    }
    chosen.sort((a, b) => a - b);
    const same = this.drawn !== null && this.drawn.length === chosen.length && this.drawn.every((c, i) => c === chosen[i]);
    if (same) return;
    this.drawn = chosen;
    const index = this.indexAttr.array as Uint32Array, start = this.shadowIndex.length;
    let end = start;
    const copy = (from: Uint32Array, starts: Int32Array, per: number) => {
      for (const c of chosen) {
        index.set(from.subarray(starts[c] * per, starts[c + 1] * per), end);
        end += (starts[c + 1] - starts[c]) * per;
      }
    };
    if (this.visibleLayers.trail) copy(this.trailIndex, this.chunkSegments, SEGMENT_INDICES);
    if (this.visibleLayers.footprints) copy(this.printIndex, this.chunkPrints, SOLE_INDICES);
    this.geometry.setDrawRange(0, end);
    this.indexAttr.clearUpdateRanges();
    if (end > start) {
      this.indexAttr.addUpdateRange(start, end - start);
      this.indexAttr.needsUpdate = true;
    }
  }
}

/**
 * A soft blob shadow on its own (a second figure's; the main figure's is part of GroundMarks): the same
 * disc as GroundMarks', placed by the mesh's transform. One small extra draw call while it is shown.
 */
export class BlobShadow {
  readonly mesh: THREE.Mesh;

  constructor() {
    const { pos, col } = shadowDisc();
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
