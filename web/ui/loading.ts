// The loading bar: #loading in index.html (styled inline there, so it shows from the first paint),
// filled from the bytes of onnxruntime's wasm and the models as they stream in, counted as they
// travel (compressed: engine/download.ts); without megabytes until those sizes are known.

const mb = (bytes: number) => (bytes / 1e6).toFixed(1);

export class LoadingBar {
  private readonly element: HTMLElement | null = document.getElementById('loading');
  private readonly bar: HTMLElement | null = this.element?.querySelector('.loading-bar') ?? null;
  private readonly label: HTMLElement | null = this.element?.querySelector('.loading-label') ?? null;
  private shown = -1;

  /** Called on every chunk: writes the DOM only when the shown percentage changes. */
  update(loaded: number, total: number, sized = true): void {
    const fraction = total > 0 ? Math.min(1, loaded / total) : 0;
    const percent = Math.floor(fraction * 100);
    const shown = sized ? percent : -2 - percent;
    if (shown === this.shown || !this.element) return;
    this.shown = shown;
    this.element.setAttribute('aria-valuenow', String(percent));
    if (this.bar) this.bar.style.transform = `scaleX(${fraction})`;
    if (this.label) this.label.textContent = total > 0 && sized ? `loading the dancers · ${mb(loaded)} of ${mb(total)} MB` : 'loading the dancers';
  }

  /** The downloads are in and compiling: the bar stays full until the dance starts. */
  compiling(): void {
    if (this.bar) this.bar.style.transform = 'scaleX(1)';
    if (this.label) this.label.textContent = 'starting the dancers…';
  }

  hide(): void {
    this.element?.setAttribute('hidden', '');
  }
}
