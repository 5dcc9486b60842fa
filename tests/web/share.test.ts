// Settings from a share link (web/ui/share.ts): every value is validated and clamped; anything
// unknown, non-numeric or carrying markup leaves the default in place.

import { describe, expect, it } from 'vitest';
import { LIMITS, type Settings, addressQuery, defaultSettings, readCamera, readSettings, writeSettings } from '../../web/ui/share';

const defaults: Settings = { ...defaultSettings(0.5), seed: 42 };
const read = (search: string) => readSettings(search, defaults);

describe('readSettings', () => {
  it('keeps every default for an empty or unrelated query', () => {
    expect(read('')).toEqual(defaults);
    expect(read('?')).toEqual(defaults);
    expect(read('?foo=bar&utm_source=x')).toEqual(defaults);
  });

  it('does not change the defaults object', () => {
    const before = structuredClone(defaults);
    read('?model=ccm&temperature=1&ghosts=3');
    expect(defaults).toEqual(before);
  });

  it('reads valid values', () => {
    const s = read('?model=compare&temperature=0.8&seed=123&ghosts=3&speed=2&trajectories=0&intentions=1&skeleton=1&camera=30,40,6');
    expect(s.model).toBe('compare');
    expect(s.temperature).toBe(0.8);
    expect(s.seed).toBe(123);
    expect(s.ghosts).toBe(3);
    expect(s.speed).toBe(2);
    expect(s.trajectories).toBe(false);
    expect(s.intentions).toBe(true);
    expect(s.skeleton).toBe(true);
    expect(s.camera).toEqual({ azimuth: 30, polar: 40, distance: 6 });
  });

  it('reads the music: tempo within what the control offers, music on unless ?music=0', () => {
    expect(defaults.tempo).toBe(170);
    expect(defaults.music).toBe(true);
    expect(read('?tempo=188').tempo).toBe(188);
    expect(read('?tempo=900').tempo).toBe(LIMITS.tempo[1]);
    expect(read('?tempo=20').tempo).toBe(LIMITS.tempo[0]);
    expect(read('?tempo=abc').tempo).toBe(defaults.tempo);
    expect(read('?music=0').music).toBe(false);
    expect(read('?music=1').music).toBe(true);
    expect(defaultSettings(0.5, 181).tempo).toBe(181);
  });

  it('reads whether the leader leads figures of his own: on unless ?figures=0, written only when off', () => {
    expect(defaults.figures).toBe(true);
    expect(read('?figures=0').figures).toBe(false);
    expect(read('?figures=1').figures).toBe(true);
    expect(read('?figures=maybe').figures).toBe(true);
    expect(new URLSearchParams(writeSettings(defaults, null, 0.5)).has('figures')).toBe(false);
    const off = writeSettings({ ...defaults, figures: false }, null, 0.5);
    expect(new URLSearchParams(off).get('figures')).toBe('0');
    expect(read(`?${off}`).figures).toBe(false);
    expect(new URLSearchParams(addressQuery('?figures=0&bodies=sticks', defaults, null, 0.5)).toString()).toBe('bodies=sticks&seed=42');
  });

  it('writes the tempo only when it is not the manifest\'s, and music=0 only when muted', () => {
    const q = (s: Partial<Settings>, tempo = 170) => new URLSearchParams(writeSettings({ ...defaults, ...s }, null, 0.5, tempo));
    expect(q({}).has('tempo')).toBe(false);
    expect(q({}).has('music')).toBe(false);
    expect(q({ tempo: 185 }).get('tempo')).toBe('185');
    expect(q({ tempo: 170 }, 165).get('tempo')).toBe('170');
    expect(q({ music: false }).get('music')).toBe('0');
    expect(read(`?${q({ tempo: 155.5, music: false })}`)).toMatchObject({ tempo: 155.5, music: false });
  });

  it('clamps numbers out of range to the limits', () => {
    expect(read('?temperature=5').temperature).toBe(LIMITS.temperature[1]);
    expect(read('?temperature=-1').temperature).toBe(LIMITS.temperature[0]);
    expect(read('?temperature=1e308').temperature).toBe(LIMITS.temperature[1]);
    expect(read('?ghosts=99').ghosts).toBe(LIMITS.ghosts[1]);
    expect(read('?ghosts=-3').ghosts).toBe(0);
    expect(read('?ghosts=2.6').ghosts).toBe(3);
    expect(read('?speed=100').speed).toBe(LIMITS.speed[1]);
    expect(read('?speed=0').speed).toBe(LIMITS.speed[0]);
    expect(read('?threads=8').threads).toBe(LIMITS.threads[1]);
    expect(read('?threads=0').threads).toBe(LIMITS.threads[0]);
  });

  it('ignores NaN, infinities, empty and non-numeric values', () => {
    for (const bad of ['NaN', 'nan', 'Infinity', '-Infinity', '', '%20', 'abc', '1,5', '[]', '1/0']) {
      const s = read(`?temperature=${bad}&speed=${bad}&ghosts=${bad}`);
      expect(s.temperature, bad).toBe(defaults.temperature);
      expect(s.speed, bad).toBe(defaults.speed);
      expect(s.ghosts, bad).toBe(defaults.ghosts);
    }
    // Number('0x1') is 1: hex is a number, but still clamped into range.
    expect(read('?temperature=0x1').temperature).toBeLessThanOrEqual(LIMITS.temperature[1]);
  });

  it('falls back to the default model for unknown models and markup', () => {
    for (const bad of ['gpt', 'OURS', 'ours ', '<script>alert(1)</script>', '"><img src=x onerror=alert(1)>', 'follower_ccm', '']) {
      expect(read(`?model=${encodeURIComponent(bad)}`).model, bad).toBe('ours');
    }
    expect(read('?model=ccm').model).toBe('ccm');
  });

  it('never lets markup or junk through any field', () => {
    const markup = encodeURIComponent('<b onmouseover=alert(1)>x</b>');
    const s = read(`?model=${markup}&temperature=${markup}&seed=${markup}&camera=${markup}&ghosts=${markup}&speed=${markup}&trajectories=${markup}&intentions=${markup}`);
    expect(s).toEqual(defaults);
    for (const value of Object.values(s)) {
      if (typeof value === 'string') expect(value).not.toMatch(/[<>"']/);
    }
  });

  it('reads threads (a bench knob) as 1 or 2 whenever the parameter is present', () => {
    expect(read('').threads).toBeNull();
    expect(read('?threads=').threads).toBeNull();
    expect(read('?threads=2').threads).toBe(2);
    // Present but unreadable: one thread, the safe choice for a benchmark.
    expect(read('?threads=%3Cb%3E').threads).toBe(1);
    expect(read('?threads=NaN').threads).toBe(1);
  });

  it('accepts only whole 32-bit seeds', () => {
    expect(read('?seed=4294967295').seed).toBe(4294967295);
    for (const bad of ['4294967296', '-1', '1.5', '1e3', 'abc', '12345678901']) expect(read(`?seed=${bad}`).seed, bad).toBe(42);
  });

  it('reads booleans only from 0/1/true/false', () => {
    expect(read('?trajectories=false').trajectories).toBe(false);
    expect(read('?intentions=true').intentions).toBe(true);
    expect(read('?trajectories=no&intentions=yes')).toMatchObject({ trajectories: true, intentions: false });
  });
});

describe('readCamera', () => {
  it('wraps the azimuth and clamps polar angle and distance', () => {
    expect(readCamera('-30,100,0.1')).toEqual({ azimuth: 330, polar: LIMITS.polar[1], distance: LIMITS.distance[0] });
    expect(readCamera('725,1,1000')).toEqual({ azimuth: 5, polar: LIMITS.polar[0], distance: LIMITS.distance[1] });
  });

  it('refuses anything that is not three finite numbers', () => {
    for (const bad of [null, '', '1,2', '1,2,3,4', 'a,b,c', 'NaN,1,1', '1,Infinity,1', '<svg>,1,2']) expect(readCamera(bad), String(bad)).toBeNull();
  });
});

describe('writeSettings', () => {
  it('round-trips through readSettings', () => {
    const settings: Settings = { ...defaults, model: 'ccm', temperature: 1.25, seed: 7, ghosts: 4, speed: 0.5, trajectories: false, intentions: true, skeleton: true };
    const camera = { azimuth: 12.34, polar: 45, distance: 5.5 };
    const query = writeSettings(settings, camera, defaults.temperature);
    const back = read(`?${query}`);
    expect({ ...back, camera: null }).toEqual({ ...settings, camera: null });
    expect(back.camera!.azimuth).toBeCloseTo(12.3, 9);
    expect(back.camera!.polar).toBe(45);
    expect(back.camera!.distance).toBe(5.5);
  });

  it('writes only what differs from a fresh visit, plus the seed', () => {
    expect(writeSettings(defaults, null, defaults.temperature)).toBe('seed=42');
  });
});

describe('addressQuery', () => {
  const changed: Settings = { ...defaults, model: 'compare', ghosts: 2, skeleton: true };

  it('writes every setting that differs from a fresh visit, and reads back the same', () => {
    const query = addressQuery('', changed, { azimuth: 90, polar: 60, distance: 4 }, defaults.temperature);
    expect(Object.fromEntries(new URLSearchParams(query))).toEqual({ model: 'compare', seed: '42', camera: '90,60,4', ghosts: '2', skeleton: '1' });
    expect({ ...read(`?${query}`), camera: null }).toEqual({ ...changed, camera: null });
  });

  it('replaces the settings it owns and keeps every other parameter', () => {
    const query = new URLSearchParams(addressQuery('?threads=1&model=ccm&bodies=sticks&skeleton=1&camera=1,2,3', { ...defaults, ghosts: 2 }, null, defaults.temperature));
    expect(query.get('threads')).toBe('1');
    expect(query.get('bodies')).toBe('sticks');
    expect(query.get('ghosts')).toBe('2');
    // Back to their defaults: gone from the address.
    expect(query.has('model')).toBe(false);
    expect(query.has('skeleton')).toBe(false);
    expect(query.has('camera')).toBe(false);
    expect(query.getAll('seed')).toEqual(['42']);
  });
});
