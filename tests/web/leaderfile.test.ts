// The check of a leader file (web/ui/leaderfile.ts): a BVH holding what no dancer can do -- a hip
// 1e30, 1e15 or 1e9 m away, a rotation of 1e30 degrees, a hip that jumps, a giant bone -- is
// refused with a message naming the quantity, the frame, the value and the bound; real recordings
// (the page's own, written by its BVH writer, and the Python fixture of the CMU skeleton) pass.

import { describe, expect, it } from 'vitest';
import { parseBvh } from '../../web/mirror/bvh';
import { N_JOINTS, ROTATIONS_SIZE } from '../../web/mirror/skeleton';
import { rotationsFromVectors } from '../../web/mirror/rollout';
import { axisRotation, matmul3 } from '../../web/mirror/bvh';
import { CHANNELS_PER_FRAME, writeBvhFromWorld } from '../../web/ui/bvhwriter';
import { leaderMotionFromText } from '../../web/ui/dropzone';
import { DuetError } from '../../web/ui/errors';
import { fixture } from './fixture';

const rollout = fixture('rollout');
const OFFSETS = Float64Array.from(rollout.offsets.leader as number[]);

/**
 * The page's own recording of a leader (the format of "download BVH"): the start pose of the
 * shipped models, walking at `speed` m/s while turning `turnsPerSecond` about its hip, its arms
 * swinging. Written by the page's BVH writer, which unwraps angles from frame to frame, so a
 * dancer that keeps turning one way has ever larger rotation channels.
 */
function recording(frames = 90, { speed = 0.5, turnsPerSecond = 0.1 } = {}): string {
  const start = rollout.startPose.leader;
  const pose = new Float64Array(ROTATIONS_SIZE);
  rotationsFromVectors(start.forward.flat(), start.up.flat(), N_JOINTS, pose);
  const hips = new Float64Array(frames * 3);
  const rotations = new Float64Array(frames * ROTATIONS_SIZE);
  const turn = new Float64Array(9);
  const swing = new Float64Array(9);
  const swung = new Float64Array(9);
  let x = start.hip[0];
  let z = start.hip[2];
  for (let f = 0; f < frames; f++) {
    const t = f / 30;
    const heading = 360 * turnsPerSecond * t;
    axisRotation('Y', heading, turn);
    x += (speed / 30) * Math.sin((heading * Math.PI) / 180);
    z += (speed / 30) * Math.cos((heading * Math.PI) / 180);
    hips.set([x, start.hip[1] + 0.02 * Math.sin(2 * Math.PI * t), z], 3 * f);
    for (let j = 0; j < N_JOINTS; j++) {
      const at = f * ROTATIONS_SIZE + 9 * j;
      if (j === 6 || j === 9) {
        // forearms swing
        axisRotation('X', 20 * Math.sin(2 * Math.PI * t), swing);
        matmul3(pose, 9 * j, swing, 0, swung, 0);
        matmul3(turn, 0, swung, 0, rotations, at);
      } else {
        matmul3(turn, 0, pose, 9 * j, rotations, at);
      }
    }
  }
  return writeBvhFromWorld({ offsets: OFFSETS, frames, hips, rotations });
}

/** `text` with channel `channel` (0..53 of the writer's order) of frames [from, from + count) set to `value`. */
function withValue(text: string, channel: number | number[], value: string, from = 20, count = 10): string {
  const lines = text.split('\n');
  const first = lines.findIndex((l) => l.startsWith('Frame Time:')) + 1;
  for (let f = from; f < from + count; f++) {
    const row = lines[first + f].split(' ');
    expect(row.length).toBe(CHANNELS_PER_FRAME);
    for (const c of [channel].flat()) row[c] = value;
    lines[first + f] = row.join(' ');
  }
  return lines.join('\n');
}

/** The message a refused file gets (title: detail); fails when the file is accepted. */
function refusal(text: string, name = 'take.bvh'): string {
  try {
    leaderMotionFromText(text, name);
  } catch (error) {
    expect(error).toBeInstanceOf(DuetError);
    return `${(error as DuetError).title}: ${(error as DuetError).detail}`;
  }
  throw new Error(`${name} was accepted`);
}

// The writer's channels: hip Xposition Yposition Zposition Zrotation Xrotation Yrotation, then
// Zrotation Xrotation Yrotation for each other joint in JOINT_NAMES order (lShin is joint 12).
const HIP_POSITION = [0, 1, 2];
const LSHIN_X = 6 + 3 * 11 + 1;

describe('leader files: what a dancer can do', () => {
  it("the page's own recordings pass", () => {
    expect(leaderMotionFromText(recording(), 'duet-leader.bvh').frames).toBe(90);
    // Turning one way for 2 minutes, 2 turns a second: the writer unwraps the hip's angle to
    // 86 400 degrees. A real recording, so the rotation bound must allow it.
    const spinning = recording(3600, { speed: 0.3, turnsPerSecond: 2 });
    const hipYrotation = Number(spinning.trim().split('\n').pop()!.split(' ')[5]);
    expect(Math.abs(hipYrotation)).toBeGreaterThan(80_000);
    expect(leaderMotionFromText(spinning, 'spin.bvh').frames).toBe(3600);
  });

  it('the Python fixture of the CMU skeleton (120 fps, collars and buttocks) passes', () => {
    const full = fixture('bvh').full;
    expect(leaderMotionFromText(full.text, 'cmu.bvh').frames).toBe(Math.ceil(full.frames / 4));
  });

  it.each([['1e30', '1.00e+30'], ['1e15', '1.00e+15'], ['1e9', '1.00e+9']])(
    'hip positions of 10 frames set to %s: refused, naming the hip, the frame, the value and the bound',
    (value, shown) => {
      const text = refusal(withValue(recording(), HIP_POSITION, value), 'duet-leader.bvh');
      expect(text).toMatch(/^Cannot dance duet-leader\.bvh: /);
      expect(text).toMatch(/hip/);
      expect(text).toMatch(/frame 21 of 90/); // frames counted from 1, as in animation tools
      expect(text).toContain(shown);
      expect(text).toMatch(/1000 m/);
    },
  );

  it('a hip height no dancer has: refused with the height and its range', () => {
    const text = refusal(withValue(recording(), 1, '1e30'));
    expect(text).toMatch(/hip height.*frame 21 of 90.*1\.50e\+30 m.*between -1 and 3 m/);
    expect(refusal(withValue(recording(), 1, '4'))).toMatch(/hip height.*frame 21 of 90.*6 m/);
  });

  it('a hip that jumps: refused with its speed and the bound', () => {
    // 2 BVH units (3 m) to the side for one frame: inside the floor, but 90 m/s.
    const lines = recording().split('\n');
    const first = lines.findIndex((l) => l.startsWith('Frame Time:')) + 1;
    const row = lines[first + 40].split(' ');
    row[0] = String(Number(row[0]) + 2);
    lines[first + 40] = row.join(' ');
    expect(refusal(lines.join('\n'))).toMatch(/hip moves at 9\d(\.\d)? m\/s from frame 40 to frame 41 of 90.*under 15 m\/s/);
  });

  it('1e30 in a rotation channel: refused, naming the joint, the channel, the frame, the value and the bound', () => {
    const text = refusal(withValue(recording(), LSHIN_X, '1e30'));
    expect(text).toMatch(/lShin Xrotation in frame 21 of 90 is 1\.00e\+30°/);
    expect(text).toMatch(/1,000,000°/);
    expect(refusal(withValue(recording(), 3, '-2e6'))).toMatch(/hip Zrotation in frame 21 of 90 is -2\.00e\+6°/);
  });

  it('NaN or infinity anywhere: refused, naming the channel and the frame', () => {
    expect(refusal(withValue(recording(), LSHIN_X, 'nan'))).toMatch(/lShin Xrotation in frame 21 of 90 is NaN/);
    expect(refusal(withValue(recording(), 0, 'Infinity'))).toMatch(/hip Xposition in frame 21 of 90 is Infinity/);
  });

  it('bones no dancer has: refused with the bone, its length and the bound', () => {
    // One bone 1.5 m long (1 BVH unit), the rest of the skeleton of normal size.
    const text = recording().replace(/(JOINT lShin\n\s*\{\n\s*OFFSET) \S+ \S+ \S+/, '$1 0 -1 0');
    expect(refusal(text)).toMatch(/lShin.*1\.5 m.*at most 1 m/);
    // A bone that is not a number.
    expect(refusal(recording().replace(/(JOINT lShin\n\s*\{\n\s*OFFSET) \S+/, '$1 nan'))).toMatch(/OFFSET of lShin.*NaN/);
  });

  it('a position channel on a joint other than the hip moves it at most a bone away', () => {
    const bvh = parseBvh(recording());
    expect(bvh.channels[12]).toEqual(['Zrotation', 'Xrotation', 'Yrotation']);
    const text = recording()
      .replace(/(JOINT lShin\n\s*\{\n\s*OFFSET \S+ \S+ \S+\n\s*CHANNELS) 3/, '$1 4 Yposition');
    // Give every frame's lShin a Yposition of -0.28 units (0.42 m), one frame 10 units (15 m).
    const lines = text.split('\n');
    const first = lines.findIndex((l) => l.startsWith('Frame Time:')) + 1;
    const at = 6 + 3 * 11;
    for (let f = 0; f < 90; f++) {
      const row = lines[first + f].split(' ');
      row.splice(at, 0, f === 30 ? '10' : '-0.28');
      lines[first + f] = row.join(' ');
    }
    expect(refusal(lines.join('\n'))).toMatch(/lShin Yposition in frame 31 of 90 is 10 units \(15 m\).*at most 1 m/);
  });
});

describe('leader files that are broken: the problem in plain words, not the reader\'s', () => {
  const plain = (text: string) => refusal(text).replace(/\u202f/g, ' ');

  it('cut short: where it ends, against what its header announces', () => {
    const text = recording(); // 90 frames of 54 numbers, one line each, then a newline
    const lines = text.split('\n');
    const first = lines.findIndex((l) => l.startsWith('Frame Time:')) + 1;
    // In the middle of frame 41: 40 whole frames and 7 numbers of the next.
    const in41 = [...lines.slice(0, first + 40), lines[first + 40].split(' ').slice(0, 7).join(' ')].join('\n');
    expect(plain(in41)).toBe('Cannot dance take.bvh: The file is cut short: it ends in frame 41 of the 90 it announces ' +
      '(it holds 2 167 of the 4 860 numbers they need). Download or record it again.');
    // After a whole frame; the last number cut off in its middle ("-12.5" as "-").
    expect(plain(lines.slice(0, first + 60).join('\n'))).toMatch(/cut short: it ends after frame 60 of the 90/);
    expect(plain(text.trimEnd().slice(0, text.trimEnd().lastIndexOf(' ') + 1) + '-')).toMatch(/cut short: it ends in the middle of the last number of frame 90 \("-"\)/);
    // Inside the skeleton, at any point; right after MOTION.
    for (const cut of [12, 300, text.indexOf('MOTION') - 3]) {
      expect(plain(text.slice(0, cut))).toMatch(/cut short: it ends inside the skeleton \(HIERARCHY\), before the motion \(MOTION\) begins/);
    }
    expect(plain(text.slice(0, text.indexOf('MOTION') + 7))).toMatch(/cut short: it ends right after MOTION/);
  });

  it('other damage: braces, words where numbers belong, the frame count', () => {
    const text = recording();
    expect(plain(text.replace(/\n\s*\}\n/, '\n'))).toMatch(/22 opening braces \{ and 21 closing braces \}: a closing brace is missing/);
    expect(plain(text.replace('OFFSET', 'OFSET'))).toMatch(/skeleton \(HIERARCHY\) holds "OFSET" \(line 4\)/);
    expect(plain(withValue(text, 7, 'abc', 4, 1))).toMatch(/holds "abc" where a number should be \(line \d+: frame 5\)/);
    expect(plain(text.replace(/Frames: 90/, 'Frames: 91'))).toMatch(/cut short: it ends after frame 90 of the 91/);
    expect(plain(text.replace(/Frames: 90/, 'Frames: 89'))).toMatch(/holds 4 860 numbers where its 89 frames of 54 channels make 4 806/);
    expect(plain(text.replace(/Frames: 90/, 'Frames: 9.5'))).toMatch(/"Frames:" line says 9\.5/);
    expect(plain(text.replace(/Frame Time: \S+/, 'Frame Time: 0'))).toMatch(/"Frame Time:" is 0 s; it must be above zero/);
    expect(plain(text.replace('MOTION', 'MOTON'))).toMatch(/no motion: its MOTION section is missing/);
    // No message is the reader's own: no exception names, no "list index", no file name prefix.
    for (const cut of [5, 40, 900, 2000, text.length - 200]) {
      const message = refusal(text.slice(0, cut));
      expect(message).not.toMatch(/Error|list index|malformed|take\.bvh: take\.bvh/);
    }
  });
});
