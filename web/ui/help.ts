// The "?" button next to the title and the help overlay it opens: what the page does in three
// sentences, one sentence per control, and an "about / details" fold for the research names and
// the engine's figures (a visitor never needs them; a researcher wants them one click away).
// Text only (textContent), built once.

export interface HelpOptions {
  /** [label, explanation] per control, in panel order. */
  controls: readonly (readonly [string, string])[];
  /** The measured comparison of the two partners (research terms allowed: it sits in the fold). */
  note: string;
  /** Live engine figures, moved into the fold. */
  details?: HTMLElement;
}

const METHOD = [
  'You lead the blue dancer with the arrow keys or your thumb; the red partner is a small neural network that, thirty times a second, looks at the last second of both dancers and chooses its next pose.',
  'Before it moves, it guesses where your head, hands and feet will be over the next second (your intention) and dances toward that guess; the baseline partner moves without such a guess.',
  'Both were trained on recorded salsa couples and run entirely in this page: nothing you do leaves your device.',
];

const RESEARCH =
  'Research names: "reads your intention" is this project\'s follower (ours), which predicts the leader\'s ' +
  'future key joints and conditions its pose on them; "baseline, no intention" is CCM, the same network ' +
  'without that step; "variety" is the partner\'s sampling temperature (the leader model keeps 0.5); ' +
  '"possible reactions" are ghost samples (the follower run again with fresh noise); an "upright choice" ' +
  'is a step in which the partner\'s sampled pose would have left the recorded dancers\' range (hips low, ' +
  'torso tipping) and the page took the most upright of 8 fresh samples instead.';

function element<K extends keyof HTMLElementTagNameMap>(tag: K, className = '', text = ''): HTMLElementTagNameMap[K] {
  const e = document.createElement(tag);
  if (className) e.className = className;
  if (text) e.textContent = text;
  return e;
}

export class Help {
  readonly button: HTMLButtonElement;
  readonly overlay: HTMLElement;
  readonly details: HTMLDetailsElement;

  constructor(options: HelpOptions) {
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
    const card = element('div', 'help-card');
    const close = element('button', 'help-close', '×');
    close.type = 'button';
    close.setAttribute('aria-label', 'close');
    close.addEventListener('click', () => this.toggle(false));
    const heading = element('h2', '', 'How duet works');
    heading.id = 'help-heading';
    card.append(close, heading);
    for (const sentence of METHOD) card.append(element('p', 'help-method', sentence));

    card.append(element('h3', '', 'Controls'));
    const list = element('dl', 'help-controls');
    for (const [name, text] of options.controls) list.append(element('dt', '', name), element('dd', '', text));
    card.append(list);
    card.append(element('p', 'help-keys-line', 'Keys: arrows or WASD lead · T lead her turn to her right, Shift+T to her left · Space pause · R start again (the camera too) · “● clip” saves a 6 s video, the corners button goes full screen · drag to turn the camera, wheel to zoom. Phone: drag one finger to lead, two fingers to turn and zoom; “pause” and the two “turn” buttons by the title.'));

    this.details = element('details', 'about-details');
    this.details.append(element('summary', '', 'about / details'), element('p', '', RESEARCH), element('p', '', options.note));
    if (options.details) this.details.append(options.details);
    card.append(this.details);
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
    this.overlay.hidden = !show;
    this.button.setAttribute('aria-expanded', String(show));
  }
}
