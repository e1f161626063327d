// The user's own character on the page (issue 40): loaded from a dropped or picked .glb/.gltf/.vrm, a URL (the
// `character` attribute and URL parameter, under the same rules as `src`: web/runtime/import/motionSource.ts), a
// Blob or an ArrayBuffer (playground.loadCharacter); drawn by the viewer in place of the mannequin in every mode,
// retargeted from the shown motion (web/motion/retarget.ts); and the exports on its skeleton. A failed load keeps
// the character (or mannequin) and the motion shown.

import { exportBVH, type BVHExportOptions } from '../motion/bvh';
import { CANONICAL_JOINTS } from '../motion/humanoid';
import { restPositions, retarget, type RetargetOptions, type RetargetResult } from '../motion/retarget';
import { quoteInput } from '../motion/text';
import type { Motion } from '../motion/types';
import { fetchSourceBytes, MAX_SOURCE_BYTES } from '../runtime/import/motionSource';
import { exportCharacterGLB } from '../viewer/characterExport';
import { disposeCharacterAsset, parseCharacter, UserCharacterDriver, type CharacterAsset } from '../viewer/userCharacter';
import type { Viewer } from '../viewer/viewer';

/** File names read as characters rather than motion. */
export const CHARACTER_FILE = /\.(glb|gltf|vrm)$/i;

const MIB = 1024 * 1024;

/** What loadCharacter resolves to (docs/api.md "Your own character"). */
export interface CharacterInfo {
  /** The file's name without its extension. */
  name: string;
  /** Bone names as the file writes them, parents before children. */
  bones: string[];
  /** Each bone's parent index in `bones` (-1 for a root). */
  parents: number[];
  /** Canonical point → the bone there (docs/api.md lists the 25 points); points the rig lacks are left out. */
  mapping: Record<string, string>;
  /** Canonical points the rig has no bone for (derived when retargeting: extra spine points, tips, toes). */
  missing: string[];
  /** Standing height in metres. */
  height: number;
  /** Where the humanoid map came from: the file's own VRM map ('vrm0', 'vrm1') or found from the skeleton ('mapped'). */
  mapSource: 'vrm0' | 'vrm1' | 'mapped';
  /** Vertices of its skinned meshes. */
  vertices: number;
  /**
   * The rest (bind) pose, per bone: local rotation [x, y, z, w] and translation [x, y, z] relative to its parent
   * (a root's relative to the scene), in the file's units; and world positions [x, y, z] in metres.
   */
  restPose: { rotations: number[][]; translations: number[][]; positions: number[][] };
}

/** Where a character comes from: a URL (string), a Blob (File) or bytes. */
export type CharacterSource = string | Blob | ArrayBuffer | ArrayBufferView;

export class CharacterInput {
  /** The character drawn for the shown motion (and the companion's, unless it has its own). */
  private main: CharacterAsset | null = null;
  /** Compare's second figure, when a second character was loaded for it. */
  private second: CharacterAsset | null = null;
  /** Bumped per load: a slower earlier load does not replace a later one. */
  private token = 0;
  /** Origins besides the page's that a character URL may come from (the element's `allowed-origins`). */
  allowedOrigins: () => readonly string[] = () => [];

  constructor(private readonly viewer: Viewer) {}

  /** The character loaded (null: the mannequin). */
  get current(): CharacterAsset | null {
    return this.main;
  }

  get info(): CharacterInfo | null {
    return this.main ? describeCharacter(this.main) : null;
  }

  /**
   * Loads a character from `source` (URL under `rules`, a Blob or bytes) and draws it for the shown motion (for
   * the companion only when `companion`). Rejects with a short reason; then nothing changes.
   */
  async load(source: CharacterSource, companion = false): Promise<CharacterInfo> {
    const token = ++this.token;
    const { bytes, name } = await readSource(source, { pageHref: location.href, allowedOrigins: this.allowedOrigins() });
    const asset = await parseCharacter(bytes, name);
    if (token !== this.token) {
      disposeCharacterAsset(asset);
      const later = new Error(`${quoteInput(name, 60)} was replaced by a later character`);
      later.name = 'SupersededError'; // the element's attribute changed again: nothing to report
      throw later;
    }
    const old = companion ? this.second : this.main;
    if (companion) this.second = asset;
    else this.main = asset;
    this.install();
    if (old && old !== this.main && old !== this.second) disposeCharacterAsset(old);
    return describeCharacter(asset);
  }

  /** Back to the mannequin (both figures). */
  clear(): void {
    const olds = [this.main, this.second];
    this.main = this.second = null;
    this.token++;
    this.viewer.setCharacterSource(null);
    for (const a of olds) if (a) disposeCharacterAsset(a);
  }

  private install(): void {
    this.viewer.setCharacterSource((motion, companion) => {
      const asset = companion ? (this.second ?? this.main) : this.main;
      if (!asset) return null;
      // Lit with a GPU (the 'high' tier), else a matcap, as the viewer does for its mannequin.
      const driver = new UserCharacterDriver(asset, { lit: this.viewer.stats().quality === 'high' });
      if (driver.setMotion(motion)) return driver;
      driver.dispose();
      return null; // this motion does not retarget onto it (not a humanoid): the mannequin or stick figure
    });
  }

  /** `motion` retargeted onto the loaded character (throws without one). */
  retarget(motion: Motion, options?: RetargetOptions): RetargetResult {
    return retarget(motion, this.need().rig, options);
  }

  /** BVH of `motion` on the character's skeleton. */
  exportBVH(motion: Motion, options: BVHExportOptions = {}): string {
    return exportBVH(this.retarget(motion).motion, options);
  }

  /** GLB of the character's mesh, skin and materials animated by `motion`. */
  exportGLB(motion: Motion, name: string): Promise<Uint8Array<ArrayBuffer>> {
    const asset = this.need();
    return exportCharacterGLB(asset, retarget(motion, asset.rig), motion.fps, name);
  }

  private need(): CharacterAsset {
    if (!this.main) throw new Error('no character is loaded (drop a .glb, .gltf or .vrm, or call loadCharacter first)');
    return this.main;
  }
}

/** The bytes of a source and the name it gives the character. */
async function readSource(source: CharacterSource, rules: { pageHref: string; allowedOrigins: readonly string[] }): Promise<{ bytes: ArrayBuffer; name: string }> {
  if (typeof source === 'string') {
    const bytes = await fetchSourceBytes(source, rules.pageHref, rules.allowedOrigins);
    return { bytes: copyOut(bytes), name: source.replace(/[?#].*$/s, '').split('/').pop() || 'character' };
  }
  if (typeof Blob !== 'undefined' && source instanceof Blob) {
    const name = (source as File).name ?? 'character';
    checkSize(source.size, name);
    return { bytes: await source.arrayBuffer(), name };
  }
  if (source instanceof ArrayBuffer) {
    checkSize(source.byteLength, 'the bytes');
    return { bytes: source, name: 'character' };
  }
  if (ArrayBuffer.isView(source)) {
    checkSize(source.byteLength, 'the bytes');
    return { bytes: copyOut(new Uint8Array(source.buffer, source.byteOffset, source.byteLength)), name: 'character' };
  }
  throw new TypeError('source must be a URL string, a Blob (File) or an ArrayBuffer');
}

function checkSize(bytes: number, what: string): void {
  if (bytes > MAX_SOURCE_BYTES) throw new Error(`${quoteInput(what, 60)} is ${(bytes / MIB).toFixed(1)} MiB; the limit is ${MAX_SOURCE_BYTES / MIB} MiB`);
}

function copyOut(bytes: Uint8Array): ArrayBuffer {
  return bytes.slice().buffer as ArrayBuffer;
}

export function describeCharacter(asset: CharacterAsset): CharacterInfo {
  const { rig, mapping } = asset;
  const named: Record<string, string> = {};
  const missing: string[] = [];
  CANONICAL_JOINTS.forEach((point, k) => {
    const bone = mapping.source[k];
    if (bone >= 0) named[point] = asset.boneNames[bone];
    else missing.push(point);
  });
  const world = restPositions(rig);
  const round = (v: number) => +v.toFixed(6);
  return {
    name: asset.name,
    bones: [...asset.boneNames],
    parents: [...rig.parents],
    mapping: named,
    missing,
    height: +asset.height.toFixed(4),
    mapSource: asset.mapSource,
    vertices: asset.vertexCount,
    restPose: {
      rotations: rig.restRotations.map((q) => q.map(round)),
      translations: rig.restTranslations.map((t) => t.map(round)),
      positions: rig.bones.map((_, k) => [0, 1, 2].map((i) => round(world[k * 3 + i] / asset.unitsPerMetre))),
    },
  };
}
