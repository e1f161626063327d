// The <motion-playground> element's module (built as dist/motion-playground.js): models are fetched
// from beside it, so the built folder can be copied to any static host and embedded from any page.
import { setAssetBase } from './runtime/worker/assetBase';
import { defineMotionPlayground } from './api/element';

setAssetBase(new URL('./', import.meta.url).href);
defineMotionPlayground();

export { MotionPlaygroundElement } from './api/element';
