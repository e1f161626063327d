// The page: one full-window <motion-playground> (index.html) that keeps its view in the URL; its API
// is also window.playground. Models are fetched from beside index.html. (Embeds load motion-playground.ts,
// which finds them beside itself; the page does not import that module, so a build keeps it, with its
// import.meta.url, at the top of the folder as motion-playground.js.)
import { defineMotionPlayground } from './api/element';
import { setAssetBase } from './runtime/worker/assetBase';

setAssetBase(new URL('./', document.baseURI).href);
defineMotionPlayground();
const element = document.querySelector('motion-playground');
if (!element) throw new Error('index.html has no <motion-playground>');
window.playground = element.playground;
document.documentElement.classList.toggle('isolated', globalThis.crossOriginIsolated === true);
