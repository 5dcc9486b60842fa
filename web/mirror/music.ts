// Mirror of training/mirror/music.py: what the dancers hear, the count of the music as a feature
// block. Same names in camelCase, same order of numbers; tests/web/music.test.ts pins both to
// the fixtures that tests/python/fixtures_writer.py writes.
//
// `beat` is the count in beats since the music started: whole numbers fall on the beats, even
// ones start a two-beat group (the recording carries the beat and the two-beat group, not the
// measure: training/data/count.py). In the page it is read from the audio clock (web/music/).

import { FPS, type Out } from './skeleton';

/** Frames of the keys the count is read at: t-30, t-25, ..., t, ..., t+30 (13 keys). */
export const MUSIC_OFFSETS: readonly number[] = Array.from({ length: 13 }, (_, i) => (i - 6) * 5);
/** 53: per key sin/cos of the beat's and the two-beat group's phase, then the tempo. */
export const MUSIC_SIZE = MUSIC_OFFSETS.length * 4 + 1;
/** The tempo when the address names none (beats a minute): the middle of the recorded takes'. */
export const DEFAULT_TEMPO = 170;
/** What the page's tempo control offers (the networks trained on 139-218). */
export const TEMPO_RANGE: readonly [number, number] = [150, 200];

/**
 * The music block [53] at out[at..] for the count now (beats) and the tempo (beats per second):
 * per key of MUSIC_OFFSETS, sin and cos of 2π·beat and of π·beat, then the tempo.
 */
export function musicBlock(beat: number, beatsPerSecond: number, out: Out, at = 0): void {
  for (let k = 0; k < MUSIC_OFFSETS.length; k++) {
    const b = beat + (beatsPerSecond * MUSIC_OFFSETS[k]) / FPS;
    const o = at + 4 * k;
    out[o] = Math.sin(2 * Math.PI * b);
    out[o + 1] = Math.cos(2 * Math.PI * b);
    out[o + 2] = Math.sin(Math.PI * b);
    out[o + 3] = Math.cos(Math.PI * b);
  }
  out[at + MUSIC_SIZE - 1] = beatsPerSecond;
}

/**
 * The music block at frame t of a take whose count per frame is `beat` (the tempo read from the
 * count over the frames around t).
 */
export function musicAt(beat: ArrayLike<number>, t: number, out: Out, at = 0): void {
  const lo = Math.max(t - 1, 0);
  const hi = Math.min(t + 1, beat.length - 1);
  const bps = ((beat[hi] - beat[lo]) * FPS) / Math.max(hi - lo, 1);
  musicBlock(beat[t], bps, out, at);
}

/** How far the count moves in one step of the duet (1/30 s) at a tempo (beats a minute). */
export function beatsPerStep(bpm: number): number {
  return bpm / 60 / FPS;
}
