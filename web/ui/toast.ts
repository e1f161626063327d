// Dismissable messages at the top of the page. Errors stay until dismissed; notes fade by themselves.

export type ToastKind = 'error' | 'info';

const MAX_TOASTS = 4;

export class Toasts {
  constructor(private readonly root: HTMLElement) {}

  show(message: string, kind: ToastKind = 'info'): HTMLElement {
    const el = document.createElement('div');
    el.className = `toast ${kind}`;
    el.setAttribute('role', kind === 'error' ? 'alert' : 'status');
    const icon = document.createElement('span');
    icon.className = 'toast-icon';
    icon.textContent = kind === 'error' ? '!' : 'i';
    const text = document.createElement('div');
    text.className = 'toast-text';
    text.textContent = message;
    const close = document.createElement('button');
    close.className = 'toast-close';
    close.type = 'button';
    close.setAttribute('aria-label', 'Dismiss');
    close.textContent = '×';
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
