// A visible message instead of a blank canvas: missing or corrupt model, no WebGL, no WebAssembly,
// or anything that throws. Text only (textContent), never markup from a message.

/** An error with a short title for people and a detail line for whoever fixes it. */
export class DuetError extends Error {
  constructor(
    readonly title: string,
    readonly detail: string,
  ) {
    super(`${title}: ${detail}`);
    this.name = 'DuetError';
  }
}

let overlay: HTMLElement | null = null;

/** Show (or replace) the error overlay and publish the message on window.duet.error. */
export function showError(error: unknown): void {
  const { title, detail } = describe(error);
  const message = `${title}: ${detail}`;
  if (window.duet) window.duet.error = message;
  console.warn('[duet]', message, error);

  if (!overlay) {
    overlay = document.createElement('div');
    overlay.className = 'error-overlay';
    overlay.setAttribute('role', 'alert');
    document.body.appendChild(overlay);
  }
  overlay.replaceChildren();
  const heading = document.createElement('h2');
  heading.textContent = title;
  const body = document.createElement('p');
  body.textContent = detail;
  const hint = document.createElement('p');
  hint.className = 'hint';
  hint.textContent = 'Reload the page to try again.';
  overlay.append(heading, body, hint);
}

function describe(error: unknown): { title: string; detail: string } {
  if (error instanceof DuetError) return { title: error.title, detail: error.detail };
  if (error instanceof Error) return { title: 'Something went wrong', detail: error.message || error.name };
  return { title: 'Something went wrong', detail: String(error) };
}

/** Fail early, with a message, on browsers that cannot run the page at all. */
export function checkBrowserSupport(): void {
  if (typeof WebAssembly !== 'object' || typeof WebAssembly.instantiate !== 'function') {
    throw new DuetError(
      'WebAssembly is not available',
      'The dancers run on neural networks executed with WebAssembly. Use a current browser, or enable WebAssembly.',
    );
  }
  const probe = document.createElement('canvas');
  // three.js draws with WebGL 2 only.
  const gl = probe.getContext('webgl2');
  if (!gl) {
    throw new DuetError(
      'WebGL is not available',
      'The dance floor is drawn with WebGL. Enable hardware acceleration or try another browser.',
    );
  }
  // Release the probe context right away; browsers cap the number of live contexts.
  gl.getExtension('WEBGL_lose_context')?.loseContext();
}

/** Anything thrown later (a failing step, a rejected promise) ends up on screen too. */
export function installGlobalErrorHandlers(): void {
  window.addEventListener('error', (event) => showError(event.error ?? event.message));
  window.addEventListener('unhandledrejection', (event) => showError(event.reason));
}
