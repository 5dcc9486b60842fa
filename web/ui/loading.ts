// The loading bar: #loading in index.html (styled inline there, so it shows from the first paint),
// filled from the bytes of onnxruntime's wasm and the models as they stream in.

const mb = (bytes: number) => (bytes / 1e6).toFixed(1);

export class LoadingBar {
  private readonly element: HTMLElement | null = document.getElementById('loading');
  private readonly bar: HTMLElement | null = this.element?.querySelector('.loading-bar') ?? null;
  private readonly label: HTMLElement | null = this.element?.querySelector('.loading-label') ?? null;
  private shown = -1;

  /** Called on every chunk: writes the DOM only when the shown percentage changes. */
  update(loaded: number, total: number): void {
    const fraction = total > 0 ? Math.min(1, loaded / total) : 0;
    const percent = Math.floor(fraction * 100);
    if (percent === this.shown || !this.element) return;
    this.shown = percent;
    this.element.setAttribute('aria-valuenow', String(percent));
    if (this.bar) this.bar.style.transform = `scaleX(${fraction})`;
    if (this.label) this.label.textContent = total > 0 ? `loading the dancers · ${mb(loaded)} of ${mb(total)} MB` : 'loading the dancers';
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
