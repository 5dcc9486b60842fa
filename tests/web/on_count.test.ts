// web/mirror/on_count.ts against training/mirror/on_count.py: each dancer's footwork and count read
// from its input, the footwork its next step aims at over three steps (the mean carried between
// them), each sample's drawn steps, footwork and hips, and the choice among samples where all, some
// and none of them stand, a sample's hips weighed and not; the planted feet counted still; the figure being led read from the input
// (figureWay) and the candidates it prefers (OnCount.prefers with figureTurn).

import { describe, expect, it } from 'vitest';
import { FIGURE_SIZE, INPUT_SIZE, LEADER_INPUT_SIZE, OUTPUT_SIZE } from '../../web/mirror/features';
import { uprightBody } from '../../web/mirror/guard';
import {
  FIGURE_AHEAD, FIGURE_IN, FIGURE_TURN, MEAN_SECONDS, OWN_TURN, OnCount, TURNING, countNext, figureWay, drawnFootwork, drawnSteps, footworkNow, hipsTurnBack, nearestCount,
  planted, plannedTurn, startsTurn, turnNow, turnRate,
} from '../../web/mirror/on_count';
import { FPS } from '../../web/mirror/skeleton';
import { expectClose, fixture } from './fixture';

const data = fixture('rollout').onCount;

describe('the footwork each dancer aims at on the count', () => {
  for (const role of ['leader', 'follower'] as const) {
    it(`reads the ${role}'s footwork and count, and aims as Python does`, () => {
      const chooser = new OnCount(role, 4, 0.8);
      for (const step of data.roles[role]) {
        const x = Float32Array.from(step.input);
        expectClose([footworkNow(x, role)], step.footwork, `${role} footwork now`);
        expectClose([countNext(x)], step.count, `${role} count at the next step`);
        expectClose([turnRate(x, role)], step.turnRate, `${role} turn rate`);
        expectClose([turnNow(x, role)], step.turnNow, `${role} turn now`);
        const target = chooser.target(x);
        if (step.target === null) expect(target, `${role} turning: no target`).toBeNull();
        else expectClose([target as number], step.target, `${role} target`);
        expectClose([chooser.mean as number], step.mean, `${role} footwork mean`);
        chooser.took(Float32Array.from(step.took));
      }
    });
  }

  for (const role of ['leader', 'follower'] as const) {
    it(`counts the feet the ${role} planted as still in the footwork now`, () => {
      // each step taken plants the left foot, then the right (fixtures_writer.py): the next target
      // leaves that foot out of the footwork it moves the mean on by
      const [first, second] = data.roles[role];
      const chooser = new OnCount(role, 4, 0.8);
      chooser.target(Float32Array.from(first.input));
      const meanBefore = chooser.mean as number;
      chooser.took(Float32Array.from(first.took));
      expect(chooser.feet).toEqual([true, false]);
      chooser.target(Float32Array.from(second.input));
      const x = Float32Array.from(second.input);
      const rightOnly = footworkNow(x, role, [true, false]);
      expect(rightOnly).toBeLessThan(footworkNow(x, role));
      expectClose([chooser.mean as number], [meanBefore + (rightOnly - meanBefore) / (MEAN_SECONDS * FPS)], `${role} mean from the free foot`);
      chooser.restart(); // a new duet forgets both
      expect([chooser.mean, chooser.feet]).toEqual([null, null]);
    });
  }

  it('leaves a turn to the network: the last step of each role turns faster than TURNING', () => {
    for (const role of ['leader', 'follower'] as const) {
      const turning = data.roles[role].map((s: { turnRate: number[]; target: number[] | null }) => [s.turnRate[0] > TURNING[role], s.target === null]);
      expect(turning).toEqual([[false, false], [false, false], [true, true]]);
    }
  });

  it('refuses a chooser with fewer than two samples', () => {
    expect(() => new OnCount('leader', 1)).toThrow(/at least 2 samples/);
  });
});

describe('nearestCount', () => {
  const outputs = Float64Array.from(data.outputs);
  const input = Float64Array.from(data.input);
  const k = data.standing.length;
  const ranges = fixture('rollout').upright.ranges;
  const offsets = fixture('rollout').offsets.follower;

  it('draws each sample\'s body, its steps, footwork and hips as Python does', () => {
    const body = new Float64Array(3 * 17);
    const steps = new Float64Array(9);
    for (let i = 0; i < k; i++) {
      expectClose([uprightBody(outputs, i * OUTPUT_SIZE, ranges, offsets, 0, 0, body)], [data.standing[i]], `margin ${i}`);
      drawnSteps(outputs, i * OUTPUT_SIZE, body, input, 'follower', steps);
      expectClose(Array.from(steps), data.steps.slice(9 * i, 9 * i + 9), `steps ${i}`);
      expectClose([drawnFootwork(steps)], [data.footwork[i]], `footwork ${i}`);
      const feet = planted(Float64Array.from(data.planting), i * OUTPUT_SIZE, [false, false]);
      expect(feet, `planted ${i}`).toEqual(data.planted[i]);
      expectClose([drawnFootwork(steps, feet)], [data.footworkStill[i]], `footwork, planted feet still, ${i}`);

      expect(hipsTurnBack(steps, input, 'follower'), `hips of ${i}`).toBe(data.turnBack[i]);
    }
    // the case the fixture is for: the first sample's hips turn back, the second's go on
    expect(data.turnBack.slice(0, 2)).toEqual([true, false]);
  });

  it('takes the standing sample nearest the target, its hips weighed, and none when none stands', () => {
    for (const [key, best] of Object.entries(data.best)) {
      const [margin, hips] = key.split('/').map(Number);
      expect(nearestCount(data.footwork, data.turnBack, k, data.target[0], data.standing, margin, hips), key).toBe(best);
    }
    // the cases where the choice matters: nearest, passed over for its hips, only one standing, none
    expect(new Set(Object.values(data.best))).toEqual(new Set([0, 1, -1]));
    expect(data.best['0.0/0.0']).toBe(0);
    expect(data.best['0.0/1.0']).toBe(1);
  });

  it('prefers the standing samples that start a turn when asked to, as Python does', () => {
    const turned = Float64Array.from(data.turned);
    for (let i = 0; i < k; i++) expect(plannedTurn(turned, i * OUTPUT_SIZE)).toBeCloseTo(data.plannedTurn[i], 4);
    for (const [degrees, expected] of Object.entries(data.starts)) {
      const started = Array.from({ length: k }, (_, i) => startsTurn(turned, i * OUTPUT_SIZE, Number(degrees)));
      expect(started, `starts from ${degrees}`).toEqual(expected);
    }
    for (const [key, best] of Object.entries(data.bestPreferred)) {
      const [margin, degrees] = key.split('/');
      expect(nearestCount(data.footwork, data.turnBack, k, data.target[0], data.standing, Number(margin), 1, data.starts[degrees]), key).toBe(best);
    }
    // where it matters: the nearest going on (1) starts no turn at 180, the first does; from 400
    // none does, and the choice is the one without a preference
    expect(data.best['-9.0/1.0']).toBe(1);
    expect(data.bestPreferred['-9.0/180.0']).toBe(0);
    expect(data.bestPreferred['-9.0/400.0']).toBe(data.best['-9.0/1.0']);
  });
});

describe('the figure being led, read by the choice', () => {
  const SIZE = { leader: LEADER_INPUT_SIZE, follower: INPUT_SIZE } as const;
  /** An input of the role's size, zeros but for the case's figure block (as Python built it). */
  const inputOf = (role: 'leader' | 'follower', figure: number[]) => {
    const x = new Float32Array(SIZE[role]);
    x.set(figure, FIGURE_IN[role]);
    return x;
  };
  const cases = (role: 'leader' | 'follower') => data.figureWays[role] as { name: string; figure: number[]; way: number | null }[];

  it('holds the figure where Python does, with the same constants', () => {
    expect(FIGURE_IN).toEqual(data.figureIn);
    expect(FIGURE_AHEAD).toBe(data.figureAhead);
    expect(FIGURE_TURN).toBe(data.figureTurn);
    expect(OWN_TURN).toEqual({ leader: 'his_turn', follower: 'her_turn' });
    for (const role of ['leader', 'follower'] as const) for (const c of cases(role)) expect(c.figure).toHaveLength(FIGURE_SIZE);
  });

  for (const role of ['leader', 'follower'] as const) {
    it(`reads the ${role}'s own turn now and within FIGURE_AHEAD, as Python does`, () => {
      for (const c of cases(role)) expect(figureWay(inputOf(role, c.figure), role), `${role} ${c.name}`).toBe(c.way);
    });
  }

  it('pins each kind now, coming and beyond, for both roles', () => {
    const way = (role: 'leader' | 'follower', name: string) => cases(role).find((c) => c.name === name)!.way;
    for (const role of ['leader', 'follower'] as const) {
      expect(way(role, 'none'), role).toBeNull();
      for (const kind of ['her_left', 'her_right', 'his_left', 'his_right']) {
        const own = kind.startsWith(role === 'leader' ? 'his' : 'her');
        const expected = own ? (kind.endsWith('left') ? 1 : -1) : 0;
        for (const when of ['now', 'next', 'ahead']) expect(way(role, `${kind}/${when}`), `${role} ${kind}/${when}`).toBe(expected);
        for (const when of ['beyond', 'past']) expect(way(role, `${kind}/${when}`), `${role} ${kind}/${when}`).toBeNull();
      }
    }
    // her turn and his at once: each dancer reads its own
    expect(way('leader', 'her and his')).toBe(1);
    expect(way('follower', 'her and his')).toBe(-1);
  });

  it('prefers the candidates the figure asks for, outside a turn, as Python does', () => {
    const figured = Float64Array.from(data.figured);
    const k = data.figuredTurn.length;
    expectClose(Array.from({ length: k }, (_, i) => plannedTurn(figured, i * OUTPUT_SIZE)), data.figuredTurn, 'planned turns');
    const byName = (role: 'leader' | 'follower', name: string) => inputOf(role, cases(role).find((c) => c.name === name)!.figure);
    const prefers = new Array<boolean>(k).fill(false);
    const seen = new Set<string>();
    for (const c of data.figurePrefers as { role: 'leader' | 'follower'; figureTurn: number | null; figure: string | null; turning: boolean; prefers: boolean[] | null }[]) {
      const chooser = new OnCount(c.role, 8, 1, 1, c.figureTurn);
      chooser.turning = c.turning;
      const label = `${c.role} figureTurn ${c.figureTurn} figure ${c.figure}${c.turning ? ' turning' : ''}`;
      prefers.fill(false);
      const got = chooser.prefers(figured, k, OUTPUT_SIZE, prefers, c.figure === null ? null : byName(c.role, c.figure));
      expect(got, label).toBe(c.prefers !== null);
      if (c.prefers !== null) expect(prefers, label).toEqual(c.prefers);
      seen.add(JSON.stringify(c.prefers));
    }
    // the cases differ: none preferred, those turning little, each way's turns, at each figureTurn
    expect(seen.size).toBeGreaterThanOrEqual(6);
    expect(() => new OnCount('follower', 8, 1, 1, 0)).toThrow(/figureTurn/);
  });
});
