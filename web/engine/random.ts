// Seeded pseudo-random numbers, so a shared link (?seed=) replays the same sampling noise.

/** mulberry32: a tiny 32-bit PRNG, good enough for sampling noise, and the same in any browser. */
export function mulberry32(seed: number): () => number {
  let state = seed >>> 0;
  return () => {
    state = (state + 0x6d2b79f5) >>> 0;
    let t = state;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return (t ^ (t >>> 14)) >>> 0;
  };
}

/** Uniform numbers strictly inside (0, 1): the Gumbel noise g = -log(-log u) is infinite at 0 and 1. */
export function createUniform(seed: number): () => number {
  const next = mulberry32(seed);
  return () => (next() + 0.5) / 4294967296;
}

/** Fill `array` with uniform (0, 1) numbers, in place. */
export function fillUniform(array: Float32Array, uniform: () => number): void {
  for (let i = 0; i < array.length; i++) {
    // float32 rounding can turn 1 - 1e-10 into exactly 1; keep the open interval.
    const u = Math.fround(uniform());
    array[i] = u >= 1 ? 0.99999994 : u;
  }
}
