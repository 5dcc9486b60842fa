// The salsa groove the page plays, and its clock: the count the dancers read.
//
// Loaded only when the music starts (web/ui/music.ts imports it on the first key or tap), so the
// page's first dancing frame never waits for it. Notes are scheduled ahead on the audio clock: a
// timer every 25 ms schedules what falls in the next 200 ms, so a busy main thread delays the timer,
// never a note. Only a stall longer than the lookahead (175 ms of main thread held) would leave a
// note's time behind the clock: it is dropped rather than played late, and counted (`dropped`).
//
// The count: whole beats fall on the beats, 0 on the first one; a measure is 8 beats, counted 1-8
// (beat 0 is the 1). The recording carries the beat and the two-beat group, not the measure
// (training/data/count.py), so the dancers hear the beat and which beat of a pair it is; the 1 is
// the band's. What the dancers read is `heardBeat()`: the count at the moment the sound now
// leaving the speakers was scheduled for, so picture and sound agree.

import { bass, clave, conga, cowbell, piano, type CongaStroke } from './instruments';

const LOOKAHEAD = 0.2; // s scheduled ahead of the audio clock
const TICK_MS = 25; // how often the scheduler looks
const EIGHTHS = 16; // a measure of 8 beats in eighth notes

// One measure of the band, in eighth notes from the 1 (0-15). Son clave 3-2: three strokes in the
// first half, two in the second.
const CLAVE = [0, 3, 6, 10, 12];
// The cowbell on every beat, the 1 and the 5 louder.
const COWBELL = [0, 2, 4, 6, 8, 10, 12, 14];
// Conga tumbao, each half measure: heel on 1, slap on 2, heel on 3, two open tones on 4 and its "and".
const TUMBAO: [number, CongaStroke][] = [[0, 'heel'], [2, 'slap'], [4, 'heel'], [6, 'open'], [7, 'low']];
// Chords by half measure (I-IV-V-IV over two measures): roots (Hz, an octave below the bass's
// lowest note doubled) and the piano's voicing.
const CHORDS: { root: number; fifth: number; voicing: number[] }[] = [
  { root: 65.41, fifth: 98.0, voicing: [261.63, 329.63, 392.0] }, // C
  { root: 87.31, fifth: 130.81, voicing: [349.23, 440.0, 523.25] }, // F
  { root: 98.0, fifth: 146.83, voicing: [392.0, 493.88, 587.33] }, // G
  { root: 87.31, fifth: 130.81, voicing: [349.23, 440.0, 523.25] }, // F
];
// Bass tumbao, each half measure: the fifth on "2 and", the next chord's root anticipated on 4.
// Piano montuno: off-beat chords.
const MONTUNO = [1, 3, 4, 6];

/** The audio clock's time a listener hears now (what leaves the speakers), seconds. */
export function heardTime(ctx: AudioContext): number {
  const stamp = ctx.getOutputTimestamp?.();
  if (stamp && stamp.contextTime !== undefined && stamp.performanceTime !== undefined && stamp.contextTime > 0) {
    return stamp.contextTime + (performance.now() - stamp.performanceTime) / 1000;
  }
  return ctx.currentTime - (ctx.outputLatency || ctx.baseLatency || 0);
}

export class Groove {
  readonly output: GainNode;
  private bpm: number;
  // The clock's anchor: at audio time t0 the count was b0.
  private t0 = 0;
  private b0 = 0;
  private nextEighth = 0;
  private timer: ReturnType<typeof setInterval> | null = null;
  /** Notes scheduled since the start (the tests read it: the band is playing). */
  scheduled = 0;
  /** Eighth notes whose time had passed before the timer came (a main thread held > 175 ms). */
  dropped = 0;

  /** Starts playing at once, the count going on from `beat` (the dance's silent count so far). */
  constructor(readonly ctx: AudioContext, bpm: number, beat: number) {
    this.bpm = bpm;
    this.output = ctx.createGain();
    this.output.gain.value = 0.8;
    this.output.connect(ctx.destination);
    this.t0 = heardTime(ctx);
    this.b0 = beat;
    this.nextEighth = Math.ceil(2 * this.beatAt(ctx.currentTime + 0.02));
    this.timer = setInterval(() => this.schedule(), TICK_MS);
    this.schedule();
  }

  get tempo(): number {
    return this.bpm;
  }

  /** The count at an audio-clock time. */
  beatAt(time: number): number {
    return this.b0 + ((time - this.t0) * this.bpm) / 60;
  }

  /** The audio-clock time of a count. */
  timeAt(beat: number): number {
    return this.t0 + ((beat - this.b0) * 60) / this.bpm;
  }

  /** The count the listener hears now. */
  heardBeat(): number {
    return this.beatAt(heardTime(this.ctx));
  }

  /** Another tempo from now on: the count goes on from where it is, only faster or slower. */
  setTempo(bpm: number): void {
    const now = heardTime(this.ctx);
    this.b0 = this.beatAt(now);
    this.t0 = now;
    this.bpm = bpm;
    // Notes already scheduled keep their times; the next one is the first not yet scheduled.
  }

  /** Silence at once, and the timer stopped (a new Groove starts the music again). */
  stop(): void {
    if (this.timer !== null) clearInterval(this.timer);
    this.timer = null;
    const g = this.output.gain;
    g.setTargetAtTime(0, this.ctx.currentTime, 0.02);
    setTimeout(() => this.output.disconnect(), 200);
  }

  private schedule(): void {
    if (this.ctx.state !== 'running') return;
    const horizon = this.ctx.currentTime + LOOKAHEAD;
    for (;;) {
      const at = this.timeAt(this.nextEighth / 2);
      if (at > horizon) break;
      if (at >= this.ctx.currentTime) this.play(this.nextEighth, at);
      else this.dropped += 1;
      this.nextEighth += 1;
    }
  }

  private play(eighth: number, at: number): void {
    const ctx = this.ctx;
    const out = this.output;
    const e = ((eighth % EIGHTHS) + EIGHTHS) % EIGHTHS; // position in the measure
    const h = e % 8; // position in the half measure
    const half = Math.floor(eighth / 8);
    const chord = CHORDS[((half % 4) + 4) % 4];
    const next = CHORDS[(((half + 1) % 4) + 4) % 4];
    const beatLength = 60 / this.bpm;
    if (CLAVE.includes(e)) { clave(ctx, out, at); this.scheduled++; }
    if (COWBELL.includes(e)) { cowbell(ctx, out, at, e === 0 || e === 8 ? 1 : 0.6); this.scheduled++; }
    for (const [pos, stroke] of TUMBAO) if (pos === h) { conga(ctx, out, at, stroke); this.scheduled++; }
    if (h === 3) { bass(ctx, out, at, chord.fifth, 1.5 * beatLength); this.scheduled++; }
    if (h === 6) { bass(ctx, out, at, next.root, 2.5 * beatLength); this.scheduled++; }
    if (MONTUNO.includes(h)) { piano(ctx, out, at, h === 6 ? next.voicing : chord.voicing, h === 1 ? 0.8 : 1); this.scheduled++; }
  }
}
