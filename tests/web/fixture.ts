// Shared by the tests: read a fixture written by `tests/python/fixtures_writer.py` and compare arrays.

import { readFileSync } from 'node:fs';
import { expect } from 'vitest';
import { Track } from '../../web/mirror/features';

export type Json = any;

const cache = new Map<string, Json>();

/** tests/fixtures/<name>.json, parsed once per test file. */
export function fixture(name: 'bvh' | 'features' | 'rollout' | 'contact'): Json {
  let data = cache.get(name);
  if (!data) {
    data = JSON.parse(readFileSync(new URL(`../fixtures/${name}.json`, import.meta.url), 'utf8'));
    cache.set(name, data);
  }
  return data;
}

/** The tolerance of the contract: 1e-5, relative for values above 1 in magnitude. */
export const TOLERANCE = 1e-5;

/**
 * Every number of `actual` equals `expected` within TOLERANCE (null in a fixture means NaN).
 * Fails with the first bad index, so a broken block is easy to find.
 */
export function expectClose(actual: ArrayLike<number>, expected: ArrayLike<number | null>, label: string, tolerance = TOLERANCE): void {
  expect(actual.length, `${label}: length`).toBe(expected.length);
  let worst = 0;
  let worstAt = -1;
  for (let i = 0; i < expected.length; i++) {
    const e = expected[i];
    const a = actual[i];
    if (e === null) {
      if (!Number.isNaN(a)) {
        worst = Infinity;
        worstAt = i;
        break;
      }
      continue;
    }
    const error = Number.isFinite(a) ? Math.abs(a - e) / Math.max(1, Math.abs(e)) : Infinity;
    if (!(error <= worst)) {
      worst = error;
      worstAt = i;
    }
  }
  if (worst > tolerance) {
    expect.fail(`${label}: index ${worstAt} is ${actual[worstAt]}, expected ${expected[worstAt]} (error ${worst.toExponential(2)})`);
  }
}

/** A Track from the features fixture; rotations exist only for fixture.rotationFrames (zeros elsewhere). */
export function trackOf(data: Json, role: 'leader' | 'follower', frames?: number): Track {
  const d = data[role];
  const n = frames ?? data.frames;
  const [first] = data.rotationFrames as [number, number];
  const rotations = new Float64Array(data.frames * 153);
  rotations.set(d.rotations, first * 153);
  return new Track(
    Float64Array.from(d.positions).slice(0, n * 51),
    rotations.slice(0, n * 153),
    Float64Array.from(d.root).slice(0, n * 2),
    Float64Array.from(d.heading).slice(0, n),
    d.beat ? Float64Array.from(d.beat).slice(0, n) : null,
  );
}
