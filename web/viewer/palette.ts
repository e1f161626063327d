// Colours of the scene. Imported before anything else in the viewer: it turns three's colour
// management off, so hex colours are used as given and no sRGB conversion runs per pixel (the renderer
// outputs "linear", i.e. the values untouched). That keeps the shaders cheap under software GL.
import * as THREE from 'three';

THREE.ColorManagement.enabled = false;

export const PALETTE = {
  background: new THREE.Color('#131826'),
  floor: new THREE.Color('#222b40'),
  gridMinor: new THREE.Color('#242d42'),
  gridMajor: new THREE.Color('#313c57'),
  left: new THREE.Color('#4f8dff'),
  right: new THREE.Color('#ff8a3d'),
  center: new THREE.Color('#dfe4ee'),
  head: new THREE.Color('#eef1f7'),
  trail: new THREE.Color('#8f7dff'),
};

/** A second figure drawn beside the main one (the raw frames in Random walk's side-by-side view): the same sides, greyed. */
export const COMPANION_PALETTE = {
  left: new THREE.Color('#6f83aa'),
  right: new THREE.Color('#b0896d'),
  center: new THREE.Color('#8c93a3'),
  head: new THREE.Color('#a3a9b6'),
};
