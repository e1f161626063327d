// The page: one full-window <motion-playground> (index.html) that keeps its view in the URL; its API
// is also window.playground.
import './motion-playground';

const element = document.querySelector('motion-playground');
if (!element) throw new Error('index.html has no <motion-playground>');
window.playground = element.playground;
document.documentElement.classList.toggle('isolated', globalThis.crossOriginIsolated === true);
