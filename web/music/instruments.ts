// The salsa band's voices, made in the page with the Web Audio API: nothing recorded ships. Each
// voice schedules one note at an audio-clock time `at` into `out` (the groove's master gain) and
// lets go of its nodes when the note ends (an oscillator that stopped is collected).

/** One second of white noise, made once per audio context: the slap's and the guiro-like hiss. */
const noiseBuffers = new WeakMap<BaseAudioContext, AudioBuffer>();
function noise(ctx: BaseAudioContext): AudioBuffer {
  let buffer = noiseBuffers.get(ctx);
  if (!buffer) {
    buffer = ctx.createBuffer(1, ctx.sampleRate, ctx.sampleRate);
    const data = buffer.getChannelData(0);
    // A fixed sequence (not Math.random): the same groove every visit.
    let s = 0x2545f491;
    for (let i = 0; i < data.length; i++) {
      s ^= s << 13; s ^= s >>> 17; s ^= s << 5;
      data[i] = ((s >>> 0) / 0xffffffff) * 2 - 1;
    }
    noiseBuffers.set(ctx, buffer);
  }
  return buffer;
}

/** A gain that rises in `attack` s to `peak` and falls exponentially to silence by `at + length`. */
function envelope(ctx: BaseAudioContext, at: number, peak: number, length: number, attack = 0.002): GainNode {
  const g = ctx.createGain();
  g.gain.setValueAtTime(0.0001, at);
  g.gain.exponentialRampToValueAtTime(peak, at + attack);
  g.gain.exponentialRampToValueAtTime(0.0001, at + length);
  return g;
}

function tone(ctx: BaseAudioContext, out: AudioNode, type: OscillatorType, hz: number, at: number, length: number, peak: number, bendTo?: number): void {
  const osc = ctx.createOscillator();
  osc.type = type;
  osc.frequency.setValueAtTime(hz, at);
  if (bendTo) osc.frequency.exponentialRampToValueAtTime(bendTo, at + Math.min(0.06, length));
  const g = envelope(ctx, at, peak, length);
  osc.connect(g).connect(out);
  osc.start(at);
  osc.stop(at + length + 0.02);
}

/** Claves: two hardwood sticks, a bright knock near 2.5 kHz that dies in a few hundredths. */
export function clave(ctx: BaseAudioContext, out: AudioNode, at: number, level = 1): void {
  tone(ctx, out, 'sine', 2500, at, 0.07, 0.5 * level);
  tone(ctx, out, 'sine', 1700, at, 0.04, 0.15 * level);
}

/** Cowbell (the campana): two detuned square waves through a band-pass, a short metallic ring. */
export function cowbell(ctx: BaseAudioContext, out: AudioNode, at: number, level = 1): void {
  const band = ctx.createBiquadFilter();
  band.type = 'bandpass';
  band.frequency.value = 900;
  band.Q.value = 1.5;
  const g = envelope(ctx, at, 0.22 * level, 0.28);
  band.connect(g).connect(out);
  for (const hz of [560, 835]) {
    const osc = ctx.createOscillator();
    osc.type = 'square';
    osc.frequency.value = hz;
    osc.connect(band);
    osc.start(at);
    osc.stop(at + 0.3);
  }
}

export type CongaStroke = 'open' | 'low' | 'slap' | 'heel';

/** Conga: open tones ring with a small drop in pitch, the slap cracks, the heel barely sounds. */
export function conga(ctx: BaseAudioContext, out: AudioNode, at: number, stroke: CongaStroke, level = 1): void {
  if (stroke === 'open') tone(ctx, out, 'sine', 240, at, 0.32, 0.55 * level, 205);
  else if (stroke === 'low') tone(ctx, out, 'sine', 185, at, 0.38, 0.55 * level, 160);
  else if (stroke === 'heel') tone(ctx, out, 'sine', 130, at, 0.08, 0.18 * level, 110);
  else {
    tone(ctx, out, 'triangle', 380, at, 0.09, 0.3 * level, 300);
    const src = ctx.createBufferSource();
    src.buffer = noise(ctx);
    const high = ctx.createBiquadFilter();
    high.type = 'highpass';
    high.frequency.value = 1200;
    const g = envelope(ctx, at, 0.35 * level, 0.06, 0.001);
    src.connect(high).connect(g).connect(out);
    src.start(at, 0, 0.08);
  }
}

/** Bass: a plucked low note (sawtooth through a closing low-pass), held `length` seconds. */
export function bass(ctx: BaseAudioContext, out: AudioNode, at: number, hz: number, length: number, level = 1): void {
  const osc = ctx.createOscillator();
  osc.type = 'sawtooth';
  osc.frequency.value = hz;
  const low = ctx.createBiquadFilter();
  low.type = 'lowpass';
  low.frequency.setValueAtTime(900, at);
  low.frequency.exponentialRampToValueAtTime(220, at + 0.25);
  const g = ctx.createGain();
  g.gain.setValueAtTime(0.0001, at);
  g.gain.exponentialRampToValueAtTime(0.42 * level, at + 0.01);
  g.gain.exponentialRampToValueAtTime(0.22 * level, at + 0.2);
  g.gain.setValueAtTime(0.22 * level, at + Math.max(0.21, length - 0.05));
  g.gain.exponentialRampToValueAtTime(0.0001, at + length);
  osc.connect(low).connect(g).connect(out);
  osc.start(at);
  osc.stop(at + length + 0.02);
}

/** Piano (the montuno's chords): a few sine partials per note, struck and decaying. */
export function piano(ctx: BaseAudioContext, out: AudioNode, at: number, hz: readonly number[], level = 1): void {
  for (const f of hz) {
    tone(ctx, out, 'triangle', f, at, 0.35, 0.07 * level);
    tone(ctx, out, 'sine', 2 * f, at, 0.2, 0.025 * level);
  }
}
