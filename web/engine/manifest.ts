// public/models/manifest.json: the skeleton, the feature layout, the model files and defaults,
// written by training/learning/export.py. Kept apart from policy.ts so the page can read it (and draw the
// floor) before the 3.7 MB onnxruntime download finishes.

import type { Manifest } from './types';
import { DuetError } from '../ui/errors';
import { VERSION_HEADER, readBody, wireSize } from './download';
import {
  FOLLOWER_INPUT_LAYOUT, INPUT_SIZE, INTENTION_SIZE, LEADER_INPUT_LAYOUT, type Layout, N_JOINTS, OUTPUT_LAYOUT, OUTPUT_SIZE,
} from '../mirror/features';

/** Sizes this page was written for; the manifest must agree. */
export const MANIFEST_VERSION = 1;
export const LAYOUT = { input: INPUT_SIZE, output: OUTPUT_SIZE, intention: INTENTION_SIZE } as const;
/** The block lists the manifest must hold, in this page's layout tables. */
export const BLOCK_LISTS = { followerInput: FOLLOWER_INPUT_LAYOUT, leaderInput: LEADER_INPUT_LAYOUT, outputBlocks: OUTPUT_LAYOUT } as const;

/** Fetch and check public/models/manifest.json (relative, so a sub-path deployment works). */
export async function loadManifest(url = 'models/manifest.json'): Promise<Manifest> {
  let response: Response;
  try {
    response = await fetch(url);
  } catch (error) {
    throw new DuetError('Could not load the models', `${url}: ${(error as Error).message}`);
  }
  if (!response.ok) {
    throw new DuetError('The models are missing', `${url} answered ${response.status}. Export models into public/models/ (python -m training.learning.export).`);
  }
  let manifest: Manifest;
  try {
    manifest = (await response.json()) as Manifest;
  } catch {
    // A dev server answers a missing file with index.html, which is not JSON.
    throw new DuetError('The models are missing', `${url} is not a JSON manifest. Export models into public/models/ (python -m training.learning.export).`);
  }
  validateManifest(manifest);
  return manifest;
}

export function validateManifest(manifest: Manifest): void {
  const bad = (detail: string) => new DuetError('The model manifest does not match this page', detail);
  if (!manifest || typeof manifest !== 'object') throw bad('manifest.json is not an object');
  if (manifest.version !== MANIFEST_VERSION) {
    throw bad(`manifest version ${manifest.version}, this page reads version ${MANIFEST_VERSION}`);
  }
  const layout = manifest.layout ?? ({} as Manifest['layout']);
  for (const key of ['input', 'output', 'intention'] as const) {
    if (layout[key] !== LAYOUT[key]) throw bad(`layout.${key} is ${layout[key]}, this page expects ${LAYOUT[key]}`);
  }
  for (const key of Object.keys(BLOCK_LISTS) as (keyof typeof BLOCK_LISTS)[]) {
    const difference = firstDifference(layout[key], BLOCK_LISTS[key]);
    if (difference) throw bad(`layout.${key} ${difference}`);
  }
  const joints = manifest.skeleton?.parents?.length;
  if (joints !== N_JOINTS) throw bad(`skeleton has ${joints} joints, expected ${N_JOINTS}`);
  for (const name of ['follower', 'leader']) {
    if (!manifest.models?.[name]) throw bad(`no "${name}" model listed`);
  }
  for (const [name, entry] of Object.entries(manifest.models)) {
    if (typeof entry.file !== 'string' || !/^[\w.-]+\.onnx$/.test(entry.file)) throw bad(`model "${name}" has a bad file name`);
    if (!(entry.channels > 0 && entry.classes > 0)) throw bad(`model "${name}" needs channels and classes`);
  }
}

/** Where a manifest's block list first differs from this page's (null where they agree). */
export function firstDifference(blocks: unknown, expected: Layout): string | null {
  const show = ([name, size]: readonly [string, number]) => `"${name}" (${size})`;
  if (!Array.isArray(blocks)) return `is missing; this page expects ${expected.map(show).join(', ')}`;
  for (let i = 0; i < Math.max(blocks.length, expected.length); i++) {
    const block: unknown = blocks[i];
    const want = expected[i];
    const valid = Array.isArray(block) && block.length === 2 && typeof block[0] === 'string' && typeof block[1] === 'number';
    if (valid && want && block[0] === want[0] && block[1] === want[1]) continue;
    const got = block === undefined ? 'missing' : valid ? show(block as [string, number]) : JSON.stringify(block);
    return `block ${i + 1} is ${got}, this page expects ${want ? show(want) : 'no more blocks'}`;
  }
  return null;
}

/** Download one model's bytes and check them against the manifest. Independent of ORT, so the
 *  downloads run while onnxruntime itself is still loading. `onBytes` sees each chunk as it
 *  arrives (the progress bar), `onWire` the bytes its body takes on the wire (compressed), once the
 *  response is in; `version` goes to the service worker (download.ts); `base` is the page's
 *  address (models/ is relative to the page, also when a worker fetches). */
export async function fetchModelBytes(
  manifest: Manifest,
  name: string,
  onBytes?: (bytes: number) => void,
  version = '',
  base = location.href,
  onWire?: (bytes: number) => void,
): Promise<Uint8Array> {
  const entry = manifest.models[name];
  if (!entry) throw new DuetError('Model not found', `"${name}" is not in manifest.json`);
  const url = `models/${entry.file}`;
  let bytes: Uint8Array;
  try {
    const response = await fetch(new URL(url, base), version ? { headers: { [VERSION_HEADER]: version } } : undefined);
    if (!response.ok) throw new Error(`answered ${response.status}`);
    onWire?.(wireSize(response, entry.bytes));
    bytes = await readBody(response, onBytes, entry.bytes);
  } catch (error) {
    throw new DuetError('A model file is missing', `${url}: ${(error as Error).message}`);
  }
  if (entry.bytes && bytes.byteLength !== entry.bytes) {
    throw new DuetError('A model file is corrupt', `${url} has ${bytes.byteLength} bytes, manifest.json says ${entry.bytes}`);
  }
  return bytes;
}
