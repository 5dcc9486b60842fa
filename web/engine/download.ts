// Downloads the first dance waits for (onnxruntime's wasm, the leader and follower models), read
// as streams so the loading screen can show a byte count instead of an empty floor.

/** Bytes of each download, so far and expected; totals go to `onChange` on every chunk. */
export class DownloadProgress {
  private readonly parts = new Map<string, { loaded: number; total: number }>();

  constructor(private readonly onChange: (loaded: number, total: number) => void = () => undefined) {}

  /** Announce a download before it starts, so the total is right from the first chunk. */
  expect(name: string, total: number): void {
    const part = this.parts.get(name);
    if (part) part.total = Math.max(part.total, total);
    else this.parts.set(name, { loaded: 0, total });
    this.report();
  }

  add(name: string, bytes: number): void {
    const part = this.parts.get(name) ?? { loaded: 0, total: 0 };
    part.loaded += bytes;
    part.total = Math.max(part.total, part.loaded);
    this.parts.set(name, part);
    this.report();
  }

  /** A finished download counts in full (its real size may differ from the expected one). */
  finish(name: string): void {
    const part = this.parts.get(name);
    if (part) part.total = part.loaded;
    this.report();
  }

  get loaded(): number {
    let sum = 0;
    for (const part of this.parts.values()) sum += part.loaded;
    return sum;
  }

  get total(): number {
    let sum = 0;
    for (const part of this.parts.values()) sum += part.total;
    return sum;
  }

  private report(): void {
    this.onChange(this.loaded, this.total);
  }
}

/**
 * The whole body of a response, reporting each chunk to `onBytes`. `expected` (the uncompressed
 * size, when known) lets it fill one buffer instead of concatenating chunks at the end.
 */
export async function readBody(response: Response, onBytes?: (bytes: number) => void, expected = 0): Promise<Uint8Array<ArrayBuffer>> {
  if (!response.body || !onBytes) {
    const bytes = new Uint8Array(await response.arrayBuffer());
    onBytes?.(bytes.byteLength);
    return bytes;
  }
  const reader = response.body.getReader();
  let buffer = new Uint8Array(expected);
  let length = 0;
  for (;;) {
    const { done, value } = await reader.read();
    if (done) break;
    if (length + value.byteLength > buffer.byteLength) {
      const grown = new Uint8Array(Math.max(2 * buffer.byteLength, length + value.byteLength));
      grown.set(buffer.subarray(0, length));
      buffer = grown;
    }
    buffer.set(value, length);
    length += value.byteLength;
    onBytes(value.byteLength);
  }
  return length === buffer.byteLength ? buffer : buffer.slice(0, length);
}

/** Read a response's body only to count it (its bytes go nowhere), reporting each chunk to
 *  `onBytes`; resolves to the total. For a clone whose twin is consumed elsewhere. */
export async function countBody(response: Response, onBytes: (bytes: number) => void): Promise<number> {
  if (!response.body) return 0;
  const reader = response.body.getReader();
  let total = 0;
  for (;;) {
    const { done, value } = await reader.read();
    if (done) return total;
    total += value.byteLength;
    onBytes(value.byteLength);
  }
}

/** A short hash of a string (FNV-1a), for cache versions. */
export function shortHash(text: string): string {
  let h = 0x811c9dc5;
  for (let i = 0; i < text.length; i++) {
    h ^= text.charCodeAt(i);
    h = Math.imul(h, 0x01000193);
  }
  return (h >>> 0).toString(36);
}

/** Request header that tells the service worker which version of the models the page expects:
 *  a worker of another version answers from the network, never with bytes of other models. */
export const VERSION_HEADER = 'x-duet-version';
