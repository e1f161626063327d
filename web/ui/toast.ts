// Dismissable messages at the top of the page, at most MAX_MESSAGE characters. Errors stay until dismissed; notes
// fade by themselves.

import { capMessage } from '../motion/text';
import { element } from './dom';

export type ToastKind = 'error' | 'info';

const MAX_TOASTS = 4;

export class Toasts {
  constructor(private readonly root: HTMLElement) {}

  show(message: string, kind: ToastKind = 'info'): HTMLElement {
    const el = element('div', `toast ${kind}`);
    el.setAttribute('role', kind === 'error' ? 'alert' : 'status');
    const icon = element('span', 'toast-icon', kind === 'error' ? '!' : 'i');
    const text = element('div', 'toast-text', capMessage(message)); // a file name or URL may be any length
    const close = element('button', 'toast-close', '×');
    close.type = 'button';
    close.setAttribute('aria-label', 'Dismiss');
    close.addEventListener('click', () => this.dismiss(el));
    el.append(icon, text, close);
    this.root.append(el);
    while (this.root.children.length > MAX_TOASTS) this.root.firstElementChild?.remove();
    if (kind === 'info') setTimeout(() => this.dismiss(el), 4500);
    return el;
  }

  dismiss(el: HTMLElement): void {
    if (!el.isConnected || el.classList.contains('leaving')) return;
    el.classList.add('leaving');
    setTimeout(() => el.remove(), 200);
  }

  clear(): void {
    this.root.replaceChildren();
  }
}
