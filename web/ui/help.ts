// The "?" button next to the title and the help overlay it opens. What shows at once must fit one
// screen without scrolling, on a phone (390x844) as on a desktop (1280x800): the method in three
// sentences, then each control and each mark on the picture in one short sentence. The rest (the
// longer explanation of every control, the keys, the research names and the engine's live
// figures) waits behind "more", a fold a visitor never needs and a researcher finds in one click.
// The dance holds still while the help is open (main.ts): it is read, not watched.
// Text only (textContent), built once. Every number it states about the page comes from where the
// page takes it (the manifest, the controls' limits, the clip's length: HelpFacts), and
// tests/web/help.test.ts checks each against those. Where the card needs scrolling (a phone held
// sideways), a "more below" line at its bottom edge says so until the end is in view.

import type { Manifest } from '../engine/types';
import { CLIP_SECONDS } from './clip';

export interface HelpOptions {
  /** [label, one short sentence] per control or mark on the picture: shown at once. */
  brief: readonly (readonly [string, string])[];
  /** [label, explanation] per control, in panel order: inside "more". */
  controls: readonly (readonly [string, string])[];
  /** The measured comparison of the two partners (research terms allowed: it sits in the fold). */
  note: string;
  /** Live engine figures, moved into the fold. */
  details?: HTMLElement;
  /** The help opened (true) or closed (false). */
  onToggle?(open: boolean): void;
  /** The numbers the help states, as the page has them. */
  facts: HelpFacts;
}

/** What the help says in numbers, from where the page takes them (main.ts: the manifest). */
export interface HelpFacts {
  /** Steps a second (manifest.fps). */
  fps: number;
  /** The partner's variety (sampling temperature) a page starts with (manifest.defaultTemperature). */
  variety: number;
  /** The leader model's own variety (manifest.leaderTemperature); null: he takes the partner's. */
  leaderVariety: number | null;
  /** His variety while he leads a figure the visitor asked for (manifest.leadingTemperature); null: his own throughout. */
  leadingVariety: number | null;
  /** The upright guard's fresh samples (manifest.guard.samples); null: no guard. */
  uprightSamples: number | null;
}

/** The facts of a manifest, for a page whose partner starts at `variety` (the address may say
 *  another: the manifest's defaultTemperature, within the control's limits). */
export function helpFacts(manifest: Manifest, variety: number): HelpFacts {
  const guard = manifest.guard;
  return {
    fps: manifest.fps,
    variety,
    leaderVariety: manifest.leaderTemperature ?? null,
    leadingVariety: manifest.leadingTemperature ?? null,
    // The upright guard acts where simulation.ts starts it: samples to choose from, and the range.
    uprightSamples: guard && guard.samples >= 2 && manifest.plausibility ? guard.samples : null,
  };
}

/** The method in three sentences (shown at once). */
export function methodText(facts: HelpFacts): string[] {
  return [
    `You lead the blue dancer; the red partner is a small neural network that picks her next pose ${facts.fps} times a second from the last second of both dancers.`,
    'Before each move she guesses where your head, hands and feet are going (your intention) and reacts to that guess, as a follower reads her leader.',
    'She learned from recorded salsa couples, and everything runs in this page.',
  ];
}

/** Every key and gesture (in the "more" fold). */
export function keysText(): string {
  return (
    'Keys: arrows or WASD lead · T: your dancer raises his right hand over her and turns to lead her turn to her right, Shift+T his left, to her left (most of her turns go that way) · ' +
    'Space pause · R start again (the camera too) · ' +
    `“● clip” saves a ${CLIP_SECONDS} s video, the corners button goes full screen · drag to turn the camera, wheel to zoom, ` +
    'double-click to frame both dancers again. Phone: drag one finger to lead, two fingers to turn and zoom, double-tap to frame ' +
    'them again; “pause” and the two “turn” buttons by the title. After a click in a number box the arrows change its number ' +
    'until Enter, or a moment without typing, gives them back to the dance.'
  );
}

/** The research names behind the plain ones (in the "more" fold). */
export function researchText(facts: HelpFacts): string {
  const own = facts.leaderVariety === null ? 'the leader model dances with the same' : `the leader model keeps ${facts.leaderVariety}`;
  const leader = facts.leadingVariety === null ? own : `${own}, and ${facts.leadingVariety} while he leads a turn you asked for`;
  const upright = facts.uprightSamples === null ? '' :
    '; an "upright choice" is a step in which the partner\'s sampled pose would have left the recorded dancers\' range (hips low, ' +
    `torso tipping) and the page took the most upright of ${facts.uprightSamples} fresh samples instead`;
  return (
    'Research names: "reads your intention" is this project\'s follower (ours), which predicts the leader\'s ' +
    'future key joints and conditions its pose on them; "baseline, no intention" is CCM, the same network ' +
    `without that step; "variety" is the partner's sampling temperature (it starts at ${facts.variety}; ${leader}); ` +
    '"possible reactions" are ghost rollouts (copies of the follower branched off at staggered steps ' +
    `within the last second, each run on by her model with fresh noise)${upright}.`
  );
}

function element<K extends keyof HTMLElementTagNameMap>(tag: K, className = '', text = ''): HTMLElementTagNameMap[K] {
  const e = document.createElement(tag);
  if (className) e.className = className;
  if (text) e.textContent = text;
  return e;
}

/** A definition list, one <div> per [term, sentence] (the terms can then run in with their text). */
function list(className: string, entries: HelpOptions['brief']): HTMLDListElement {
  const dl = element('dl', className);
  for (const [name, text] of entries) {
    const row = element('div');
    row.append(element('dt', '', name), element('dd', '', text));
    dl.append(row);
  }
  return dl;
}

export class Help {
  readonly button: HTMLButtonElement;
  readonly overlay: HTMLElement;
  readonly card: HTMLElement;
  readonly details: HTMLDetailsElement;
  /** The "more below" cue at the card's bottom edge. */
  readonly moreBelow: HTMLElement;

  constructor(private readonly options: HelpOptions) {
    this.button = element('button', 'help-button', '?');
    this.button.type = 'button';
    this.button.title = 'how it works';
    this.button.setAttribute('aria-label', 'how it works');
    this.button.addEventListener('click', () => this.toggle());
    // Next to the title (the overlay lets drags through; the button takes its own clicks).
    const title = document.querySelector('#overlay .title-row');
    if (title) title.append(this.button);
    else document.body.append(this.button);

    this.overlay = element('div', 'help-overlay');
    this.overlay.hidden = true;
    this.overlay.setAttribute('role', 'dialog');
    this.overlay.setAttribute('aria-modal', 'true');
    this.overlay.setAttribute('aria-labelledby', 'help-heading');
    const card = (this.card = element('div', 'help-card'));
    const close = element('button', 'help-close', '×');
    close.type = 'button';
    close.setAttribute('aria-label', 'close');
    close.addEventListener('click', () => this.toggle(false));
    const heading = element('h2', '', 'How duet works');
    heading.id = 'help-heading';
    card.append(close, heading);
    for (const sentence of methodText(options.facts)) card.append(element('p', 'help-method', sentence));
    card.append(list('help-brief', options.brief));

    // Class about-details: tests treat what is inside as the fold where research terms may stand.
    this.details = element('details', 'about-details');
    this.details.append(
      element('summary', '', 'more: every control in full, the keys, research names, live figures'),
      list('help-controls', options.controls),
      element('p', 'help-keys-line', keysText()),
      element('p', '', researchText(options.facts)),
      element('p', '', options.note),
    );
    if (options.details) this.details.append(options.details);
    // "more below": held at the card's bottom edge while there is more to scroll to. No height of
    // its own (its words hang above it), so it never makes the card scroll.
    this.moreBelow = element('div', 'help-more-below');
    this.moreBelow.append(element('span', '', 'more below ↓'));
    this.moreBelow.setAttribute('aria-hidden', 'true');
    card.append(this.details, this.moreBelow);
    const cue = () => this.showMoreBelow();
    card.addEventListener('scroll', cue, { passive: true });
    this.details.addEventListener('toggle', cue);
    new ResizeObserver(cue).observe(card);
    this.overlay.append(card);
    // A click on the dimmed backdrop (not the card) closes, as does Escape.
    this.overlay.addEventListener('click', (event) => {
      if (event.target === this.overlay) this.toggle(false);
    });
    window.addEventListener('keydown', (event) => {
      if (event.key === 'Escape' && !this.overlay.hidden) this.toggle(false);
    });
    document.body.append(this.overlay);
  }

  get open(): boolean {
    return !this.overlay.hidden;
  }

  toggle(show = !this.open): void {
    if (show === this.open) return;
    this.overlay.hidden = !show;
    this.button.setAttribute('aria-expanded', String(show));
    if (show) {
      this.details.open = false; // each opening starts short: the part that fits the screen
      this.card.scrollTop = 0;
      this.showMoreBelow();
    }
    this.options.onToggle?.(show);
  }

  /** Whether the card has more below what it shows (a phone held sideways): the cue says so. */
  private showMoreBelow(): void {
    const card = this.card;
    this.moreBelow.classList.toggle('shown', card.scrollTop + card.clientHeight < card.scrollHeight - 2);
  }
}
