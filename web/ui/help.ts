// The "?" button next to the title and the help overlay it opens. What shows at once must fit one
// screen without scrolling, on a phone (390x844) as on a desktop (1280x800): the method in three
// sentences, then each control and each mark on the picture in one short sentence. The rest (the
// longer explanation of every control, the keys, the research names and the engine's live
// figures) waits behind "more", a fold a visitor never needs and a researcher finds in one click.
// The dance holds still while the help is open (main.ts): it is read, not watched.
// Text only (textContent), built once.

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
}

const METHOD = [
  'You lead the blue dancer; the red partner is a small neural network that picks her next pose thirty times a second from the last second of both dancers.',
  'Before each move she guesses where your head, hands and feet are going (your intention) and reacts to that guess, as a follower reads her leader.',
  'She learned from recorded salsa couples, and everything runs in this page.',
];

const KEYS =
  'Keys: arrows or WASD lead · T raise your right hand over her to lead a turn, Shift+T your left · Space pause · R start again (the camera too) · ' +
  '“● clip” saves a 6 s video, the corners button goes full screen · drag to turn the camera, wheel to zoom. Phone: drag one finger ' +
  'to lead, two fingers to turn and zoom; “pause” and the two “turn” buttons by the title.';

const RESEARCH =
  'Research names: "reads your intention" is this project\'s follower (ours), which predicts the leader\'s ' +
  'future key joints and conditions its pose on them; "baseline, no intention" is CCM, the same network ' +
  'without that step; "variety" is the partner\'s sampling temperature (the leader model keeps 0.5); ' +
  '"possible reactions" are ghost rollouts (copies of the follower branched off at staggered steps ' +
  'within the last second, each run on by her model with fresh noise); an "upright choice" ' +
  'is a step in which the partner\'s sampled pose would have left the recorded dancers\' range (hips low, ' +
  'torso tipping) and the page took the most upright of 32 fresh samples instead.';

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
    for (const sentence of METHOD) card.append(element('p', 'help-method', sentence));
    card.append(list('help-brief', options.brief));

    // Class about-details: tests treat what is inside as the fold where research terms may stand.
    this.details = element('details', 'about-details');
    this.details.append(
      element('summary', '', 'more: every control in full, the keys, research names, live figures'),
      list('help-controls', options.controls),
      element('p', 'help-keys-line', KEYS),
      element('p', '', RESEARCH),
      element('p', '', options.note),
    );
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
    if (show === this.open) return;
    this.overlay.hidden = !show;
    this.button.setAttribute('aria-expanded', String(show));
    if (show) {
      this.details.open = false; // each opening starts short: the part that fits the screen
      this.card.scrollTop = 0;
    }
    this.options.onToggle?.(show);
  }
}
