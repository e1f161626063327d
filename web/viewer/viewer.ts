// The three.js viewer: scene, orbit camera (optionally following the root), time-based playback with
// interpolation between frames, and the ground decorations (trail, footprints, blob shadow).

import * as THREE from 'three';
import './palette'; // first: sets up colour handling
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import type { Motion } from '../motion/types';
import { Figure } from './figure';
import { CharacterDriver } from './character';
import type { CharacterView } from './userCharacter';
import { DEFAULT_LOOK, type Look } from './look';
import { COMPANION_MANNEQUIN_COLORS, restMannequin } from './mannequin';
import { BACKGROUND, BlobShadow, Floor, FloorGlow, GroundMarks } from './ground';
import { COMPANION_PALETTE } from './palette';
import { Playback, type PlaybackState } from './playback';
import { chooseQuality, DynamicResolution, fixedResolution, probeGL, type GLInfo, type Quality } from './quality';

/** The ground, y = 0 (pointer picks land on it). */
const GROUND_PLANE = new THREE.Plane(new THREE.Vector3(0, 1, 0), 0);

/**
 * The part of the stage the UI's overlays (top bar, cards, the control panel) leave free, as insets in CSS
 * pixels from the stage's edges: framings keep the figure inside it.
 */
export interface FreeArea {
  top: number;
  right: number;
  bottom: number;
  left: number;
}

export interface ViewerLayers {
  follow: boolean;
  trail: boolean;
  footprints: boolean;
}

export interface RenderStats {
  /** Smoothed display frame rate. */
  fps: number;
  /** Device pixels per CSS pixel currently rendered (dynamic resolution). */
  pixelRatio: number;
  quality: Quality;
  /** WebGL renderer string, e.g. "ANGLE (Google, Vulkan 1.3.0 (SwiftShader Device …))". */
  renderer: string;
  software: boolean;
  /** The look chosen: the stick figure, the character, or both. */
  look: Look;
  /** Vertices of the character drawn now (0: none drawn, the look is 'skeleton' or the skeleton does not map to a humanoid). */
  characterVertices: number;
  /** Vertices of the companion's character drawn now (Compare's second figure; 0: none). */
  companionVertices: number;
}

/** How far (m) a companion figure is drawn beside the main one, towards the left of the screen. */
export const COMPANION_OFFSET = 1.2;

/** A second figure playing the same frames as the main motion beside it (Random walk's side-by-side view). */
export interface Companion {
  /** Same frame count and joints as the shown motion. */
  motion: Motion;
  /** Labels drawn above the two figures' heads. */
  labels: { main: string; companion: string };
}

/** The GPU probe, made once for the page (each probe costs a WebGL context of its own). */
let probed: GLInfo | null = null;

/** How far outside the viewport (CSS px) an element keeps its WebGL context. */
const CONTEXT_MARGIN = '200px';

/**
 * The WebGL context's state. A viewer holds a context only while it is near the viewport (browsers keep about 16
 * per page and drop the oldest beyond that): 'none' until first seen; 'releasing'/'released' while out of view
 * (lost on purpose through WEBGL_lose_context); 'restoring' on its way back; 'lost' when the browser took it;
 * 'failed' when none could be made.
 */
type ContextState = 'none' | 'live' | 'releasing' | 'released' | 'restoring' | 'lost' | 'failed';

export class Viewer {
  /** The canvas drawn on (kept for the viewer's life; its WebGL context comes and goes with visibility). */
  readonly canvas: HTMLCanvasElement;
  readonly scene = new THREE.Scene();
  readonly camera = new THREE.PerspectiveCamera(38, 1, 0.1, 200);
  readonly controls: OrbitControls;
  readonly playback = new Playback();
  /** Called after every rendered frame (for the UI's time display). */
  onFrame: ((s: PlaybackState) => void) | null = null;
  /** Smoothed display frame rate, for the UI. */
  displayFps = 0;

  private readonly floor: Floor;
  /** Beyond its far distance everything is the background colour. */
  private readonly fog: THREE.Fog;
  private readonly glow = new FloorGlow();
  private readonly marks = new GroundMarks();
  private figure: Figure | null = null;
  /** The shown motion as the mannequin; null when its skeleton does not map to the canonical one. */
  private character: CharacterView | null = null;
  /** A user's own character (userCharacter.ts) drawn instead of the mannequin: set by setCharacterSource. */
  private characterSource: ((motion: Motion, companion: boolean) => CharacterView | null) | null = null;
  /** The views characterSource made (a user's character), as against the mannequin drawn when it made none. */
  private readonly ownCharacters = new WeakSet<CharacterView>();
  private look: Look = DEFAULT_LOOK;
  private readonly lights: CharacterLights;
  /**
   * The character is lit by the scene's lights and casts a shadow map on the ground (with a GPU); under software
   * GL it is shaded by a baked studio matcap and has the blob shadow only, as the stick figure (every lit pixel
   * and the shadow pass cost frames there).
   */
  private readonly lit: boolean;
  private motion: Motion | null = null;
  private companion: { motion: Motion; figure: Figure; character: CharacterView | null; pose: Float32Array; dx: number; dz: number; labels: HTMLElement[] } | null = null;
  private readonly companionShadow = new BlobShadow();
  private pose = new Float32Array(0);
  private root = 0;
  private targetY = 0.9;
  private figureHeight = 1.7;
  private follow = true;
  /** Where the UI's overlays leave the stage free (setFreeAreaSource), asked at each framing. */
  private freeAreaSource: (() => FreeArea) | null = null;
  /** The world points the last framing fitted into the free area (lowerView fits them again). */
  private fitted: THREE.Vector3[] = [];
  /** Showing a live window of streamed frames (setLive) rather than a clip. */
  private live = false;
  private snap = true;
  private last = 0;
  /** Something changed since the last render. */
  private dirty = true;
  private renderedLast = false;
  private readonly tmp = new THREE.Vector3();
  private readonly raycaster = new THREE.Raycaster();
  private readonly gl: GLInfo;
  private readonly quality: Quality;
  private readonly basePixelRatio: number;
  private readonly resolution: DynamicResolution;
  private webgl: THREE.WebGLRenderer | null = null;
  private contextState: ContextState = 'none';
  /** A loss the browser caused was reported (onContextLost): its restoring is reported too. */
  private lossReported = false;
  private loser: WEBGL_lose_context | null = null;
  /** Near the viewport (CONTEXT_MARGIN): only then is a WebGL context held and the scene drawn. */
  private visible = false;
  private running = false;
  private frameRequest = 0;
  private disposed = false;
  private readonly resizeObserver: ResizeObserver;
  private readonly visibility: IntersectionObserver | null = null;
  /** The browser took the context (or none could be made): `reason` says so in a few words. */
  onContextLost: ((reason: string) => void) | null = null;
  /** A context lost by the browser came back (drawing again). */
  onContextRestored: (() => void) | null = null;

  constructor(private readonly container: HTMLElement) {
    this.gl = probed ??= probeGL();
    this.quality = chooseQuality(this.gl);
    const high = this.quality === 'high';
    this.lit = high;
    this.basePixelRatio = high ? Math.min(window.devicePixelRatio || 1, 2) : 1;
    this.resolution = new DynamicResolution(0.5, 1, high ? 1 : 0.75, fixedResolution());
    this.canvas = document.createElement('canvas');
    this.canvas.addEventListener('webglcontextlost', (e) => this.contextLost(e));
    this.canvas.addEventListener('webglcontextrestored', () => this.contextRestored());
    this.scene.background = BACKGROUND;
    // A GPU can afford a wider grid reaching further before the fog; software GL gets a smaller stage.
    this.floor = new Floor(high ? 24 : 12);
    this.fog = high ? new THREE.Fog(BACKGROUND, 8, 26) : new THREE.Fog(BACKGROUND, 5, 14);
    this.scene.fog = this.fog;
    this.canvas.classList.add('viewer-canvas');
    container.appendChild(this.canvas);

    // The stick figure shades itself (figure.ts) and the ground layers are unlit; the lights are the character's.
    // The floor glow is a large filled area: only worth its pixels with a GPU.
    if (high) this.scene.add(this.glow.mesh);
    this.scene.add(this.floor.group, this.marks.mesh, this.companionShadow.mesh);
    this.lights = new CharacterLights(this.camera);
    this.scene.add(this.lights.group);

    this.camera.position.set(3.2, 1.9, 4.6);
    this.controls = new OrbitControls(this.camera, this.canvas);
    this.controls.target.set(0, 0.9, 0);
    this.controls.enableDamping = true;
    this.controls.dampingFactor = 0.12;
    this.controls.minDistance = 0.5;
    this.controls.maxDistance = 60;
    this.controls.maxPolarAngle = Math.PI * 0.495; // stay above the floor
    this.controls.update();

    this.resizeObserver = new ResizeObserver(() => this.resize());
    this.resizeObserver.observe(container);
    if ('IntersectionObserver' in window) {
      this.visibility = new IntersectionObserver((entries) => this.setVisible(entries[entries.length - 1].isIntersecting), { rootMargin: CONTEXT_MARGIN });
      this.visibility.observe(container);
    } else {
      this.setVisible(true);
    }
    this.resize();
    this.setRunning(true);
  }

  /**
   * The three.js renderer, made on first use (a viewer makes its WebGL context when it first comes near the
   * viewport). Throws when no WebGL context can be made.
   */
  get renderer(): THREE.WebGLRenderer {
    if (this.webgl) return this.webgl;
    const high = this.quality === 'high';
    let renderer: THREE.WebGLRenderer;
    try {
      renderer = new THREE.WebGLRenderer({ canvas: this.canvas, antialias: high, alpha: false, powerPreference: 'high-performance' });
    } catch (e) {
      if (this.contextState !== 'failed') {
        this.contextState = 'failed';
        this.onContextLost?.(`WebGL: no context could be made (${e instanceof Error ? e.message : String(e)})`);
      }
      throw e;
    }
    this.webgl = renderer;
    // Kept from the start: a context already lost gives out no extensions (three.js asks only when told to).
    this.loser = renderer.getContext().getExtension('WEBGL_lose_context');
    this.contextState = 'live';
    renderer.setPixelRatio(this.basePixelRatio * this.resolution.scale);
    renderer.outputColorSpace = THREE.LinearSRGBColorSpace; // colours are used as given (see palette.ts)
    renderer.shadowMap.enabled = this.lit; // the character's shadow on the ground (CharacterLights)
    renderer.shadowMap.type = THREE.PCFSoftShadowMap;
    this.resize();
    // Compile the figure's shader while the page waits for its first motion (models loading), not in the
    // frame that first draws one: under software GL that compile costs tens of milliseconds.
    const idle = (globalThis.requestIdleCallback as ((cb: () => void, o?: { timeout: number }) => number) | undefined) ?? ((cb: () => void) => setTimeout(cb, 50));
    idle(() => this.compileFigureShader(), { timeout: 500 });
    return renderer;
  }

  /** Whether the viewer holds a live WebGL context now (near the viewport, not lost). */
  get hasContext(): boolean {
    return this.contextState === 'live';
  }

  /** Near the viewport: make (or get back) the WebGL context; away from it: let it go, so others can have one. */
  private setVisible(visible: boolean): void {
    if (this.disposed || visible === this.visible) return;
    this.visible = visible;
    this.dirty = true;
    if (visible) {
      if (this.contextState === 'none') {
        try {
          void this.renderer;
        } catch {
          // reported through onContextLost
        }
      } else if (this.contextState === 'released' || this.contextState === 'lost') {
        // (A context the browser took, e.g. the oldest of too many, is asked back when its element is seen again.)
        this.contextState = 'restoring';
        this.loser?.restoreContext();
      }
      // 'releasing': restored once the loss arrives (contextLost); 'restoring' and 'live': nothing to do.
    } else if (this.contextState === 'live') {
      this.contextState = 'releasing';
      this.loser?.loseContext();
    }
  }

  private contextLost(e: Event): void {
    e.preventDefault(); // (three.js does too) so that the context can be restored
    if (this.disposed) return;
    if (this.contextState === 'releasing') {
      this.contextState = 'released';
      if (this.visible) {
        this.contextState = 'restoring';
        this.loser?.restoreContext();
      }
      return;
    }
    this.contextState = 'lost';
    this.lossReported = true;
    this.onContextLost?.('WebGL: the context was lost (too many on the page, or the GPU was reset)');
  }

  private contextRestored(): void {
    if (this.disposed) return;
    const wasLost = this.lossReported;
    this.lossReported = false;
    this.contextState = 'live';
    this.dirty = true;
    this.resize();
    if (!this.visible) {
      this.contextState = 'releasing';
      this.loser?.loseContext();
    }
    if (wasLost) this.onContextRestored?.();
  }

  /**
   * Stops everything for good (its element was taken off the page): the frame loop, the observers, the camera
   * controls' listeners, every geometry, material and texture, and the WebGL context (lost at once, so the
   * browser frees it rather than waiting for garbage collection).
   */
  dispose(): void {
    if (this.disposed) return;
    this.setRunning(false);
    this.disposed = true;
    this.resizeObserver.disconnect();
    this.visibility?.disconnect();
    this.controls.dispose();
    this.setCompanion(null);
    this.removeFigures(); // (the character's skeleton holds a bone texture that the traversal below would not find)
    const textures = new Set<THREE.Texture>();
    this.scene.traverse((object) => {
      const mesh = object as THREE.Mesh;
      mesh.geometry?.dispose();
      const materials = Array.isArray(mesh.material) ? mesh.material : mesh.material ? [mesh.material] : [];
      for (const material of materials) {
        for (const value of Object.values(material)) if (value instanceof THREE.Texture) textures.add(value);
        material.dispose();
      }
    });
    for (const texture of textures) texture.dispose();
    this.figure = null;
    this.character = null;
    this.scene.clear();
    if (this.webgl) {
      this.webgl.dispose();
      if (this.contextState === 'live' || this.contextState === 'restoring') this.loser?.loseContext();
      this.webgl = null;
    }
    this.contextState = 'released';
    this.canvas.remove();
  }

  /**
   * Compiles the figure's program on a hidden stand-in figure that stays in the scene (three.js frees a program
   * once no material uses it; every Figure's material shares this one's program).
   */
  private compileFigureShader(): void {
    if (this.figure || this.contextState !== 'live') return;
    const standIn = new Figure({ fps: 30, frames: 1, joints: ['Hips', 'Head'], parents: [-1, 0], positions: new Float32Array([0, 1, 0, 0, 1.5, 0]) });
    this.scene.add(standIn.mesh);
    // The character's program too (a lit, skinned, shadowed material: the slowest to compile).
    const mannequin = restMannequin({ lit: this.lit });
    this.scene.add(mannequin.mesh);
    this.renderer.compile(this.scene, this.camera);
    standIn.mesh.visible = false;
    mannequin.mesh.visible = false;
  }

  /** Starts or stops the frame loop (an element taken off the page draws nothing and costs nothing). */
  setRunning(running: boolean): void {
    if (this.disposed) return;
    this.last = performance.now();
    this.running = running;
    cancelAnimationFrame(this.frameRequest);
    this.frameRequest = running ? requestAnimationFrame(this.loop) : 0;
  }

  private readonly loop = (now: number): void => {
    if (!this.running) return;
    this.frameRequest = requestAnimationFrame(this.loop);
    this.tick(now);
  };

  get current(): Motion | null {
    return this.motion;
  }

  /** Shows a motion (already validated) from its first frame, playing. */
  setMotion(motion: Motion, contacts: Uint8Array | undefined): void {
    const J = motion.joints.length;
    this.setCompanion(null);
    const figure = new Figure(motion);
    this.removeFigures();
    this.figure = figure;
    this.scene.add(figure.mesh);
    this.character = this.characterFor(motion, false);
    if (this.character) this.scene.add(this.character.mannequin.mesh);
    this.showLook();
    this.motion = motion;
    this.pose = new Float32Array(J * 3);
    this.root = Math.max(0, motion.parents.indexOf(-1));

    // Camera height: around the hips, from the clip's mean root height; figure size from frame 0.
    let sumY = 0;
    for (let f = 0; f < motion.frames; f++) sumY += motion.positions[(f * J + this.root) * 3 + 1];
    const meanRootY = sumY / motion.frames;
    let minY = Infinity, maxY = -Infinity;
    for (let j = 0; j < J; j++) {
      const y = motion.positions[j * 3 + 1];
      minY = Math.min(minY, y);
      maxY = Math.max(maxY, y);
    }
    this.figureHeight = Math.min(Math.max(maxY - minY, 0.5), 3);
    this.targetY = Math.min(Math.max(meanRootY * 0.72, 0.25), 2); // a bit low: the figure sits above the playback bar

    this.marks.build(motion, contacts, this.root);
    this.live = false;
    this.playback.hold = false;
    this.playback.reset(motion.frames, motion.fps);
    this.playback.playing = true;
    this.applyPose();
    this.frameCharacter();
  }

  /**
   * Shows a live window of a streamed motion: the first call starts it like `setMotion`; later calls
   * replace the window without moving the camera, where `dropped` frames were removed from its start
   * (the playhead stays on the same frame); `dropped` < 0 starts a new stream. Playback waits at the newest frame instead of looping.
   */
  setLive(motion: Motion, contacts: Uint8Array | undefined, dropped: number): void {
    const same = dropped >= 0 && this.live && this.motion !== null && this.motion.joints.length === motion.joints.length;
    if (!same) {
      this.setMotion(motion, contacts);
      this.live = true;
      this.playback.hold = true;
      return;
    }
    const time = this.playback.time - dropped / this.playback.fps;
    this.motion = motion;
    if (this.character && !this.character.setMotion(motion)) {
      this.scene.remove(this.character.mannequin.mesh);
      this.character.dispose();
      this.character = null;
      this.showLook();
    }
    this.retryOwnCharacter(motion);
    this.marks.build(motion, contacts, this.root);
    this.playback.frames = motion.frames;
    this.playback.fps = motion.fps;
    this.playback.time = Math.min(Math.max(time, 0), this.playback.duration);
    this.applyPose();
  }

  /**
   * Draws `companion` beside the shown motion, in step with it (null removes it). It keeps its side offset
   * (COMPANION_OFFSET towards the screen's left, chosen from the camera when it first appears) until removed
   * or a new motion is shown; with it the camera follows the midpoint of the two. Call again after every
   * setLive with the companion's window of the same frames.
   */
  setCompanion(companion: Companion | null): void {
    if (!companion) {
      if (this.companion) {
        this.scene.remove(this.companion.figure.mesh);
        this.companion.figure.dispose();
        if (this.companion.character) {
          this.scene.remove(this.companion.character.mannequin.mesh);
          this.companion.character.dispose();
        }
        this.companion.labels.forEach((l) => l.remove());
        this.companion = null;
        this.companionShadow.mesh.visible = false;
        this.dirty = true;
      }
      return;
    }
    const m = this.motion;
    if (!m || companion.motion.frames !== m.frames || companion.motion.joints.length !== m.joints.length) {
      throw new Error(`setCompanion: the companion (${companion.motion.frames} frames) must match the shown motion (${m?.frames ?? 0} frames, same joints)`);
    }
    if (!this.companion) {
      const figure = new Figure(companion.motion, COMPANION_PALETTE);
      this.scene.add(figure.mesh);
      const character = this.characterFor(companion.motion, true);
      if (character) this.scene.add(character.mannequin.mesh);
      // Offset towards the screen's left: minus the camera's horizontal right vector (−dz, dx of the view direction).
      const vx = this.controls.target.x - this.camera.position.x, vz = this.controls.target.z - this.camera.position.z;
      const l = Math.hypot(vx, vz) || 1;
      const labels = ['main', 'companion'].map((kind) => {
        const el = document.createElement('div');
        el.className = `figure-label figure-label-${kind}`;
        this.container.appendChild(el);
        return el;
      });
      this.companion = { motion: companion.motion, figure, character, pose: new Float32Array(m.joints.length * 3), dx: (vz / l) * COMPANION_OFFSET, dz: (-vx / l) * COMPANION_OFFSET, labels };
      this.companionShadow.mesh.visible = true;
      this.companion.labels[0].textContent = companion.labels.main;
      this.companion.labels[1].textContent = companion.labels.companion;
      this.showLook();
      this.applyPose();
      this.frameCharacter(); // both in view, a little further back
      return;
    }
    this.companion.motion = companion.motion;
    const c = this.companion;
    if (c.character && !c.character.setMotion(companion.motion)) {
      this.scene.remove(c.character.mannequin.mesh);
      c.character.dispose();
      c.character = null;
      this.showLook();
    }
    this.applyPose();
  }

  /** Removes the motion: an empty stage. */
  clear(): void {
    this.setCompanion(null);
    this.removeFigures();
    this.motion = null;
    this.showLook();
    this.live = false;
    this.playback.hold = false;
    this.playback.reset(0, 30);
    this.playback.playing = false;
    this.marks.mesh.visible = false;
    this.dirty = true;
  }

  play(): void { if (this.motion) this.playback.playing = true; }
  pause(): void { this.playback.playing = false; }
  toggle(): void { if (this.playback.playing) this.pause(); else this.play(); }

  seek(frame: number): void {
    if (!this.motion) return;
    this.playback.seek(frame);
    this.applyPose();
    this.snap = true;
  }

  /** Pauses and moves by whole frames. */
  step(delta: number): void {
    if (!this.motion) return;
    this.pause();
    this.seek(Math.round(this.playback.frameFloat) + delta);
  }

  setSpeed(x: number): number { return this.playback.setSpeed(x); }

  state(): PlaybackState { return this.playback.state(); }

  stats(): RenderStats {
    return {
      fps: this.displayFps,
      pixelRatio: this.basePixelRatio * this.resolution.scale,
      quality: this.quality,
      renderer: this.gl.renderer,
      software: this.gl.software,
      look: this.look,
      characterVertices: this.character && this.look !== 'skeleton' ? this.character.mannequin.vertexCount : 0,
      companionVertices: this.companion?.character && this.look !== 'skeleton' ? this.companion.character.mannequin.vertexCount : 0,
    };
  }

  /** The look chosen (what is drawn for a motion whose skeleton maps to a humanoid; others always get the stick figure). */
  get currentLook(): Look {
    return this.look;
  }

  /** Draws the stick figure, the character, or both (the character see-through, the skeleton inside it). */
  setLook(look: Look): void {
    this.look = look;
    this.showLook();
  }

  /** The character drawn for a motion: the user's own when one is set (and it retargets), else the mannequin. */
  private characterFor(motion: Motion, companion: boolean): CharacterView | null {
    const own = this.characterSource?.(motion, companion) ?? null;
    if (own) {
      this.ownCharacters.add(own);
      return own;
    }
    return companion ? CharacterDriver.for(motion, { colors: COMPANION_MANNEQUIN_COLORS, lit: this.lit }) : CharacterDriver.for(motion, { lit: this.lit });
  }

  /**
   * A live stream whose earlier window did not retarget onto the user's character (the mannequin or nothing drawn in
   * its place) tries it again on each new window: a dance's first second with a foot held high may not map as a
   * humanoid, a longer window does, and the user's character should not be lost for the rest of the stream.
   */
  private retryOwnCharacter(motion: Motion): void {
    if (!this.characterSource || (this.character && this.ownCharacters.has(this.character))) return;
    const own = this.characterSource(motion, false);
    if (!own) return;
    if (this.character) {
      this.scene.remove(this.character.mannequin.mesh);
      this.character.dispose();
    }
    this.ownCharacters.add(own);
    this.character = own;
    this.scene.add(own.mannequin.mesh);
    this.showLook();
  }

  /**
   * Draws a user's own character instead of the mannequin (null: the mannequin again): `source` makes one for a
   * motion (the companion's when `companion`), or returns null to leave the mannequin. The shown figures are rebuilt.
   */
  setCharacterSource(source: ((motion: Motion, companion: boolean) => CharacterView | null) | null): void {
    this.characterSource = source;
    const swap = (old: CharacterView | null, motion: Motion | null, companion: boolean): CharacterView | null => {
      if (old) {
        this.scene.remove(old.mannequin.mesh);
        old.dispose();
      }
      const made = motion && motion.frames > 0 ? this.characterFor(motion, companion) : null;
      if (made) this.scene.add(made.mannequin.mesh);
      return made;
    };
    this.character = swap(this.character, this.motion, false);
    if (this.companion) this.companion.character = swap(this.companion.character, this.companion.motion, true);
    this.showLook();
    this.applyPose();
  }

  /** The character drawn for the shown motion and for the companion (null: none, or the look hides it). */
  get characters(): { main: CharacterView | null; companion: CharacterView | null } {
    return { main: this.character, companion: this.companion?.character ?? null };
  }

  /** The figures' visibility for the look: the stick figure wherever there is no character. */
  private showLook(): void {
    const pairs: Array<[Figure | null, CharacterView | null]> = [[this.figure, this.character]];
    if (this.companion) pairs.push([this.companion.figure, this.companion.character]);
    for (const [figure, character] of pairs) {
      if (figure) figure.mesh.visible = this.look !== 'character' || !character;
      if (character) {
        character.mannequin.mesh.visible = this.look !== 'skeleton';
        character.mannequin.setSeeThrough(this.look === 'both');
      }
    }
    this.lights.setShadows(this.lit && this.look !== 'skeleton' && this.character !== null);
    this.dirty = true;
  }

  private removeFigures(): void {
    if (this.figure) {
      this.scene.remove(this.figure.mesh);
      this.figure.dispose();
    }
    if (this.character) {
      this.scene.remove(this.character.mannequin.mesh);
      this.character.dispose();
    }
    this.figure = null;
    this.character = null;
  }

  layers(): ViewerLayers {
    return { follow: this.follow, ...this.marks.layers() };
  }

  setLayers(l: Partial<ViewerLayers>): void {
    if (l.follow !== undefined) { this.follow = l.follow; if (l.follow) this.snap = false; }
    this.marks.setLayers(l);
    this.dirty = true;
  }

  /** Number of footprints placed for the shown motion. */
  get footprintCount(): number { return this.marks.footprintCount; }

  /** Puts the camera at a three-quarter view of the figure, looking across its direction of travel. */
  frameCharacter(): void {
    if (!this.motion) return;
    const m = this.motion;
    const J = m.joints.length;
    const P = m.positions;
    // Direction of travel around the current frame (±1 s), else over the whole clip, else +z.
    const f = this.playback.frame, w = Math.round(m.fps);
    const dir = (a: number, b: number) => {
      const r0 = (a * J + this.root) * 3, r1 = (b * J + this.root) * 3;
      return [P[r1] - P[r0], P[r1 + 2] - P[r0 + 2]];
    };
    let [dx, dz] = dir(Math.max(0, f - w), Math.min(m.frames - 1, f + w));
    if (Math.hypot(dx, dz) < 0.3) [dx, dz] = dir(0, m.frames - 1);
    const l = Math.hypot(dx, dz);
    if (l < 0.3) { dx = 0; dz = 1; } else { dx /= l; dz /= l; }
    // Look across the direction of travel, a little from the front: the walk crosses the screen with
    // its trail and footprints on either side of the figure.
    const a = (62 * Math.PI) / 180;
    const cx = dx * Math.cos(a) + dz * Math.sin(a), cz = -dx * Math.sin(a) + dz * Math.cos(a);
    const dist = this.figureHeight * (this.companion ? 3.3 : 2.8);
    const root = this.followPoint();
    this.controls.target.set(root.x, this.targetY, root.z);
    this.camera.position.set(root.x + cx * dist, this.targetY + dist * 0.42, root.z + cz * dist);
    this.snap = true;
    this.controls.update();
    this.fitFreeArea(this.figurePoints());
    this.dirty = true;
  }

  /** Fits the whole root trajectory in view (and stops following the root). */
  frameAll(): void {
    if (this.motion) this.frameGround([]);
  }

  /**
   * Fits ground points (x, z pairs) and the shown root trajectory in view, seen from at least
   * `minElevation` (the view direction's least y before normalising), and stops following the root. Works with
   * nothing shown (Path mode's drawing view).
   */
  frameGround(xz: ArrayLike<number>, minElevation = 0.35): void {
    const box = new THREE.Box3();
    for (let i = 0; i + 1 < xz.length; i += 2) box.expandByPoint(this.tmp.set(xz[i], 0, xz[i + 1]));
    const m = this.motion;
    if (m) {
      const J = m.joints.length;
      for (let f = 0; f < m.frames; f++) {
        const o = (f * J + this.root) * 3;
        box.expandByPoint(this.tmp.set(m.positions[o], 0, m.positions[o + 2]));
      }
    }
    if (box.isEmpty()) return;
    box.expandByScalar(0.6);
    box.max.y = this.figureHeight;
    const center = box.getCenter(new THREE.Vector3());
    const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1.5);
    const dist = radius / Math.sin(THREE.MathUtils.degToRad(this.camera.fov / 2)) * 0.9;
    const dir = this.camera.position.clone().sub(this.controls.target).normalize();
    if (dir.y < minElevation) { dir.y = minElevation; dir.normalize(); }
    this.follow = false;
    this.controls.target.copy(center).setY(this.targetY * 0.6);
    this.camera.position.copy(this.controls.target).addScaledVector(dir, dist);
    this.controls.update();
    // The ground points and the root's track fitted (without the margin added above), a figure's height over each.
    const track: THREE.Vector3[] = [];
    const stride = Math.max(1, Math.floor(xz.length / 2 / 40));
    for (let i = 0; i + 1 < xz.length; i += 2 * stride) track.push(new THREE.Vector3(xz[i], 0, xz[i + 1]));
    if (m) {
      const J = m.joints.length, every = Math.max(1, Math.floor(m.frames / 40));
      for (let f = 0; f < m.frames; f += every) track.push(new THREE.Vector3(m.positions[(f * J + this.root) * 3], 0, m.positions[(f * J + this.root) * 3 + 2]));
    }
    for (const q of track.slice()) track.push(q.clone().setY(this.figureHeight));
    this.fitFreeArea(track);
    this.dirty = true;
  }

  // ---------- a mode's camera work (the modes hold no three.js objects of their own) ----------

  /**
   * The ground point (x, z) under a pointer at client coordinates, or null: the sky, or a hit further than
   * `maxReach` metres from the view's centre (rays grazing the horizon).
   */
  groundAt(clientX: number, clientY: number, maxReach = 80): [number, number] | null {
    const rect = this.canvas.getBoundingClientRect();
    const ndc = new THREE.Vector2(((clientX - rect.left) / rect.width) * 2 - 1, -((clientY - rect.top) / rect.height) * 2 + 1);
    this.raycaster.setFromCamera(ndc, this.camera);
    const hit = this.raycaster.ray.intersectPlane(GROUND_PLANE, new THREE.Vector3());
    if (!hit) return null;
    const t = this.controls.target;
    if (Math.hypot(hit.x - t.x, hit.z - t.z) > maxReach) return null;
    return [hit.x, hit.z];
  }

  /** Whether a right-button drag turns the view (a mode that draws with the left button) or pans it (the default). */
  setRightDragRotates(rotates: boolean): void {
    this.controls.mouseButtons.RIGHT = rotates ? THREE.MOUSE.ROTATE : THREE.MOUSE.PAN;
  }

  /**
   * Looks down at ground point (x, z) from `distance` metres, `rise` the view direction's y before
   * normalising, keeping the camera's compass direction; stops following the root.
   */
  lookAtGround(x: number, z: number, distance: number, rise: number): void {
    const dir = this.camera.position.clone().sub(this.controls.target).setY(0);
    if (dir.lengthSq() < 1e-6) dir.set(0.6, 0, 0.8);
    dir.normalize().setY(rise).normalize();
    this.setLayers({ follow: false });
    this.controls.target.set(x, 0, z);
    this.camera.position.copy(this.controls.target).addScaledVector(dir, distance);
    this.controls.update();
    this.dirty = true;
  }

  /** Moves the view down by `share` of the camera's distance (the framed content then sits higher on screen). */
  lowerView(share: number): void {
    const drop = this.camera.position.distanceTo(this.controls.target) * share;
    this.controls.target.y -= drop;
    this.camera.position.y -= drop;
    this.controls.update();
    this.fitFreeArea(this.fitted);
    this.dirty = true;
  }

  /**
   * Where the UI's overlays leave the stage free (null: all of it), asked at every framing: where the
   * figure framed by `frameCharacter`, `frameGround` or `lowerView` would reach under an overlay (a
   * phone's tall, narrow stage), the view backs off and its centre moves to the free area's centre.
   */
  setFreeAreaSource(source: (() => FreeArea) | null): void {
    this.freeAreaSource = source;
  }

  /**
   * After a framing: if `points` (world) do not all project inside the free area, moves the
   * view's centre (the projection's principal point, kept while following and orbiting) to put their box at
   * the free area's centre and backs the camera off from its target until the box fits with a margin. Points
   * that already fit leave the framing as it is (a desktop's stage).
   */
  private fitFreeArea(points: THREE.Vector3[]): void {
    this.fitted = points;
    this.camera.clearViewOffset();
    const w = this.container.clientWidth, h = this.container.clientHeight;
    const area = this.freeAreaSource?.();
    if (!area || !points.length || w < 2 || h < 2) return;
    const free = { left: area.left, top: area.top, right: w - area.right, bottom: h - area.bottom };
    const freeW = free.right - free.left, freeH = free.bottom - free.top;
    if (freeW < 40 || freeH < 40) return; // no room worth fitting into: keep the plain framing
    // Margins for what moves after the framing: a walk turning, a pair's spacing seen from another angle, a
    // panel that grows a line once its stream runs.
    const marginX = 0.1 * freeW, marginY = 0.08 * freeH;
    const p = new THREE.Vector3();
    const bounds = () => {
      this.camera.updateMatrixWorld();
      let x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
      for (const q of points) {
        p.copy(q).project(this.camera);
        const x = ((p.x + 1) / 2) * w, y = ((1 - p.y) / 2) * h;
        x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y);
      }
      return { x0, x1, y0, y1 };
    };
    const b = bounds();
    // Inside the free area: left as framed. Otherwise fitted with a margin (so a small change doesn't refit).
    if (b.x0 >= free.left && b.x1 <= free.right && b.y0 >= free.top && b.y1 <= free.bottom) return;
    // Projected size goes nearly as 1 / distance and the view offset moves the picture by whole pixels:
    // a few rounds settle both.
    let offX = 0, offY = 0;
    for (let round = 0; round < 6; round++) {
      const { x0, x1, y0, y1 } = bounds();
      if (!Number.isFinite(x0 + x1 + y0 + y1)) break;
      const scale = Math.max((x1 - x0) / (freeW - 2 * marginX), (y1 - y0) / (freeH - 2 * marginY));
      offX -= (free.left + free.right) / 2 - (x0 + x1) / 2;
      offY -= (free.top + free.bottom) / 2 - (y0 + y1) / 2;
      this.camera.setViewOffset(w, h, offX, offY, w, h);
      if (scale > 1.001) {
        const t = this.controls.target;
        this.camera.position.sub(t).multiplyScalar(Math.min(scale, 4)).add(t);
      } else if (Math.abs((free.top + free.bottom) / 2 - (y0 + y1) / 2) < 1) break;
    }
    this.controls.update();
  }

  /**
   * Points that bound each shown figure from the playhead on: its joints, with its mesh's reach above and
   * below them, and an upright cylinder around its root as tall as the figure stands, wide enough for its
   * limbs as it turns and moves (a crouch in a dance rises again; the camera follows the root).
   */
  private figurePoints(): THREE.Vector3[] {
    const out: THREE.Vector3[] = [];
    if (!this.motion) return out;
    const poses = this.companion ? [this.pose, this.companion.pose] : [this.pose];
    const radius = 0.3 * this.figureHeight, top = this.figureHeight + 0.15;
    for (const pose of poses) {
      if (pose.length < 3) continue;
      for (let k = 0; k + 2 < pose.length; k += 3) {
        const [x, y, z] = [pose[k], pose[k + 1], pose[k + 2]];
        out.push(new THREE.Vector3(x, y + 0.15, z), new THREE.Vector3(x, Math.max(0, y - 0.1), z));
      }
      const r = this.root * 3;
      for (let i = 0; i < 8; i++) {
        const x = pose[r] + radius * Math.cos((i * Math.PI) / 4), z = pose[r + 2] + radius * Math.sin((i * Math.PI) / 4);
        out.push(new THREE.Vector3(x, 0, z), new THREE.Vector3(x, top, z));
      }
    }
    return out;
  }

  /** Puts the camera `distance` metres behind a character facing `heading` (rad), turned `side` rad toward its side, `rise` up. */
  placeBehind(heading: number, side: number, distance: number, rise: number): void {
    const a = heading + Math.PI + side;
    const l = Math.hypot(1, rise);
    const t = this.controls.target;
    this.camera.position.set(t.x + (Math.sin(a) / l) * distance, t.y + (rise / l) * distance, t.z + (Math.cos(a) / l) * distance);
    this.controls.update();
    this.dirty = true;
  }

  /** Swings the camera's compass direction a `share` (0…1) of the way toward behind `heading` (turned `side` rad), about the view's centre. */
  swingBehind(heading: number, side: number, share: number): void {
    const t = this.controls.target;
    const ox = this.camera.position.x - t.x, oz = this.camera.position.z - t.z;
    const current = Math.atan2(ox, oz);
    let diff = heading + Math.PI + side - current;
    diff = Math.atan2(Math.sin(diff), Math.cos(diff)); // wrapped to (−π, π]
    const turn = diff * share;
    if (Math.abs(turn) < 1e-5) return;
    const c = Math.cos(turn), sn = Math.sin(turn);
    // A turn about +y by `turn`: (x, z) → (x cos + z sin, −x sin + z cos).
    this.camera.position.x = t.x + ox * c + oz * sn;
    this.camera.position.z = t.z - ox * sn + oz * c;
    this.camera.lookAt(t);
    this.dirty = true;
  }

  /** The compass direction the camera looks along on the ground (rad, 0 faces +z). */
  viewHeading(): number {
    const t = this.controls.target, cam = this.camera.position;
    return Math.atan2(t.x - cam.x, t.z - cam.z);
  }

  /** The root's ground position at the playhead, or null with nothing shown. */
  rootPosition(): { x: number; z: number } | null {
    if (!this.motion) return null;
    const r = this.rootNow();
    return { x: r.x, z: r.z };
  }

  /** Asks for a render: for things other modules add to the scene (ground overlays). */
  /** Draws the scene now (so the canvas holds a fresh image for toBlob or a capture stream in this task). */
  renderNow(): void {
    if (this.disposed) return;
    if (this.contextState === 'live' || this.contextState === 'none') this.renderer.render(this.scene, this.camera);
    this.placeLabels();
  }

  invalidate(): void {
    this.dirty = true;
  }

  private rootNow(): THREE.Vector3 {
    const r = this.root * 3;
    return this.tmp.set(this.pose[r], this.pose[r + 1], this.pose[r + 2]);
  }

  /** What the camera follows: the root, or with a companion the midpoint of the two roots as drawn. */
  private followPoint(): THREE.Vector3 {
    const root = this.rootNow();
    const c = this.companion;
    if (!c) return root;
    const r = this.root * 3;
    return root.set((root.x + c.pose[r]) / 2, root.y, (root.z + c.pose[r + 2]) / 2);
  }

  /** Puts each figure's label above its head (the highest joint), in CSS pixels of the stage. */
  private placeLabels(): void {
    const c = this.companion;
    if (!c) return;
    const w = this.container.clientWidth, h = this.container.clientHeight;
    [this.pose, c.pose].forEach((pose, i) => {
      let top = 1;
      for (let j = 0; j < pose.length / 3; j++) if (pose[j * 3 + 1] > pose[top * 3 + 1]) top = j;
      const p = this.tmp.set(pose[top * 3], pose[top * 3 + 1] + 0.22, pose[top * 3 + 2]).project(this.camera);
      const label = c.labels[i];
      label.hidden = p.z > 1 || p.z < -1;
      label.style.transform = `translate(${((p.x + 1) / 2) * w}px, ${((1 - p.y) / 2) * h}px) translate(-50%, -100%)`;
    });
  }

  private applyPose(): void {
    const m = this.motion;
    if (!m || !this.figure) return;
    const n = m.joints.length * 3;
    const ff = this.playback.frameFloat;
    const i0 = Math.floor(ff), i1 = Math.min(i0 + 1, m.frames - 1), a = ff - i0;
    const P = m.positions, o0 = i0 * n, o1 = i1 * n;
    for (let k = 0; k < n; k++) this.pose[k] = P[o0 + k] + (P[o1 + k] - P[o0 + k]) * a;
    this.figure.update(this.pose);
    this.character?.update(i0, i1, a);
    const c = this.companion;
    if (c && c.motion.frames === m.frames) {
      // (a live window replaced by setLive has its companion window replaced right after)
      const C = c.motion.positions;
      for (let k = 0; k < n; k += 3) {
        c.pose[k] = C[o0 + k] + (C[o1 + k] - C[o0 + k]) * a + c.dx;
        c.pose[k + 1] = C[o0 + k + 1] + (C[o1 + k + 1] - C[o0 + k + 1]) * a;
        c.pose[k + 2] = C[o0 + k + 2] + (C[o1 + k + 2] - C[o0 + k + 2]) * a + c.dz;
      }
      c.figure.update(c.pose);
      c.character?.update(i0, i1, a, c.dx, c.dz);
      const r = this.root * 3;
      this.companionShadow.set(c.pose[r], c.pose[r + 2], this.figureHeight * 0.55);
    }
    const root = this.rootNow();
    this.lights.follow(root.x, root.z, this.figureHeight);
    this.marks.setShadow(root.x, root.z, this.figureHeight * 0.55);
    this.glow.setCenter(root.x, root.z);
    this.marks.setProgress(ff, this.playback.frame);
    this.dirty = true;
  }

  private tick(now: number): void {
    const dt = Math.min(Math.max((now - this.last) / 1000, 0), 0.1);
    this.last = now;
    // Frame-rate figures only mean something while frames are being drawn back to back.
    if (this.renderedLast && dt > 0) {
      this.displayFps = this.displayFps ? this.displayFps * 0.95 + (1 / dt) * 0.05 : 1 / dt;
      if (this.resolution.sample(dt, now)) {
        this.webgl?.setPixelRatio(this.basePixelRatio * this.resolution.scale);
        this.resize();
      }
    }
    if (this.motion) {
      if (this.playback.playing) {
        this.playback.advance(dt);
        this.applyPose();
      }
      if (this.follow) {
        const root = this.followPoint();
        const k = this.snap ? 1 : 1 - Math.exp(-dt * 5);
        const dx = (root.x - this.controls.target.x) * k;
        const dy = (this.targetY - this.controls.target.y) * k;
        const dz = (root.z - this.controls.target.z) * k;
        if (Math.abs(dx) + Math.abs(dy) + Math.abs(dz) > 1e-7) {
          this.controls.target.x += dx; this.controls.target.y += dy; this.controls.target.z += dz;
          this.camera.position.x += dx; this.camera.position.y += dy; this.camera.position.z += dz;
          this.dirty = true;
        }
      }
    }
    this.snap = false;
    if (this.controls.update()) this.dirty = true;
    // Render on demand: a paused, still scene costs nothing; nor does one scrolled away (no context then).
    const drawable = this.contextState === 'live';
    this.renderedLast = this.dirty && drawable;
    if (this.dirty && drawable) {
      this.dirty = false;
      this.floor.setCenter(this.controls.target.x, this.controls.target.z);
      this.marks.drawFor(this.camera, Math.min(this.fog.far, this.camera.far));
      this.renderer.render(this.scene, this.camera);
      this.placeLabels();
    }
    this.onFrame?.(this.playback.state());
  }

  private resize(): void {
    const w = Math.max(this.container.clientWidth, 1), h = Math.max(this.container.clientHeight, 1);
    if (this.webgl && this.contextState === 'live') this.webgl.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.dirty = true;
  }
}

/**
 * The character's lights: a sky/ground fill, a key light high in front that casts the character's shadow on the
 * ground (a shadow-only plane under it, so the unlit ground layers stay as they are), and a soft light from the
 * camera so the side in view is never dark. They follow the shown root.
 */
class CharacterLights {
  readonly group = new THREE.Group();
  private readonly key: THREE.DirectionalLight;
  private readonly catcher: THREE.Mesh;

  constructor(camera: THREE.Camera) {
    const sky = new THREE.HemisphereLight(0xdfe6ff, 0x3a3f52, 0.85);
    this.key = new THREE.DirectionalLight(0xfff3e6, 2.0);
    this.key.position.set(1.6, 5, 2.4);
    this.key.castShadow = true;
    this.key.shadow.mapSize.set(1024, 1024);
    const cam = this.key.shadow.camera;
    cam.left = -2.2; cam.right = 2.2; cam.top = 2.2; cam.bottom = -2.2; cam.near = 0.5; cam.far = 12;
    this.key.shadow.bias = -0.0005;
    this.key.shadow.normalBias = 0.02;
    this.key.shadow.radius = 3;
    // The camera's light: added to the camera, which is put in the group so that its children are drawn.
    const fill = new THREE.DirectionalLight(0xcfd8ff, 0.55);
    fill.position.set(0, 0, 1);
    fill.target.position.set(0, 0, 0);
    camera.add(fill, fill.target);
    this.catcher = new THREE.Mesh(new THREE.PlaneGeometry(4.4, 4.4).rotateX(-Math.PI / 2), new THREE.ShadowMaterial({ color: 0x000000, opacity: 0.32, depthWrite: false }));
    this.catcher.position.y = 0.002; // just above the floor and its marks
    this.catcher.receiveShadow = true;
    this.catcher.renderOrder = 1;
    this.group.add(sky, this.key, this.key.target, this.catcher, camera);
  }

  /** Puts the key light and the shadow catcher over ground point (x, z), sized for a figure `height` tall. */
  follow(x: number, z: number, height: number): void {
    const s = Math.max(height / 1.7, 0.3);
    this.key.position.set(x + 1.6 * s, 5 * s, z + 2.4 * s);
    this.key.target.position.set(x, 0, z);
    this.key.shadow.camera.far = 12 * s;
    this.catcher.position.set(x, 0.002, z);
  }

  setShadows(on: boolean): void {
    this.key.castShadow = on;
    this.catcher.visible = on;
  }
}
