// The count for people learning: "1 2 3 · 5 6 7 ·" under the title, the count the dance is on
// lit. Salsa steps on 1-2-3 and 5-6-7 and holds on 4 and 8 (shown as dots). It shows the count
// of the step on screen, the music's while it plays.

const MARKS = ['1', '2', '3', '·', '5', '6', '7', '·'];

/** Which of the 8 counts (0-7) a count in beats is on: beat 0 is the 1. */
export function countOf(beat: number): number {
  return ((Math.floor(beat + 1e-6) % 8) + 8) % 8;
}

export class CountDisplay {
  readonly element: HTMLElement;
  private readonly marks: HTMLElement[];
  private lit = -1;

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
    parent.append(this.element);
  }

  show(beat: number): void {
    const n = countOf(beat);
    if (n === this.lit) return;
    this.marks[this.lit]?.classList.remove('on');
    this.marks[n].classList.add('on');
    this.lit = n;
  }
}
