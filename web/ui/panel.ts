// The settings panel (lil-gui). It edits the Settings object in place and tells main.ts what
// changed; main.ts decides what that means for the simulation. The Settings keys (and so the URL
// keys of share links) keep their technical names; only the labels people read are plain words.
// The panel also owns the "?" help overlay, whose text explains every label below.

import GUI from 'lil-gui';
import type { Settings } from './share';
import { LIMITS } from './share';
import type { FollowerChoice } from '../engine/types';
import { Help, type HelpFacts } from './help';
import { CLIP_SECONDS } from './clip';

export interface PanelOptions {
  settings: Settings;
  /** Which follower choices the shipped models allow (compare needs both followers). */
  models: FollowerChoice[];
  onModel(model: FollowerChoice): void;
  onGhosts(count: number): void;
  /** The music's tempo changed (beats a minute), or it was muted / switched on. */
  onTempo(bpm: number): void;
  onMusic(on: boolean): void;
  /** The leader's own figures were switched on or off. */
  onFigures(on: boolean): void;
  onReset(): void;
  onResetView(): void;
  onShare(): void;
  /** Shows or hides the skeleton; without it (capsule figures) the panel has no skeleton switch. */
  onSkeleton?(on: boolean): void;
  /** A setting has its new value (a slider let go, a number typed, a box ticked, a menu chosen). */
  onSettingsChange(): void;
  /** Live engine figures (the HUD's details line): shown inside the help's "more" fold. */
  details?: HTMLElement;
  /** The help opened or closed (the dance holds still while it is open). */
  onHelp?(open: boolean): void;
  /** The numbers the help states (the manifest's: help.ts HelpFacts). */
  facts: HelpFacts;
}

/** What the intention adds on this data, as measured (docs/results.md, "Intention against no
 * intention"; docs/plausibility.md); shown in the help's details fold. */
export const INTENTION_NOTE =
  'Measured on the CMU salsa takes, both networks hearing the music, the intention makes no ' +
  'difference twelve takes can show (6-fold cross-validation against CCM: the same pose error within ' +
  '0.1 cm, the same turns, the same steps on the beat); run without the page\'s upright guard, ours ' +
  'went down in 2 of the 6 folds, which costs it FID. With the guard, in 100 steered minutes neither ' +
  'partner falls or freezes. Details: docs/results.md and docs/plausibility.md.';

/** The partner menu: plain names first; the research names live in the details fold. */
export const MODEL_LABELS: Record<FollowerChoice, string> = {
  ours: 'reads your intention',
  ccm: 'baseline, no intention',
  compare: 'both, side by side',
};

/** Every control's label and its one-sentence explanation (the help overlay lists them all). */
export const CONTROLS = {
  model: ['partner', 'Which network dances with you: one that first guesses where your body is going (your intention), a baseline that does not, or both side by side with a copy of you each.'],
  temperature: ['variety', 'Low: the partner always makes its most likely move; high: it picks more varied, sometimes wilder moves.'],
  tempo: ['tempo', `The music’s beats a minute (${LIMITS.tempo[0]}-${LIMITS.tempo[1]}); both dancers hear it and dance on its count.`],
  music: ['music', 'Plays the salsa band (from your first key or tap); off, the dance keeps its count in silence.'],
  figures: ['his own turns', 'On: your dancer also leads a turn now and then by himself, hers or his own, every few bars; off: only the turns you ask for (T, Shift+T). The count shows the turn coming.'],
  ghosts: ['possible reactions', `Up to ${LIMITS.ghosts[1]} faint partners, one colour each: copies of her that branched off within the last second and dance on with moves of their own.`],
  trajectories: ['floor paths', "Each dancer's path on the floor, a second ahead."],
  intentions: ['show what the partner expects', "Purple lines: where the partner expects your head, hands and feet to go over the next second."],
  reset: ['start again (R)', 'Both dancers go back to the opening pose, and the camera to its first view.'],
  view: ['reset view', 'Puts the camera back where it started, both dancers in view.'],
  share: ['copy link to this view', 'Copies a link that opens the page with these settings and this camera.'],
  skeleton: ['skeleton', 'Shows the thin bones inside each body.'],
  record: ['● record', 'Records both dancers; press again to stop.'],
  download: ['download BVH', 'Saves the recording as one motion file per dancer (for Blender and other animation tools).'],
  open: ['leader from BVH file…', 'Your dancer plays a motion file instead of following your keys (you can also drop the file on the page).'],
  leaderModel: ['leader back to model', 'Gives your dancer back to your keys or thumb.'],
  avatar: ['partner avatar (.vrm)…', 'Dresses your partner in a VRM avatar file (on a computer you can also drop one on either dancer).'],
  plainBodies: ['plain bodies again', 'Takes off the avatars the dancers wear.'],
  pause: ['pause', 'The button by the title (or Space) stops the dance; press it again to go on.'],
} as const satisfies Record<string, readonly [string, string]>;

const [label, help] = [(k: keyof typeof CONTROLS) => CONTROLS[k][0], (k: keyof typeof CONTROLS) => CONTROLS[k][1]];

/** What the help shows at once: one short sentence per control and per mark on the picture, few
 * enough words that the whole list and the method fit a phone's screen (help.ts). The full
 * sentences above are in the help's "more" fold. */
export const BRIEF: readonly (readonly [string, string])[] = [
  ['arrows · WASD · finger', 'Lead the blue dancer.'],
  ['drag · wheel · 2 fingers', 'Move the camera; a double tap brings both dancers back.'],
  ['pause (Space)', 'Holds the dance, or lets it go on.'],
  ['R- · L-hand turn (T, Shift+T)', 'He raises that hand and turns, leading her turn that way; she mostly follows the way.'],
  ['his own turns', 'He leads some himself too; off: only yours.'],
  ['● clip · corners', `Save a ${CLIP_SECONDS} s video · full screen.`],
  ['partner', 'Reads your intention, a baseline that does not, or both side by side.'],
  ['variety', 'Low: her likeliest move; high: wilder ones.'],
  ['tempo · music', 'The band’s beats a minute · sound on or off; both dance on its count.'],
  ['possible reactions', 'Faint partners, a colour each: other moves she could make now.'],
  ['floor paths', 'Each dancer’s path, a second ahead.'],
  ['show what the partner expects', 'Purple: where she expects your head, hands and feet.'],
  ['skeleton', 'The bones inside each body.'],
  ['start again (R) · reset view', 'Dancers and camera to the start · only the camera.'],
  ['copy link to this view', 'A link that opens the page as you see it.'],
  ['record · play a file', 'Save the dance as BVH, play a file as your dancer, wear a VRM avatar.'],
  ['orange glow', 'Where hands hold or bodies touch.'],
];

export class Panel {
  readonly gui: GUI;
  readonly help: Help;

  constructor(options: PanelOptions) {
    const { settings } = options;
    // "settings", not "duet": the page title already says duet, and on a phone both sit on screen.
    this.gui = new GUI({ title: 'settings' });
    this.gui.domElement.classList.add('duet-panel');
    // Phones: start folded so the dancers are visible (the panel is a bottom sheet there).
    if (window.matchMedia('(max-width: 600px), (max-height: 500px)').matches) this.gui.close();
    this.gui.onOpenClose((gui) => {
      if (gui === this.gui) document.body.classList.toggle('panel-open', !gui._closed);
    });
    document.body.classList.toggle('panel-open', !this.gui._closed);

    const choices = Object.fromEntries(options.models.map((m) => [MODEL_LABELS[m], m]));
    const model = this.gui.add(settings, 'model', choices).name(label('model')).onChange((m: FollowerChoice) => options.onModel(m));
    model.domElement.title = help('model');
    this.gui.add(settings, 'temperature', ...LIMITS.temperature, 0.05).name(label('temperature'));
    this.gui.add(settings, 'tempo', ...LIMITS.tempo, 1).name(label('tempo')).onChange((bpm: number) => options.onTempo(bpm));
    this.gui.add(settings, 'music').name(label('music')).onChange((on: boolean) => options.onMusic(on));
    this.gui.add(settings, 'figures').name(label('figures')).onChange((on: boolean) => options.onFigures(on));
    this.gui.add(settings, 'ghosts', ...LIMITS.ghosts, 1).name(label('ghosts')).onChange((k: number) => options.onGhosts(k));
    this.gui.add(settings, 'trajectories').name(label('trajectories'));
    this.gui.add(settings, 'intentions').name(label('intentions'));
    this.gui.add({ reset: options.onReset }, 'reset').name(label('reset'));
    this.gui.add({ view: options.onResetView }, 'view').name(label('view'));
    this.gui.add({ share: options.onShare }, 'share').name(label('share'));
    const onSkeleton = options.onSkeleton;
    if (onSkeleton) this.gui.add(settings, 'skeleton').name(label('skeleton')).onChange((on: boolean) => onSkeleton(on));
    // Every setting goes to the address once it has its value: not on every step of a slider's
    // drag, which would write the address dozens of times a second.
    this.gui.onFinishChange(() => options.onSettingsChange());

    this.help = new Help({
      brief: BRIEF,
      controls: Object.values(CONTROLS),
      note: INTENTION_NOTE,
      details: options.details,
      onToggle: options.onHelp,
      facts: options.facts,
    });
  }

  /** Show values changed from elsewhere (keyboard, URL). */
  refresh(): void {
    for (const controller of this.gui.controllersRecursive()) controller.updateDisplay();
  }
}
