// Settings <-> URL query, so a link reproduces what someone saw: follower model, temperature,
// sampling seed, camera, the music, the leader's own figures, and the view options. Every value from the URL is parsed, validated and
// clamped here; nothing from it ever reaches the page as markup. The page writes the settings into
// its own address as they change (addressQuery), so the address bar is always such a link.

import type { FollowerChoice } from '../engine/types';
import { type CameraOrbit, ORBIT_LIMITS } from '../draw/orbit';
import { DEFAULT_TEMPO, TEMPO_RANGE } from '../mirror/music';

export interface Settings {
  model: FollowerChoice;
  temperature: number;
  seed: number;
  camera: CameraOrbit | null;
  ghosts: number;
  /** Plays the dance faster or slower (address only: tests and fast-forward); the music plays
   *  only at 1, where the dance can keep to it. */
  speed: number;
  /** The music's tempo, beats a minute (the networks dance to it). */
  tempo: number;
  /** Whether the page plays the music (muted: the dance keeps its silent count). */
  music: boolean;
  /** Whether the leader leads figures of his own (off: only the turns the visitor asks for). */
  figures: boolean;
  trajectories: boolean;
  intentions: boolean;
  /** The thin bones over the shaded bodies. */
  skeleton: boolean;
  /** WASM threads; null = as many as the page may use (for the bench: ?threads=1). */
  threads: number | null;
}

export const LIMITS = {
  temperature: [0, 2],
  ghosts: [0, 8],
  speed: [0.25, 4],
  /** The tempo control: within what the networks trained on (139-218, web/mirror/music.ts). */
  tempo: TEMPO_RANGE,
  /** The camera (web/draw/orbit.ts). */
  polar: ORBIT_LIMITS.polar,
  distance: ORBIT_LIMITS.distance,
  threads: [1, 2],
} as const;

/** The query keys the settings own; addressQuery replaces these and keeps any other. */
const KEYS = ['model', 'temperature', 'seed', 'camera', 'ghosts', 'speed', 'tempo', 'music', 'figures', 'trajectories', 'intentions', 'skeleton'];

const MODELS: readonly FollowerChoice[] = ['ours', 'ccm', 'compare'];

export function defaultSettings(defaultTemperature: number, defaultTempo: number = DEFAULT_TEMPO): Settings {
  return {
    model: 'ours',
    temperature: clamp(defaultTemperature, LIMITS.temperature),
    seed: randomSeed(),
    camera: null,
    ghosts: 0,
    speed: 1,
    tempo: clamp(defaultTempo, LIMITS.tempo),
    music: true,
    figures: true,
    trajectories: true,
    intentions: false,
    skeleton: false,
    threads: null,
  };
}

/** Read settings from a query string; anything missing or invalid keeps its default. */
export function readSettings(search: string, defaults: Settings): Settings {
  const query = new URLSearchParams(search);
  const settings: Settings = { ...defaults };
  const model = query.get('model');
  if (model && (MODELS as readonly string[]).includes(model)) settings.model = model as FollowerChoice;
  settings.temperature = readNumber(query.get('temperature'), LIMITS.temperature, settings.temperature);
  settings.ghosts = Math.round(readNumber(query.get('ghosts'), LIMITS.ghosts, settings.ghosts));
  settings.speed = readNumber(query.get('speed'), LIMITS.speed, settings.speed);
  settings.tempo = readNumber(query.get('tempo'), LIMITS.tempo, settings.tempo);
  settings.music = readBoolean(query.get('music'), settings.music);
  settings.figures = readBoolean(query.get('figures'), settings.figures);
  settings.trajectories = readBoolean(query.get('trajectories'), settings.trajectories);
  settings.intentions = readBoolean(query.get('intentions'), settings.intentions);
  settings.skeleton = readBoolean(query.get('skeleton'), settings.skeleton);
  const seed = query.get('seed');
  if (seed !== null && /^\d{1,10}$/.test(seed) && Number(seed) <= 0xffffffff) settings.seed = Number(seed);
  const threads = query.get('threads');
  if (threads !== null && threads !== '') settings.threads = Math.round(readNumber(threads, LIMITS.threads, 1));
  settings.camera = readCamera(query.get('camera')) ?? settings.camera;
  return settings;
}

/** The query string for a share link (only what differs from a fresh visit, plus the seed). */
export function writeSettings(settings: Settings, camera: CameraOrbit | null, defaultTemperature: number, defaultTempo: number = DEFAULT_TEMPO): string {
  const query = new URLSearchParams();
  if (settings.model !== 'ours') query.set('model', settings.model);
  if (settings.temperature !== defaultTemperature) query.set('temperature', round(settings.temperature, 3));
  query.set('seed', String(settings.seed));
  if (camera) query.set('camera', formatCamera(camera));
  if (settings.ghosts) query.set('ghosts', String(settings.ghosts));
  if (settings.speed !== 1) query.set('speed', round(settings.speed, 2));
  if (settings.tempo !== defaultTempo) query.set('tempo', round(settings.tempo, 1));
  if (!settings.music) query.set('music', '0');
  if (!settings.figures) query.set('figures', '0');
  if (!settings.trajectories) query.set('trajectories', '0');
  if (settings.intentions) query.set('intentions', '1');
  if (settings.skeleton) query.set('skeleton', '1');
  return query.toString();
}

/**
 * The page's query `search` with the settings written in (writeSettings), every other parameter
 * (?threads=1, ?bodies=sticks, anything a link carried) kept as it was.
 */
export function addressQuery(search: string, settings: Settings, camera: CameraOrbit | null, defaultTemperature: number, defaultTempo: number = DEFAULT_TEMPO): string {
  const query = new URLSearchParams(search);
  for (const key of KEYS) query.delete(key);
  for (const [key, value] of new URLSearchParams(writeSettings(settings, camera, defaultTemperature, defaultTempo))) query.append(key, value);
  return query.toString();
}

/** "azimuth,polar,distance" as a link writes it (degrees, degrees, metres; 0.1 apart). */
export function formatCamera(camera: CameraOrbit): string {
  return [camera.azimuth, camera.polar, camera.distance].map((v) => round(v, 1)).join(',');
}

/** "azimuth,polar,distance" in degrees, degrees, metres. */
export function readCamera(value: string | null): CameraOrbit | null {
  if (!value) return null;
  const parts = value.split(',').map(Number);
  if (parts.length !== 3 || !parts.every(Number.isFinite)) return null;
  const [azimuth, polar, distance] = parts;
  return {
    azimuth: ((azimuth % 360) + 360) % 360,
    polar: clamp(polar, LIMITS.polar),
    distance: clamp(distance, LIMITS.distance),
  };
}

/** Copy a link to the clipboard; false when the browser refuses (then the caller shows it). */
export async function copyLink(url: string): Promise<boolean> {
  try {
    await navigator.clipboard.writeText(url);
    return true;
  } catch {
    return false;
  }
}

function readNumber(value: string | null, [low, high]: readonly [number, number], fallback: number): number {
  if (value === null || value.trim() === '') return fallback;
  const number = Number(value);
  return Number.isFinite(number) ? clamp(number, [low, high]) : fallback;
}

function readBoolean(value: string | null, fallback: boolean): boolean {
  if (value === '1' || value === 'true') return true;
  if (value === '0' || value === 'false') return false;
  return fallback;
}

function clamp(value: number, [low, high]: readonly [number, number]): number {
  return Math.min(high, Math.max(low, value));
}

function round(value: number, digits: number): string {
  return String(Number(value.toFixed(digits)));
}

function randomSeed(): number {
  return crypto.getRandomValues(new Uint32Array(1))[0];
}
