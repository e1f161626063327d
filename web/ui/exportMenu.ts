// The header's Export menu: a button that opens a small card (Export BVH, Export glTF, rest pose, Snapshot,
// Record). It closes on Escape (focus back on the button), on a click outside it, and after an export or a
// snapshot; the selects inside keep it open.
import { $, currentScope } from './dom';

export class ExportMenu {
  private readonly button = $<HTMLButtonElement>('export-menu-btn');
  private readonly menu = $('export-menu');
  private readonly root = currentScope().root;

  constructor() {
    this.button.addEventListener('click', () => this.setOpen(!this.open));
    this.menu.addEventListener('click', (e) => {
      const item = (e.target as HTMLElement).closest('button');
      if (item && item.id !== 'record-btn') this.setOpen(false);
    });
    this.menu.addEventListener('keydown', (e) => {
      if (e.key !== 'Escape') return;
      e.stopPropagation();
      this.setOpen(false);
      this.button.focus();
    });
    // A press outside the menu (anywhere in this element's shadow root or on the page) closes it.
    const outside = (e: Event) => {
      if (!this.open) return;
      const path = e.composedPath();
      if (!path.includes(this.menu) && !path.includes(this.button)) this.setOpen(false);
    };
    this.root.addEventListener('pointerdown', outside);
    document.addEventListener('pointerdown', outside, { signal: currentScope().signal });
  }

  get open(): boolean {
    return !this.menu.hidden;
  }

  setOpen(open: boolean): void {
    this.menu.hidden = !open;
    this.button.setAttribute('aria-expanded', String(open));
    if (open) (this.menu.querySelector<HTMLElement>('button:not(:disabled), select') ?? this.menu).focus();
  }
}
