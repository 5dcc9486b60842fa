// The page's music: started by the visitor's first key press or tap (browsers start audio only
// after a gesture), muted and re-tempoed from the panel, paused with the dance. The band itself
// (web/music/groove.ts, with its voices) is fetched when the music starts, never before the
// first dancing frame.
//
// While it plays, the dance reads its count from it (heardBeat: what the listener hears now);
// muted, paused for good, at a playback speed other than 1, or where the browser has no Web
// Audio, the dance keeps its own silent count at the same tempo (web/mirror/rollout.ts).

import type { Groove } from '../music/groove';
import { heardTime } from '../music/clock';


export type MusicState = 'waiting' | 'starting' | 'playing' | 'muted' | 'unavailable';

export class Music {
  private ctx: AudioContext | null = null;
  private groove: Groove | null = null;
  private starting: Promise<void> | null = null;
  private held = false;
  state: MusicState;
  /** Why the music could not start, when it could not. */
  problem = '';

  constructor(
    private tempo: number,
    private enabled: boolean,
    /** The dance's count now: the music joins it where it is, no jump. */
    private readonly danceBeat: () => number,
  ) {
    this.state = typeof AudioContext === 'undefined' ? 'unavailable' : enabled ? 'waiting' : 'muted';
  }

  /**
   * Called from a key or tap handler (a user gesture): makes the audio context there and then,
   * as Safari asks, and starts the band once its code is in. Later calls do nothing.
   */
  gesture(): void {
    if (this.state !== 'waiting' || this.starting) return;
    try {
      this.ctx ??= new AudioContext({ latencyHint: 'interactive' });
      void this.ctx.resume();
    } catch (error) {
      this.state = 'unavailable';
      this.problem = error instanceof Error ? error.message : String(error);
      return;
    }
    this.state = 'starting';
    this.starting = import('../music/groove')
      .then(async ({ Groove }) => {
        if (this.state !== 'starting' || !this.ctx) return; // muted while the code came
        const groove = await Groove.start(this.ctx, this.tempo, this.danceBeat);
        if (this.state !== 'starting') return groove.stop(); // muted while the band was rendered
        this.groove = groove;
        if (groove.tempo !== this.tempo) void groove.setTempo(this.tempo); // changed meanwhile
        this.state = 'playing';
        if (this.held) void this.ctx.suspend();
      })
      .catch((error: unknown) => {
        this.state = 'unavailable';
        this.problem = error instanceof Error ? error.message : String(error);
      })
      .finally(() => (this.starting = null));
  }

  /** The count the listener hears now, or null while no music plays (the dance counts alone). */
  heardBeat(): number | null {
    if (!this.groove || this.state !== 'playing' || this.held || this.ctx?.state !== 'running') return null;
    return this.groove.heardBeat();
  }

  /** The audio clock's time the listener hears now, seconds (null while no music plays). */
  heardTime(): number | null {
    if (!this.groove || !this.ctx || this.state !== 'playing') return null;
    return heardTime(this.ctx);
  }

  /** Notes in the band's rendered loops (0 before it starts), and notes it could not play (the
   *  loop plays on the audio thread: none). */
  get scheduled(): number {
    return this.groove?.scheduled ?? 0;
  }

  get dropped(): number {
    return this.groove?.dropped ?? 0;
  }

  /** The tempo the band plays now (a new one takes over once rendered); null before it plays. */
  get playingTempo(): number | null {
    return this.groove?.tempo ?? null;
  }

  get contextState(): string {
    return this.ctx?.state ?? 'none';
  }

  setTempo(bpm: number): void {
    this.tempo = bpm;
    if (this.groove) void this.groove.setTempo(bpm);
  }

  /** Mute (false) or play again (true, from the next gesture if none came yet). */
  setEnabled(on: boolean): void {
    if (on === this.enabled || this.state === 'unavailable') return;
    this.enabled = on;
    if (!on) {
      this.groove?.stop();
      this.groove = null;
      this.state = 'muted';
      return;
    }
    this.state = 'waiting';
    // A click in the panel is itself a gesture: start at once where the context exists or may.
    this.gesture();
  }

  /** Hold the music with the dance (pause, help open), or let it go on. */
  hold(held: boolean): void {
    if (held === this.held) return;
    this.held = held;
    if (!this.ctx || !this.groove) return;
    if (held) void this.ctx.suspend();
    else void this.ctx.resume();
  }
}
