// "Lead a turn": the two buttons beside pause (a phone has no T key). Each asks the leader model
// to lead her turn on the next beat, or after the figure running (Simulation.askTurn): he raises
// his right hand over her (T) or his left (Shift+T), and turns with her that way (rollout
// leadPlan). She is told only what her hand would feel (the figure being led, which both dancers
// read): her body and timing are her network's, and most of her turns after a request go the asked
// way (78 %: docs/results.md, "Which way she turns"), so the buttons name the hand and her way.
// A button stays marked while the turn it asked for is planned or danced. On a phone the word
// "hand" folds away (one row of buttons: style.css).

/** [direction for Simulation.askTurn, hand letter, hand, key]. */
const TURNS = [
  [-1, 'R', 'right', 'T'],
  [1, 'L', 'left', 'Shift+T'],
] as const;

/** What a turn button says it does, in its tooltip and to a screen reader. */
export function turnTitle(hand: 'right' | 'left', key: string): string {
  return `lead a turn to her ${hand}: he raises his ${hand} hand over her and turns with her (${key}); most of her turns go that way`;
}

export class TurnButtons {
  private readonly buttons: HTMLButtonElement[] = [];
  private shown = 0;

  /** `onTurn(direction)`: -1 his right hand raised (T), +1 his left (Shift+T). */
  constructor(onTurn: (direction: number) => void) {
    const row = document.querySelector('#overlay .title-row') ?? document.body;
    for (const [direction, letter, hand, key] of TURNS) {
      const button = document.createElement('button');
      button.type = 'button';
      button.className = 'pause-button turn-button';
      // "R-hand turn": the letter, "-hand" (hidden on a phone), " turn".
      const word = document.createElement('span');
      word.className = 'turn-hand';
      word.textContent = '-hand';
      button.append(letter, word, ' turn');
      button.title = turnTitle(hand, key);
      button.setAttribute('aria-label', button.title);
      button.addEventListener('click', () => onTurn(direction));
      row.append(button);
      this.buttons.push(button);
    }
  }

  /** Mark the button of the turn being led (0: none). Called every frame: touches the page only on a change. */
  show(direction: number): void {
    if (direction === this.shown) return;
    this.shown = direction;
    this.buttons.forEach((b, i) => b.classList.toggle('leading', direction === TURNS[i][0]));
  }
}
