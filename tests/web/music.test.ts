// web/mirror/music.ts against training/mirror/music.py: the block the dancers hear, at counts
// below 0 and far on, at the tempos the page offers; and the count a take's frames carry.

import { describe, expect, it } from 'vitest';
import * as M from '../../web/mirror/music';
import * as F from '../../web/mirror/features';
import { expectClose, fixture } from './fixture';
import { countOf, figureMark, figureWords } from '../../web/ui/count';

const data = fixture('features');
const music = data.music;

describe('music block', () => {
  it('constants match Python', () => {
    expect([...M.MUSIC_OFFSETS]).toEqual(music.MUSIC_OFFSETS);
    expect(M.MUSIC_SIZE).toBe(music.MUSIC_SIZE);
    expect(M.DEFAULT_TEMPO).toBe(music.DEFAULT_TEMPO);
    expect([...M.TEMPO_RANGE]).toEqual(music.TEMPO_RANGE);
  });

  it('musicBlock matches Python', () => {
    for (const c of music.blocks) {
      const out = new Float64Array(M.MUSIC_SIZE + 3);
      M.musicBlock(c.beat, c.bps, out, 3);
      expectClose(out.subarray(3), c.expected, `beat ${c.beat}`);
    }
  });

  it('musicAt reads the count a take carries, its tempo from the frames around', () => {
    const out = new Float64Array(M.MUSIC_SIZE);
    (data.t as number[]).forEach((t, i) => {
      M.musicAt(data.leader.beat, t, out, 0);
      expectClose(out, music.at.slice(i * M.MUSIC_SIZE, (i + 1) * M.MUSIC_SIZE), `t ${t}`);
    });
  });

  it('beatsPerStep matches Python', () => {
    for (const c of music.beatsPerStep) expect(M.beatsPerStep(c.bpm)).toBeCloseTo(c.expected, 12);
  });

  it('an input with no count anywhere is an error, never a silent zero', () => {
    const track = new F.Track(new Float64Array(61 * 51), new Float64Array(61 * 153), new Float64Array(61 * 2), new Float64Array(61));
    expect(() => F.followerInput(track, track, 30, new Float32Array(F.INPUT_SIZE))).toThrow(/no count/);
    const heard = new Float64Array(M.MUSIC_SIZE);
    M.musicBlock(2.25, 3, heard);
    const out = new Float32Array(F.INPUT_SIZE);
    F.followerInput(track, track, 30, out, 0, null, heard);
    expectClose(out.subarray(F.INPUT_SIZE - M.MUSIC_SIZE), [...heard], 'the music given');
  });
});

describe('the count display', () => {
  it('puts beat 0 on the 1 and wraps every 8 beats, below 0 too', () => {
    expect([0, 0.99, 1, 3.5, 7.99, 8, 16.2, -0.5, -8].map(countOf)).toEqual([0, 0, 1, 3, 7, 0, 0, 7, 0]);
  });
  it('names the figure coming: her turn with an arrow, his own with a circling one (a phone shows the mark alone)', () => {
    const shown = F.FIGURE_KINDS.map(([name, way]) => figureWords(name) + figureMark(name, way));
    expect(shown).toEqual(['her turn ←', 'her turn →', 'his turn ↺', 'his turn ↻']);
    expect(new Set(F.FIGURE_KINDS.map(([name, way]) => figureMark(name, way))).size).toBe(4);
  });
});
