// Toasts: a short visible message at the bottom of the page that goes away by itself, for
// anything that is not fatal (window.duet.error and the error overlay are for fatal errors only).
// Toasts are text only (textContent), so a file name or a message never becomes markup.

export type ToastKind = 'info' | 'error';

let toasts: HTMLElement | null = null;

/** A message at the bottom of the page for a few seconds (click to dismiss). */
export function showToast(title: string, detail = '', kind: ToastKind = 'error', ms = kind === 'error' ? 9000 : 5000): HTMLElement {
  if (!toasts) {
    toasts = document.createElement('div');
    toasts.className = 'toasts';
    document.body.appendChild(toasts);
  }
  const toast = document.createElement('div');
  toast.className = `toast toast-${kind}`;
  toast.setAttribute('role', kind === 'error' ? 'alert' : 'status');
  const heading = document.createElement('strong');
  heading.textContent = title;
  toast.appendChild(heading);
  if (detail) {
    const body = document.createElement('p');
    body.textContent = detail;
    toast.appendChild(body);
  }
  const remove = () => toast.remove();
  toast.addEventListener('click', remove);
  setTimeout(remove, ms);
  // At most four at a time: the oldest goes first.
  while (toasts.children.length >= 4) toasts.firstElementChild?.remove();
  toasts.appendChild(toast);
  if (kind === 'error') console.warn('[duet]', `${title}: ${detail}`);
  return toast;
}
