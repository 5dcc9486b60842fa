// Step-time statistics over a sliding window, for the HUD, the bench and window.duet.stepMs.
// Shared by every Simulation implementation so they all report the same thing.

export class StepTimer {
  private readonly samples: Float64Array;
  private readonly sorted: Float64Array;
  private count = 0;
  private next = 0;
  private readonly stats = { median: 0, p95: 0 };
  /** stats holds the window as it is (nothing added since it was computed). */
  private current = false;

  constructor(readonly window = 300) {
    this.samples = new Float64Array(window);
    this.sorted = new Float64Array(window);
  }

  add(milliseconds: number): void {
    this.samples[this.next] = milliseconds;
    this.next = (this.next + 1) % this.window;
    this.count = Math.min(this.count + 1, this.window);
    this.current = false;
  }

  /** Median and 95th percentile of the window (the same object each call), sorted again only
   *  after a new sample: the HUD and the page's test hook read it every frame. */
  summary(): { median: number; p95: number } {
    if (this.current) return this.stats;
    this.current = true;
    const n = this.count;
    if (n === 0) {
      this.stats.median = 0;
      this.stats.p95 = 0;
      return this.stats;
    }
    const view = this.sorted.subarray(0, n);
    view.set(this.samples.subarray(0, n));
    view.sort();
    this.stats.median = n % 2 ? view[(n - 1) / 2] : 0.5 * (view[n / 2 - 1] + view[n / 2]);
    this.stats.p95 = view[Math.min(n - 1, Math.ceil(0.95 * n) - 1)];
    return this.stats;
  }

  clear(): void {
    this.count = 0;
    this.next = 0;
    this.current = false;
  }
}
