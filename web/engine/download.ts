// Downloads the first dance waits for (onnxruntime's wasm, the leader and follower models), read
// as streams so the loading screen can show a byte count instead of an empty floor.

/**
 * Bytes of each download, so far and expected; totals go to `onChange` on every chunk.
 *
 * A reader sees a file's bytes decoded, but what travels (and what a visitor waits for) is the
 * compressed body: onnxruntime's wasm is 11.2 MB decoded and 1.8 MB as brotli, so counting
 * decoded bytes said 15.1 MB where 4.3 MB came. So each file's compressed size is taken from its
 * response (`wire`), and its decoded bytes count in proportion. A file whose response has not
 * come yet (the downloads share two slots: slots.ts) is estimated from the files of its kind
 * that have (the models compress alike; the wasm far better); until every kind has one, the
 * byte counts are not `sized` and the bar shows no megabytes.
 */
export class DownloadProgress {
  private readonly parts = new Map<string, { loaded: number; total: number; kind: string; wire: number | null }>();

  constructor(private readonly onChange: (loaded: number, total: number, sized: boolean) => void = () => undefined) {}

  /** Announce a download (its decoded size) before it starts, so the total is right from the
   *  first chunk. `kind` groups files that compress alike. */
  expect(name: string, total: number, kind = name): void {
    const part = this.parts.get(name);
    if (part) part.total = Math.max(part.total, total);
    else this.parts.set(name, { loaded: 0, total, kind, wire: null });
    this.report();
  }

  /** The bytes that travel for this file (its compressed size), once its response is in. */
  wire(name: string, bytes: number): void {
    const part = this.parts.get(name);
    if (part) part.wire = bytes;
    this.report();
  }

  add(name: string, bytes: number): void {
    const part = this.parts.get(name) ?? { loaded: 0, total: 0, kind: name, wire: null };
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

  /** Decoded bytes so far. */
  get loaded(): number {
    let sum = 0;
    for (const part of this.parts.values()) sum += part.loaded;
    return sum;
  }

  /** Decoded bytes expected. */
  get total(): number {
    let sum = 0;
    for (const part of this.parts.values()) sum += part.total;
    return sum;
  }

  /** Compressed bytes so far and expected, or null while a kind has no response yet. */
  get travelled(): { loaded: number; total: number } | null {
    const ratios = new Map<string, [number, number]>(); // kind: [wire, decoded] of the sized files
    for (const part of this.parts.values()) {
      if (part.wire === null || part.total <= 0) continue;
      const sum = ratios.get(part.kind) ?? [0, 0];
      ratios.set(part.kind, [sum[0] + part.wire, sum[1] + part.total]);
    }
    let loaded = 0, total = 0;
    for (const part of this.parts.values()) {
      const sum = ratios.get(part.kind);
      if (part.wire === null && !sum) return null;
      const wire = part.wire ?? (part.total * sum![0]) / sum![1];
      total += wire;
      loaded += part.total > 0 ? Math.min(wire, (part.loaded * wire) / part.total) : 0;
    }
    return { loaded: Math.round(loaded), total: Math.round(total) };
  }

  private report(): void {
    const travelled = this.travelled;
    if (travelled) this.onChange(travelled.loaded, travelled.total, true);
    else this.onChange(this.loaded, this.total, false);
  }
}

/** The bytes a response's body takes on the wire: its Content-Length, which counts the body as
 *  sent (compressed where Content-Encoding says so); `decoded` where the header is missing. */
export function wireSize(response: Response, decoded: number): number {
  const length = Number(response.headers.get('content-length'));
  return length > 0 ? length : decoded;
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
