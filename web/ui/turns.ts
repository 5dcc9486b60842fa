// "Lead a turn": the two buttons beside pause (a phone has no T key). Each asks the leader model
// to lead the partner's turn now, to her right or to her left (Simulation.askTurn); the follower
// is never told: she turns only if she reads it in the leader's motion.

export class TurnButtons {
  private readonly buttons: HTMLButtonElement[] = [];
  private shown = 0;

  /** `onTurn(direction)`: -1 her right (clockwise seen from above), +1 her left. */
  constructor(onTurn: (direction: number) => void) {
    const row = document.querySelector('#overlay .title-row') ?? document.body;
    for (const [direction, label, title] of [
      [-1, '↻ turn', 'lead her turn to her right (T)'],
      [1, '↺ turn', 'lead her turn to her left (Shift+T)'],
    ] as const) {
      const button = document.createElement('button');
      button.type = 'button';
      button.className = 'pause-button turn-button';
      button.textContent = label;
      button.title = title;
      button.setAttribute('aria-label', title);
      button.addEventListener('click', () => onTurn(direction));
      row.append(button);
      this.buttons.push(button);
    }
  }

  /** Mark the button of the turn being led (0: none). Called every frame: touches the page only on a change. */
  show(direction: number): void {
    if (direction === this.shown) return;
    this.shown = direction;
    this.buttons.forEach((b, i) => b.classList.toggle('leading', direction === (i === 0 ? -1 : 1)));
  }
}
