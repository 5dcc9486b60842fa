// The salsa groove the page plays, and its clock: the count the dancers read.
//
// Loaded only when the music starts (web/ui/music.ts imports it on the first key or tap), so the
// page's first dancing frame never waits for it. The band's two measures are rendered once per
// tempo into an audio buffer (OfflineAudioContext, off the main thread) and played as a loop by
// the audio thread itself: nothing the page's main thread does (stepping the networks, drawing,
// a garbage collection) can delay or drop a note. A note-by-note scheduler on a timer dropped 110
// of 238 eighth notes on a machine whose two cores were busy with other work; the loop drops none.
// A new tempo is rendered in the background and takes over on a beat.
//
// The count: whole beats fall on the beats, 0 on the first one; a measure is 8 beats, counted 1-8
// (beat 0 is the 1). The recording carries the beat and the two-beat group, not the measure
// (training/data/count.py), so the dancers hear the beat and which beat of a pair it is; the 1 is
// the band's. What the dancers read is `heardBeat()`: the count of the sound leaving the speakers
// now, so picture and sound agree.

import { bass, clave, conga, cowbell, piano, type CongaStroke } from './instruments';
import { heardTime } from './clock';

const LOOP_BEATS = 16; // two measures: the chords go I-IV-V-IV, one per half measure
const EIGHTHS = 16; // a measure of 8 beats in eighth notes
const TAIL = 1.5; // s rendered past the loop's end for notes still ringing: folded onto its start
const SWITCH_AHEAD = 0.15; // s: a new tempo takes over on the first beat at least this far ahead

// One measure of the band, in eighth notes from the 1 (0-15). Son clave 3-2: three strokes in the
// first half, two in the second.
const CLAVE = [0, 3, 6, 10, 12];
// The cowbell on every beat, the 1 and the 5 louder.
const COWBELL = [0, 2, 4, 6, 8, 10, 12, 14];
// Conga tumbao, each half measure: heel on 1, slap on 2, heel on 3, two open tones on 4 and its "and".
const TUMBAO: [number, CongaStroke][] = [[0, 'heel'], [2, 'slap'], [4, 'heel'], [6, 'open'], [7, 'low']];
// Chords by half measure (I-IV-V-IV over two measures): the bass's root and fifth (Hz) and the
// piano's voicing.
const CHORDS: { root: number; fifth: number; voicing: number[] }[] = [
  { root: 65.41, fifth: 98.0, voicing: [261.63, 329.63, 392.0] }, // C
  { root: 87.31, fifth: 130.81, voicing: [349.23, 440.0, 523.25] }, // F
  { root: 98.0, fifth: 146.83, voicing: [392.0, 493.88, 587.33] }, // G
  { root: 87.31, fifth: 130.81, voicing: [349.23, 440.0, 523.25] }, // F
];
// Bass tumbao, each half measure: the fifth on "2 and", the next chord's root anticipated on 4.
// Piano montuno: off-beat chords.
const MONTUNO = [1, 3, 4, 6];

/** Every note of the two measures, at `at` seconds from the loop's start; returns how many. */
function band(ctx: BaseAudioContext, out: AudioNode, bpm: number): number {
  const beat = 60 / bpm;
  let notes = 0;
  for (let eighth = 0; eighth < 2 * LOOP_BEATS; eighth++) {
    const at = (eighth * beat) / 2;
    const e = eighth % EIGHTHS; // position in the measure
    const h = e % 8; // position in the half measure
    const half = Math.floor(eighth / 8);
    const chord = CHORDS[half % 4];
    const next = CHORDS[(half + 1) % 4];
    if (CLAVE.includes(e)) { clave(ctx, out, at); notes++; }
    if (COWBELL.includes(e)) { cowbell(ctx, out, at, e === 0 || e === 8 ? 1 : 0.6); notes++; }
    for (const [pos, stroke] of TUMBAO) if (pos === h) { conga(ctx, out, at, stroke); notes++; }
    if (h === 3) { bass(ctx, out, at, chord.fifth, 1.5 * beat); notes++; }
    if (h === 6) { bass(ctx, out, at, next.root, 2.5 * beat); notes++; }
    if (MONTUNO.includes(h)) { piano(ctx, out, at, h === 6 ? next.voicing : chord.voicing, h === 1 ? 0.8 : 1); notes++; }
  }
  return notes;
}

/** The two measures at a tempo as one seamless loop (what rings past its end is folded onto its start). */
export async function renderLoop(bpm: number, sampleRate: number): Promise<{ buffer: AudioBuffer; notes: number }> {
  const loopSeconds = (LOOP_BEATS * 60) / bpm;
  const length = Math.ceil((loopSeconds + TAIL) * sampleRate);
  const offline = new OfflineAudioContext(2, length, sampleRate);
  const notes = band(offline, offline.destination, bpm);
  const rendered = await offline.startRendering();
  const loopLength = Math.round(loopSeconds * sampleRate);
  const buffer = new AudioBuffer({ numberOfChannels: 2, length: loopLength, sampleRate });
  for (let c = 0; c < 2; c++) {
    const from = rendered.getChannelData(c);
    const to = buffer.getChannelData(c);
    to.set(from.subarray(0, loopLength));
    for (let i = loopLength; i < from.length; i++) to[(i - loopLength) % loopLength] += from[i];
  }
  return { buffer, notes };
}

export class Groove {
  readonly output: GainNode;
  private bpm: number;
  // The clock's anchor: at audio time t0 the count was b0.
  private t0: number;
  private b0: number;
  private source: AudioBufferSourceNode | null = null;
  /** The tempo asked for last (a render for it may still be under way). */
  private wanted: number;
  /** Notes in the loops rendered so far (the tests read it: the band is playing). */
  scheduled = 0;
  /** Notes that could not be played: always 0 (the loop plays on the audio thread). */
  readonly dropped = 0;

  private constructor(readonly ctx: AudioContext, bpm: number, beat: number) {
    this.bpm = this.wanted = bpm;
    this.output = ctx.createGain();
    this.output.gain.value = 0.8;
    this.output.connect(ctx.destination);
    this.t0 = heardTime(ctx);
    this.b0 = beat;
  }

  /** The band playing from now on, the count going on from `beat` (the dance's silent count). */
  static async start(ctx: AudioContext, bpm: number, beat: () => number): Promise<Groove> {
    const { buffer, notes } = await renderLoop(bpm, ctx.sampleRate);
    const groove = new Groove(ctx, bpm, beat());
    groove.scheduled += notes;
    groove.play(buffer, ctx.currentTime + 0.05);
    return groove;
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

  /** Another tempo: rendered in the background, then it takes over on a beat; the count goes on. */
  async setTempo(bpm: number): Promise<void> {
    this.wanted = bpm;
    const { buffer, notes } = await renderLoop(bpm, this.ctx.sampleRate);
    if (this.wanted !== bpm || !this.source) return; // another tempo was asked meanwhile, or stopped
    this.scheduled += notes;
    const at = this.timeAt(Math.ceil(this.beatAt(this.ctx.currentTime + SWITCH_AHEAD)));
    const beat = this.beatAt(at);
    this.t0 = at;
    this.b0 = beat;
    this.bpm = bpm;
    this.play(buffer, at);
  }

  /** Silence at once (a new Groove starts the music again). */
  stop(): void {
    this.source?.stop();
    this.source = null;
    this.output.gain.setTargetAtTime(0, this.ctx.currentTime, 0.02);
    setTimeout(() => this.output.disconnect(), 200);
  }

  /** Play a loop from audio time `at`, at the place in it the count then falls on. */
  private play(buffer: AudioBuffer, at: number): void {
    const old = this.source;
    const source = this.ctx.createBufferSource();
    source.buffer = buffer;
    source.loop = true;
    source.connect(this.output);
    const into = ((((this.beatAt(at) % LOOP_BEATS) + LOOP_BEATS) % LOOP_BEATS) * 60) / this.bpm;
    source.start(at, into);
    old?.stop(at);
    this.source = source;
  }
}
