// Capsule-and-sphere figure for any joint set, in one draw call. Every joint is a sphere and every bone
// a capsule; both are drawn as ray-cast impostors: each instance is a small box around its capsule
// (a sphere is a capsule of zero length) and the fragment shader intersects the view ray with the exact
// capsule, writes its depth and shades it. That is a few hundred triangles for a whole figure with
// perfectly round silhouettes, which matters under software GL where every triangle costs.

import * as THREE from 'three';
import { PALETTE } from './palette';
import type { Motion } from '../motion/types';
import { findHead, sideOf } from './naming';

export interface FigureColors {
  left: THREE.Color;
  right: THREE.Color;
  center: THREE.Color;
  head: THREE.Color;
}

export const COLORS: FigureColors = { left: PALETTE.left, right: PALETTE.right, center: PALETTE.center, head: PALETTE.head };

// Everything is done in view space: the vertex shader hands over the capsule's end points already
// transformed, so the fragment shader has no matrix work beyond the depth.
const vertexShader = /* glsl */ `
  attribute vec3 aA;
  attribute vec3 aB;
  attribute float aR;
  attribute vec3 aColor;
  varying vec3 vView;
  flat varying vec3 vA;
  flat varying vec3 vB;
  flat varying float vR;
  flat varying vec3 vColor;
  #include <fog_pars_vertex>
  void main() {
    vec3 axis = aB - aA;
    float len = length(axis);
    vec3 d = len > 1e-6 ? axis / len : vec3(0.0, 1.0, 0.0);
    vec3 t = normalize(abs(d.y) < 0.99 ? cross(d, vec3(0.0, 1.0, 0.0)) : cross(d, vec3(1.0, 0.0, 0.0)));
    vec3 b = cross(d, t);
    // Unit box → box around the capsule (a little margin for the rasteriser).
    float w = 2.0 * aR * 1.02;
    vec3 p = 0.5 * (aA + aB) + d * position.y * (len + w) + t * position.x * w + b * position.z * w;
    vec4 mvPosition = viewMatrix * vec4(p, 1.0);
    vView = mvPosition.xyz;
    vA = (viewMatrix * vec4(aA, 1.0)).xyz;
    vB = (viewMatrix * vec4(aB, 1.0)).xyz;
    vR = aR;
    vColor = aColor;
    gl_Position = projectionMatrix * mvPosition;
    #include <fog_vertex>
  }`;

const fragmentShader = /* glsl */ `
  uniform mat4 projectionMatrix;
  varying vec3 vView;
  flat varying vec3 vA;
  flat varying vec3 vB;
  flat varying float vR;
  flat varying vec3 vColor;
  #include <fog_pars_fragment>

  // Ray from the eye (origin) along rd; distance to a sphere, or 1e20 for a miss.
  float sphereHit(vec3 rd, vec3 c, float r) {
    float b = dot(c, rd);
    float h = b * b - (dot(c, c) - r * r);
    return h < 0.0 ? 1e20 : b - sqrt(h);
  }

  // Ray–capsule intersection: the nearest of the cylinder body (after Inigo Quilez) and the two end
  // spheres; returns the distance along rd, or -1 for a miss.
  float capsule(vec3 rd, vec3 pa, vec3 pb, float r) {
    float best = min(sphereHit(rd, pa, r), sphereHit(rd, pb, r));
    vec3 ba = pb - pa;
    float baba = dot(ba, ba);
    if (baba > 1e-10) {
      vec3 oa = -pa;
      float bard = dot(ba, rd);
      float baoa = dot(ba, oa);
      float a = baba - bard * bard;
      float b = baba * dot(rd, oa) - baoa * bard;
      float c = baba * dot(oa, oa) - baoa * baoa - r * r * baba;
      float h = b * b - a * c;
      if (h >= 0.0 && a > 1e-12) {
        float t = (-b - sqrt(h)) / a;
        float y = baoa + t * bard;
        if (y > 0.0 && y < baba) best = min(best, t);
      }
    }
    return best > 1e19 ? -1.0 : best;
  }

  void main() {
    vec3 rd = normalize(vView);
    float t = capsule(rd, vA, vB, vR);
    if (t < 0.0) discard;
    vec3 pos = rd * t;
    vec3 ba = vB - vA;
    float h = clamp(dot(pos - vA, ba) / max(dot(ba, ba), 1e-12), 0.0, 1.0);
    vec3 n = (pos - vA - ba * h) / vR;
    // NDC depth of a view-space point: (P22·z + P32) / −z, mapped to [0, 1].
    gl_FragDepth = 0.5 * (projectionMatrix[3].z / -pos.z - projectionMatrix[2].z) + 0.5;
    // Studio lighting fixed to the camera (like a matcap): key from the upper left, soft fill, cool rim.
    const vec3 key = vec3(-0.42, 0.62, 0.66);
    const vec3 half_ = vec3(-0.2306, 0.3404, 0.9116); // normalize(key + view)
    float diff = max(dot(n, key), 0.0);
    float fill = 0.5 + 0.5 * n.y;
    float edge = 1.0 - max(n.z, 0.0);
    float spec = max(dot(n, half_), 0.0);
    spec *= spec; spec *= spec; spec *= spec; spec *= spec;
    vec3 col = vColor * (0.2 + 0.22 * fill + 0.68 * diff) + vec3(0.45, 0.55, 0.9) * (edge * edge * 0.3) + spec * 0.28;
    gl_FragColor = vec4(col, 1.0);
    // The scene's linear fog (three.js fog_fragment), held short of hiding the figure: framing a long drawn path
    // puts it beyond the fog's far distance (14 m under software GL), where it would vanish into the background.
    #ifdef USE_FOG
      gl_FragColor.rgb = mix(gl_FragColor.rgb, fogColor, min(smoothstep(fogNear, fogFar, vFogDepth), 0.55));
    #endif
  }`;

export class Figure {
  readonly mesh: THREE.Mesh;
  private readonly geometry: THREE.BufferGeometry;
  private readonly material: THREE.ShaderMaterial;
  private readonly attrA: THREE.BufferAttribute;
  private readonly attrB: THREE.BufferAttribute;
  /** Vertices per box, and per-item end points before they are copied to every vertex of its box. */
  private readonly boxVerts: number;
  private readonly itemA: Float32Array;
  private readonly itemB: Float32Array;
  private readonly parents: number[];
  private readonly joints: number;
  /** Child joint index of each bone (its parent is parents[child]). */
  private readonly bones: number[];
  private readonly head: number;
  /** The two joints whose midpoint is the head's centre, or null. */
  private readonly headSeg: [number, number] | null = null;

  constructor(motion: Motion, colors: FigureColors = COLORS) {
    const J = motion.joints.length;
    this.joints = J;
    this.parents = motion.parents.slice();
    this.bones = [];
    for (let j = 0; j < J; j++) if (motion.parents[j] >= 0) this.bones.push(j);
    this.head = findHead(motion.joints);
    if (this.head >= 0) {
      const child = motion.parents.indexOf(this.head);
      if (child >= 0) this.headSeg = [this.head, child];
      else if (motion.parents[this.head] >= 0) this.headSeg = [motion.parents[this.head], this.head];
    }

    // Sizes from the first frame: figure height sets the scale, bone length the thickness.
    const p = motion.positions;
    let minY = Infinity, maxY = -Infinity;
    for (let j = 0; j < J; j++) { minY = Math.min(minY, p[j * 3 + 1]); maxY = Math.max(maxY, p[j * 3 + 1]); }
    const s = Math.min(Math.max(maxY - minY, 0.5), 3) / 1.7;
    const n = J + this.bones.length; // instances: joints first, then bones
    const radius = new Float32Array(n);
    const color = new Float32Array(n * 3);
    const colorOf = (j: number) => {
      if (j === this.head) return colors.head;
      const side = sideOf(motion.joints[j]);
      return side === 'left' ? colors.left : side === 'right' ? colors.right : colors.center;
    };
    this.bones.forEach((c, i) => {
      const a = this.parents[c];
      const len = Math.hypot(p[c * 3] - p[a * 3], p[c * 3 + 1] - p[a * 3 + 1], p[c * 3 + 2] - p[a * 3 + 2]);
      const central = sideOf(motion.joints[c]) === null && c !== this.head;
      const r = central ? 0.03 * s : Math.min(Math.max(0.11 * len, 0.014 * s), 0.032 * s);
      radius[J + i] = r;
      radius[c] = Math.max(radius[c], r * 1.22);
      radius[a] = Math.max(radius[a], r * 1.22);
      colorOf(c).toArray(color, (J + i) * 3);
    });
    for (let j = 0; j < J; j++) {
      if (radius[j] === 0) radius[j] = 0.03 * s;
      colorOf(j).toArray(color, j * 3);
    }
    if (this.head >= 0) radius[this.head] = 0.1 * s;

    // One plain (non-instanced) mesh of boxes: software GL runs instanced draws instance by instance,
    // which costs far more than a few hundred extra vertices. Each box's vertices carry its capsule.
    const box = new THREE.BoxGeometry(1, 1, 1);
    const boxPos = box.getAttribute('position').array as Float32Array;
    const boxIndex = box.index!.array;
    const V = boxPos.length / 3;
    this.boxVerts = V;
    const corner = new Float32Array(n * V * 3);
    const r = new Float32Array(n * V);
    const rgb = new Float32Array(n * V * 3);
    const index: number[] = [];
    for (let i = 0; i < n; i++) {
      corner.set(boxPos, i * V * 3);
      r.fill(radius[i], i * V, (i + 1) * V);
      for (let v = 0; v < V; v++) rgb.set(color.subarray(i * 3, i * 3 + 3), (i * V + v) * 3);
      for (let k = 0; k < boxIndex.length; k++) index.push(i * V + boxIndex[k]);
    }
    box.dispose();
    this.itemA = new Float32Array(n * 3);
    this.itemB = new Float32Array(n * 3);
    this.geometry = new THREE.BufferGeometry();
    this.geometry.setIndex(index);
    this.geometry.setAttribute('position', new THREE.BufferAttribute(corner, 3));
    this.attrA = new THREE.BufferAttribute(new Float32Array(n * V * 3), 3).setUsage(THREE.DynamicDrawUsage);
    this.attrB = new THREE.BufferAttribute(new Float32Array(n * V * 3), 3).setUsage(THREE.DynamicDrawUsage);
    this.geometry.setAttribute('aA', this.attrA);
    this.geometry.setAttribute('aB', this.attrB);
    this.geometry.setAttribute('aR', new THREE.BufferAttribute(r, 1));
    this.geometry.setAttribute('aColor', new THREE.BufferAttribute(rgb, 3));

    this.material = new THREE.ShaderMaterial({
      uniforms: THREE.UniformsUtils.clone(THREE.UniformsLib.fog),
      vertexShader,
      fragmentShader,
      fog: true,
      side: THREE.BackSide, // back faces: still drawn when the camera is inside a box
    });
    this.mesh = new THREE.Mesh(this.geometry, this.material);
    this.mesh.frustumCulled = false;
    this.update(motion.positions.subarray(0, J * 3));
  }

  /** Poses the figure from one frame of world positions (joints × 3). */
  update(pose: ArrayLike<number>): void {
    const A = this.itemA, B = this.itemB;
    const J = this.joints;
    for (let k = 0; k < J * 3; k++) A[k] = B[k] = pose[k];
    if (this.headSeg) {
      // The head is a big sphere centred on the head segment (Head→Head_end in BVH, upperneck→head in ASF).
      const [a, b] = this.headSeg, o = this.head * 3;
      for (let k = 0; k < 3; k++) A[o + k] = B[o + k] = (pose[a * 3 + k] + pose[b * 3 + k]) / 2;
    }
    this.bones.forEach((c, i) => {
      const a = this.parents[c], o = (J + i) * 3;
      for (let k = 0; k < 3; k++) {
        A[o + k] = pose[a * 3 + k];
        B[o + k] = pose[c * 3 + k];
      }
    });
    // Copy each item's end points to all vertices of its box.
    const VA = this.attrA.array as Float32Array, VB = this.attrB.array as Float32Array;
    const V = this.boxVerts, n = A.length / 3;
    for (let i = 0; i < n; i++) {
      const ax = A[i * 3], ay = A[i * 3 + 1], az = A[i * 3 + 2];
      const bx = B[i * 3], by = B[i * 3 + 1], bz = B[i * 3 + 2];
      for (let v = 0, o = i * V * 3; v < V; v++, o += 3) {
        VA[o] = ax; VA[o + 1] = ay; VA[o + 2] = az;
        VB[o] = bx; VB[o + 1] = by; VB[o + 2] = bz;
      }
    }
    this.attrA.needsUpdate = true;
    this.attrB.needsUpdate = true;
  }

  dispose(): void {
    this.geometry.dispose();
    this.material.dispose();
  }
}
