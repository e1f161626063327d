// Overlays flat on the ground for the optimiser modes: a polyline as a ribbon with a dot at its start
// (Path mode's drawn path), and an arrow (Steer mode's target heading). Unlit and single-coloured,
// one draw call each, like the viewer's other ground layers.

import * as THREE from 'three';

/** What the user asked for (a drawn path, a target heading): mint, apart from the trail's purple and the feet's blue and orange. */
export const TARGET_COLOR = new THREE.Color('#46d9a8');

const DOT_SEGMENTS = 20;

function groundMaterial(color: THREE.Color, opacity: number): THREE.MeshBasicMaterial {
  // No fog: the path and the arrow are what the user is working with, however far the view reaches.
  return new THREE.MeshBasicMaterial({ color, transparent: true, opacity, depthWrite: false, side: THREE.DoubleSide, fog: false });
}

/** A polyline on the ground (x, z pairs) drawn as a ribbon `width` wide, with a dot marking its start. */
export class GroundLine {
  readonly mesh: THREE.Mesh;
  private readonly geometry = new THREE.BufferGeometry();

  constructor(color: THREE.Color, private readonly width: number, opacity: number, private readonly y = 0.002) {
    this.mesh = new THREE.Mesh(this.geometry, groundMaterial(color, opacity));
    this.mesh.renderOrder = 0.5; // above the grid, under the trail and footprints
    this.mesh.frustumCulled = false;
    this.mesh.visible = false;
  }

  /** Shows the line through `xz` (x0, z0, x1, z1, …); fewer than two points hide it. */
  set(xz: ArrayLike<number>): void {
    const n = Math.floor(xz.length / 2);
    if (n < 2) {
      this.mesh.visible = false;
      return;
    }
    const dot = 1 + DOT_SEGMENTS;
    const pos = new Float32Array((n * 2 + dot) * 3);
    const index: number[] = [];
    const h = this.width / 2;
    let nx = 1, nz = 0; // last good normal, for repeated points
    for (let i = 0; i < n; i++) {
      const a = Math.max(i - 1, 0), b = Math.min(i + 1, n - 1);
      const tx = xz[2 * b] - xz[2 * a], tz = xz[2 * b + 1] - xz[2 * a + 1], tl = Math.hypot(tx, tz);
      if (tl > 1e-6) { nx = -tz / tl; nz = tx / tl; }
      const x = xz[2 * i], z = xz[2 * i + 1];
      pos.set([x + nx * h, this.y, z + nz * h, x - nx * h, this.y, z - nz * h], i * 6);
      if (i < n - 1) index.push(2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 1, 2 * i + 3, 2 * i + 2);
    }
    // The start dot: where the character sets off.
    const c = n * 2, r = this.width * 2.2;
    pos.set([xz[0], this.y, xz[1]], c * 3);
    for (let i = 0; i < DOT_SEGMENTS; i++) {
      const t = (i / DOT_SEGMENTS) * Math.PI * 2;
      pos.set([xz[0] + Math.cos(t) * r, this.y, xz[1] + Math.sin(t) * r], (c + 1 + i) * 3);
      index.push(c, c + 1 + i, c + 1 + ((i + 1) % DOT_SEGMENTS));
    }
    this.geometry.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    this.geometry.setIndex(index);
    this.geometry.computeBoundingSphere();
    this.mesh.visible = true;
  }

  clear(): void {
    this.mesh.visible = false;
  }
}

/** A flat arrow on the ground around a point, pointing along a heading (0 = +z, π/2 = +x). */
export class GroundArrow {
  readonly mesh: THREE.Mesh;
  private readonly pos = new Float32Array(7 * 3);
  private readonly attr: THREE.BufferAttribute;

  /** The arrow starts `inner` metres out from its point (clear of the figure's feet). */
  constructor(color: THREE.Color, opacity: number, private readonly inner = 0.38) {
    const geometry = new THREE.BufferGeometry();
    this.attr = new THREE.BufferAttribute(this.pos, 3).setUsage(THREE.DynamicDrawUsage);
    geometry.setAttribute('position', this.attr);
    // Shaft (0, 1, 2, 3) and head (4, 5, 6).
    geometry.setIndex([0, 1, 2, 0, 2, 3, 4, 5, 6]);
    this.mesh = new THREE.Mesh(geometry, groundMaterial(color, opacity));
    this.mesh.renderOrder = 1.5;
    this.mesh.frustumCulled = false;
    this.mesh.visible = false;
    this.setLength(0.6);
  }

  /** Arrow length beyond `inner` (m): the shaft stretches, the head keeps its size. */
  setLength(length: number): void {
    const head = 0.2, half = 0.035, wing = 0.12, y = 0.006;
    const a = this.inner, b = this.inner + Math.max(length - head, 0.02), tip = b + head;
    // Local frame: +z forward, x lateral.
    this.pos.set([-half, y, a, half, y, a, half, y, b, -half, y, b, -wing, y, b, wing, y, b, 0, y, tip]);
    this.attr.needsUpdate = true;
  }

  /** Places the arrow at ground point (x, z), pointing along `heading`. */
  place(x: number, z: number, heading: number): void {
    this.mesh.position.set(x, 0, z);
    this.mesh.rotation.set(0, heading, 0); // a turn about +y by h takes +z to (sin h, 0, cos h)
    this.mesh.visible = true;
  }

  hide(): void {
    this.mesh.visible = false;
  }
}
