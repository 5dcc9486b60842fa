// The count for people learning: "1 2 3 · 5 6 7 ·" under the title, the count the dance is on
// lit. Salsa steps on 1-2-3 and 5-6-7 and holds on 4 and 8 (shown as dots). It shows the count
// of the step on screen, the music's while it plays. After it, the figure the leader leads:
// "her turn ←" (to her left) or "her turn →" (to her right), "his turn ↺" (his own turn to his
// left, counterclockwise seen from above) or "his turn ↻" (to his right), faint from when it is
// planned and lit while it is danced, so a visitor sees a turn coming on the count; on a phone only
// the mark, which tells the two apart (a straight arrow: hers; a circling one: his).

import type { FigureView } from '../engine/types';
import type { FigureName } from '../mirror/features';

const MARKS = ['1', '2', '3', '·', '5', '6', '7', '·'];

/** Which of the 8 counts (0-7) a count in beats is on: beat 0 is the 1. */
export function countOf(beat: number): number {
  return ((Math.floor(beat + 1e-6) % 8) + 8) % 8;
}

/** The mark of a figure: her turn to her left (+1) ←, to her right (-1) →; his turn to his left ↺
 *  (counterclockwise seen from above), to his right ↻. */
export function figureMark(name: FigureName, way: number): string {
  if (name === 'his_turn') return way > 0 ? '↺' : '↻';
  return way > 0 ? '←' : '→';
}

/** The words before the mark (hidden on a phone). */
export function figureWords(name: FigureName): string {
  return name === 'his_turn' ? 'his turn ' : 'her turn ';
}

export class CountDisplay {
  readonly element: HTMLElement;
  private readonly marks: HTMLElement[];
  private readonly figure: HTMLElement;
  private readonly word: Text;
  private readonly mark: Text;
  private lit = -1;
  /** The figure shown (by identity: the simulation's view is the same object while unchanged). */
  private shown: FigureView | null = null;

  constructor(parent: HTMLElement) {
    this.element = document.createElement('div');
    this.element.className = 'duet-count';
    this.element.setAttribute('aria-hidden', 'true'); // a picture of the beat; the music says it
    this.marks = MARKS.map((text) => {
      const span = document.createElement('span');
      span.textContent = text;
      this.element.append(span);
      return span;
    });
    // Its place is kept while no figure is planned (hidden, not removed): the line never moves.
    this.figure = document.createElement('span');
    this.figure.className = 'count-figure';
    const word = document.createElement('span');
    word.className = 'count-figure-word';
    this.word = document.createTextNode(figureWords('her_turn'));
    word.append(this.word);
    this.mark = document.createTextNode(figureMark('her_turn', 1));
    this.figure.append(word, this.mark);
    this.element.append(this.figure);
    parent.append(this.element);
  }

  show(beat: number, figure: FigureView | null = null): void {
    const n = countOf(beat);
    if (n !== this.lit) {
      this.marks[this.lit]?.classList.remove('on');
      this.marks[n].classList.add('on');
      this.lit = n;
    }
    if (figure === this.shown) return;
    this.shown = figure;
    this.figure.classList.toggle('planned', figure !== null);
    this.figure.classList.toggle('on', figure !== null && !figure.coming);
    if (figure) {
      this.word.data = figureWords(figure.name);
      this.mark.data = figureMark(figure.name, figure.way);
    }
  }
}
