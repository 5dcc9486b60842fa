// web/engine/manifest.ts: the page refuses a manifest whose feature layout differs from its own tables
// (web/mirror/features.ts), naming the first block that differs. The shipped manifest must pass.

import { readFileSync } from 'node:fs';
import { describe, expect, it } from 'vitest';
import { firstDifference, validateManifest } from '../../web/engine/manifest';
import { DuetError } from '../../web/ui/errors';
import { FOLLOWER_INPUT_LAYOUT } from '../../web/mirror/features';
import type { Manifest } from '../../web/engine/types';

const shipped = () => JSON.parse(readFileSync(new URL('../../public/models/manifest.json', import.meta.url), 'utf8')) as Manifest;

/** The detail of the DuetError that validateManifest throws on the edited shipped manifest. */
function refusal(edit: (manifest: Manifest) => void): string {
  const manifest = shipped();
  edit(manifest);
  try {
    validateManifest(manifest);
  } catch (error) {
    expect(error).toBeInstanceOf(DuetError);
    expect((error as DuetError).title).toBe('The model manifest does not match this page');
    return (error as DuetError).detail;
  }
  throw new Error('validateManifest accepted the manifest');
}

describe('validateManifest', () => {
  it('accepts the shipped manifest (its block lists are the page\'s layout tables)', () => {
    expect(() => validateManifest(shipped())).not.toThrow();
  });

  it('refuses two input blocks in another order, naming the first one that differs', () => {
    const detail = refusal((m) => {
      const blocks = m.layout.followerInput;
      [blocks[0], blocks[1]] = [blocks[1], blocks[0]]; // both 24 wide: the total size still agrees
    });
    expect(detail).toBe('layout.followerInput block 1 is "partner_trajectory_future" (24), this page expects "partner_trajectory_past" (24)');
  });

  it('refuses a renamed block, a resized block, a missing and an extra block', () => {
    expect(refusal((m) => (m.layout.leaderInput[6][0] = 'steering'))).toBe(
      'layout.leaderInput block 7 is "steering" (24), this page expects "control" (24)');
    expect(refusal((m) => (m.layout.outputBlocks[4][1] = 4))).toBe(
      'layout.outputBlocks block 5 is "contacts" (4), this page expects "contacts" (2)');
    expect(refusal((m) => m.layout.outputBlocks.pop())).toBe(
      'layout.outputBlocks block 5 is missing, this page expects "contacts" (2)');
    expect(refusal((m) => m.layout.leaderInput.push(['extra', 1]))).toBe(
      'layout.leaderInput block 11 is "extra" (1), this page expects no more blocks');
  });

  it('refuses a manifest without block lists', () => {
    expect(refusal((m) => delete (m.layout as Partial<Manifest['layout']>).followerInput)).toMatch(
      /^layout\.followerInput is missing; this page expects "partner_trajectory_past" \(24\), /);
  });

  it('checks the sizes first, as before', () => {
    expect(refusal((m) => (m.layout.input = 600))).toBe('layout.input is 600, this page expects 817');
  });
});

describe('firstDifference', () => {
  it('is null for the page\'s own table and names malformed entries', () => {
    expect(firstDifference(FOLLOWER_INPUT_LAYOUT.map(([n, s]) => [n, s]), FOLLOWER_INPUT_LAYOUT)).toBeNull();
    expect(firstDifference([['partner_trajectory_past']], FOLLOWER_INPUT_LAYOUT)).toBe(
      'block 1 is ["partner_trajectory_past"], this page expects "partner_trajectory_past" (24)');
  });
});
