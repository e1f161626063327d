// Entry point: builds the page (viewer, panel, drop zone) and installs the automation API.
import './style.css';
import { createPlayground } from './api/playground';
import { App } from './ui/app';

const app = new App();
const playground = createPlayground(app);
window.playground = playground;

const version = document.getElementById('version');
if (version) version.textContent = `v${playground.version}`;
document.body.classList.toggle('isolated', globalThis.crossOriginIsolated === true);
