// Every number the help states about the page matches where the page takes it: the shipped
// manifest (public/models/manifest.json: fps, defaultTemperature, leaderTemperature, the upright
// guard's samples), the controls' limits (web/ui/share.ts LIMITS) and the clip's length; and the
// words name the controls and keys that exist. Before: the help said the leader model keeps
// variety 0.5 while the manifest shipped 0.7, and the turn buttons promised "her right / her left".

import { readFileSync } from 'node:fs';
import { describe, expect, it } from 'vitest';
import type { Manifest } from '../../web/engine/types';
import { CLIP_SECONDS } from '../../web/ui/clip';
import { helpFacts, keysText, methodText, researchText } from '../../web/ui/help';
import { BRIEF, CONTROLS } from '../../web/ui/panel';
import { LIMITS, defaultSettings } from '../../web/ui/share';
import { turnTitle } from '../../web/ui/turns';

const manifest = JSON.parse(readFileSync(new URL('../../public/models/manifest.json', import.meta.url), 'utf8')) as Manifest;
/** The variety a page starts with: the manifest's, within the control's limits (main.ts). */
const variety = defaultSettings(manifest.defaultTemperature).temperature;
const facts = helpFacts(manifest, variety);

/** Every number written in `text` (0.7, 150-200, 6 s), as numbers. */
const numbers = (text: string) => [...text.matchAll(/\d+(?:\.\d+)?/g)].map((m) => Number(m[0]));

describe('the help, against the manifest and the page', () => {
  it('takes its facts from the manifest', () => {
    expect(facts.fps).toBe(manifest.fps);
    expect(facts.variety).toBe(manifest.defaultTemperature);
    expect(facts.leaderVariety).toBe(manifest.leaderTemperature ?? null);
    expect(facts.leadingVariety).toBe(manifest.leadingTemperature ?? null);
    expect(facts.uprightSamples).toBe(manifest.guard && manifest.plausibility ? manifest.guard.samples : null);
  });

  it('states both varieties as the manifest ships them', () => {
    const research = researchText(facts);
    expect(research).toContain(`it starts at ${manifest.defaultTemperature}`);
    if (manifest.leaderTemperature !== undefined) expect(research).toContain(`the leader model keeps ${manifest.leaderTemperature}`);
    else expect(research).toContain('the leader model dances with the same');
    // Another manifest, other words: nothing is written in.
    const other = researchText(helpFacts({ ...manifest, leaderTemperature: 0.85 }, 0.35));
    expect(other).toContain('it starts at 0.35');
    expect(other).toContain('the leader model keeps 0.85');
    expect(researchText(helpFacts({ ...manifest, leaderTemperature: undefined }, 0.35))).toContain('the leader model dances with the same');
    if (manifest.leadingTemperature !== undefined) expect(research).toContain(`${manifest.leadingTemperature} while he leads a turn you asked for`);
    expect(researchText(helpFacts({ ...manifest, leadingTemperature: 0.95 }, 0.35))).toContain('0.95 while he leads a turn you asked for');
    expect(researchText(helpFacts({ ...manifest, leadingTemperature: undefined }, 0.35))).not.toContain('while he leads');
  });

  it('every number it states is one the page has', () => {
    const page = new Set<number>([
      manifest.fps,
      variety,
      ...(facts.leaderVariety === null ? [] : [facts.leaderVariety]),
      ...(facts.leadingVariety === null ? [] : [facts.leadingVariety]),
      ...(facts.uprightSamples === null ? [] : [facts.uprightSamples]),
      CLIP_SECONDS,
      ...LIMITS.tempo,
      LIMITS.ghosts[1],
    ]);
    const texts: [string, string][] = [
      ...methodText(facts).map((t): [string, string] => ['method', t]),
      ...BRIEF.map(([term, text]): [string, string] => [`brief "${term}"`, text]),
      ...Object.values(CONTROLS).map(([term, text]): [string, string] => [`control "${term}"`, text]),
      ['keys', keysText()],
      ['research names', researchText(facts)],
    ];
    const strange = texts.flatMap(([where, text]) => numbers(text).filter((n) => !page.has(n)).map((n) => `${where}: ${n}`));
    expect(strange).toEqual([]);
    // And the ones it must state.
    expect(methodText(facts)[0]).toContain(`${manifest.fps} times a second`);
    expect(CONTROLS.tempo[1]).toContain(`${LIMITS.tempo[0]}-${LIMITS.tempo[1]}`);
    expect(CONTROLS.ghosts[1]).toContain(`Up to ${LIMITS.ghosts[1]}`);
    expect(keysText()).toContain(`${CLIP_SECONDS} s video`);
  });

  it('names the keys the page reads, and the turn buttons say what they do today', () => {
    for (const key of ['arrows', 'WASD', 'T', 'Shift+T', 'Space', 'R ', 'double-click', 'double-tap', 'Enter']) expect(keysText()).toContain(key);
    for (const [hand, key] of [['right', 'T'], ['left', 'Shift+T']]) {
      const title = turnTitle(hand as 'right' | 'left', key);
      expect(title).toContain(`his ${hand} hand`);
      expect(title).toContain(`(${key})`);
      // The hand names her way: his right hand leads her turn to her right (rollout lead_plan).
      expect(title).toContain(`lead a turn to her ${hand}`);
      expect(title).toContain('most of her turns go that way');
    }
    expect(keysText()).toContain('T: your dancer raises his right hand over her and turns to lead her turn to her right');
    expect(keysText()).toContain('Shift+T his left, to her left');
    const brief = BRIEF.map(([term, text]) => `${term} ${text}`).join('\n');
    expect(brief).toContain('leading her turn that way');
    expect(brief).not.toMatch(/↻|↺/);
  });

  it('the brief names every control of the panel', () => {
    const terms = BRIEF.map(([term]) => term).join(' · ');
    for (const key of ['model', 'temperature', 'tempo', 'music', 'figures', 'ghosts', 'trajectories', 'intentions', 'skeleton', 'view', 'share'] as const) {
      expect(terms).toContain(CONTROLS[key][0]);
    }
  });
});
