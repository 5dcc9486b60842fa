// The order of the first downloads (onnxruntime's wasm, then the models). A phone's link is the
// bottleneck of a first visit: every file shares it, so what matters is which file comes in
// when. Whatever arrives last decides how long the page still works after the last byte, so:
// - at most `parallel` downloads run at once (two: in the phone bench a single stream used only
//   about 80 % of the emulated 9 Mbit/s link, two streams used all of it), and
// - a download that has to wait starts, when a slot frees, before smaller ones. The page asks for
//   the wasm first (compiled as it streams in, needed before any model can start), then the
//   models largest first: the smallest comes in last, and creating its session is all that is
//   left to do after the last byte.

export class DownloadSlots {
  private running = 0;
  private readonly waiting: { bytes: number; start: () => void }[] = [];

  constructor(private readonly parallel = 2) {}

  /**
   * Run `download` (of about `bytes` bytes; it resolves once its last byte is in) now if a slot
   * is free, synchronously, so that the request goes out before any long task that follows;
   * otherwise when one frees, largest waiting download first.
   */
  run<T>(bytes: number, download: () => Promise<T>): Promise<T> {
    return new Promise<T>((resolve, reject) => {
      const start = () => {
        this.running++;
        let result: Promise<T>;
        try {
          result = download();
        } catch (error) {
          result = Promise.reject(error);
        }
        result.then(resolve, reject).finally(() => {
          this.running--;
          this.next();
        });
      };
      if (this.running < this.parallel) start();
      else this.waiting.push({ bytes, start });
    });
  }

  private next(): void {
    if (this.running >= this.parallel || this.waiting.length === 0) return;
    this.waiting.sort((a, b) => b.bytes - a.bytes);
    this.waiting.shift()!.start();
  }
}
