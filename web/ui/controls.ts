// Steering input: arrow keys / WASD and a touch joystick, both relative to where the camera looks,
// turned into one 2D vector on the floor (world x, z) of length 0..1. Space pauses, R resets; a
// double-click or a double tap on the floor frames both dancers again.
// The keys steer wherever the focus is (a button, a checkbox, the partner menu): only a text field
// keeps its keys.

import type { Steer } from '../engine/types';

/** Joystick travel in CSS pixels for full speed, and the dead zone around the thumb. */
const JOYSTICK_RADIUS = 60;
const DEAD_ZONE = 6;
/** A tap: a finger down and up within this long, moved less than this far. Two taps within
 *  DOUBLE_TAP_MS of each other and DOUBLE_TAP_PX apart are a double tap. */
const TAP_MS = 300;
const TAP_PX = 12;
const DOUBLE_TAP_MS = 400;
const DOUBLE_TAP_PX = 40;

const KEY_DIRECTIONS: Record<string, [number, number]> = {
  // [forward, right]
  ArrowUp: [1, 0],
  KeyW: [1, 0],
  ArrowDown: [-1, 0],
  KeyS: [-1, 0],
  ArrowLeft: [0, -1],
  KeyA: [0, -1],
  ArrowRight: [0, 1],
  KeyD: [0, 1],
};

export interface ControlsOptions {
  /** Where pointers are read (the WebGL canvas). */
  surface: HTMLElement;
  /** Writes the camera's floor-projected, normalized view direction into `out`. */
  viewForward(out: { x: number; z: number }): void;
  onPause(): void;
  onReset(): void;
  /** T: the leader raises his right hand to lead her turn (-1); Shift+T his left (+1). */
  onTurn(direction: number): void;
  /** A double-click or a double tap on the surface: frame both dancers again. */
  onFrame?(): void;
}

export class Controls {
  private readonly pressed = new Set<string>();
  private readonly steer: Steer = { x: 0, z: 0, active: false };
  private readonly forward = { x: 0, z: 1 };
  private readonly joystick = { pointerId: -1, originX: 0, originY: 0, forward: 0, right: 0 };
  private readonly base: HTMLElement;
  private readonly knob: HTMLElement;
  private readonly touches = new Set<number>();
  /** The finger down now (for taps), and the last tap's end: time (ms) and place. */
  private readonly press = { id: -1, t: 0, x: 0, y: 0 };
  private readonly lastTap = { t: -Infinity, x: 0, y: 0 };

  constructor(private readonly options: ControlsOptions) {
    // Keys are read by physical position (event.code), so WASD works on AZERTY keyboards too.
    // Read at the window in the capture phase, before any element sees them: lil-gui stops key
    // events inside the panel from reaching the window, so after a click on a panel control the
    // arrows did not steer (nor R reset, nor Space pause), and a key released there stayed held.
    window.addEventListener('keydown', (event) => this.onKeyDown(event), { capture: true });
    window.addEventListener('keyup', (event) => this.pressed.delete(event.code), { capture: true });
    // A key released while the window had no focus would otherwise steer forever.
    window.addEventListener('blur', () => this.pressed.clear());

    this.base = document.createElement('div');
    this.base.className = 'joystick';
    this.knob = document.createElement('div');
    this.knob.className = 'joystick-knob';
    this.base.appendChild(this.knob);
    document.body.appendChild(this.base);

    const surface = options.surface;
    // touch-action: none (style.css) stops the browser from scrolling or zooming while steering.
    surface.addEventListener('pointerdown', (event) => this.onPointerDown(event));
    window.addEventListener('pointermove', (event) => this.onPointerMove(event));
    window.addEventListener('pointerup', (event) => this.onPointerUp(event));
    window.addEventListener('pointercancel', (event) => this.onPointerUp(event));
    // iOS Safari pinch-zooms the page through its own gesture events.
    document.addEventListener('gesturestart', (event) => event.preventDefault());
    surface.addEventListener('dblclick', () => options.onFrame?.());
  }

  /** The current steering vector in world x/z (the same object every call). */
  getSteer(): Steer {
    let forward = 0;
    let right = 0;
    for (const code of this.pressed) {
      const direction = KEY_DIRECTIONS[code];
      if (!direction) continue;
      forward += direction[0];
      right += direction[1];
    }
    if (this.joystick.pointerId !== -1) {
      forward += this.joystick.forward;
      right += this.joystick.right;
    }
    // Diagonals (two keys) are as fast as straight lines.
    const length = Math.hypot(forward, right);
    if (length > 1) {
      forward /= length;
      right /= length;
    }
    // Forward is the camera's view on the floor; right is forward turned 90° clockwise seen from above.
    const f = this.forward;
    this.options.viewForward(f);
    this.steer.x = forward * f.x - right * f.z;
    this.steer.z = forward * f.z + right * f.x;
    this.steer.active = length > 0;
    return this.steer;
  }

  private onKeyDown(event: KeyboardEvent): void {
    // Typing a number into the settings panel must not steer or reset.
    if (typesText(event.target)) return;
    if (event.ctrlKey || event.metaKey || event.altKey) return; // Ctrl+R still reloads; Alt+Down opens a menu
    if (event.code in KEY_DIRECTIONS) {
      this.pressed.add(event.code);
      // Arrows would scroll the page, or change the partner in a focused (closed) menu. An open
      // menu's list is a popup of its own: its keys never come here.
      event.preventDefault();
    } else if (event.code === 'Space') {
      event.preventDefault(); // a focused button or checkbox would be pressed too
      if (!event.repeat) this.options.onPause();
    } else if (event.code === 'KeyR' && !event.repeat) {
      this.options.onReset();
    } else if (event.code === 'KeyT' && !event.repeat) {
      this.options.onTurn(event.shiftKey ? 1 : -1);
    }
  }

  // Touch joystick: the first finger on the canvas steers from wherever it lands; a second finger
  // hands the gesture to the camera (OrbitControls: two fingers orbit and zoom).

  private onPointerDown(event: PointerEvent): void {
    if (event.pointerType === 'mouse') return; // the mouse orbits; the keyboard steers
    this.touches.add(event.pointerId);
    if (this.touches.size > 1) {
      this.release();
      this.press.id = -1; // two fingers: not a tap
      return;
    }
    Object.assign(this.press, { id: event.pointerId, t: event.timeStamp, x: event.clientX, y: event.clientY });
    const j = this.joystick;
    j.pointerId = event.pointerId;
    j.originX = event.clientX;
    j.originY = event.clientY;
    j.forward = 0;
    j.right = 0;
    this.base.style.left = `${event.clientX}px`;
    this.base.style.top = `${event.clientY}px`;
    this.knob.style.transform = 'translate(-50%, -50%)';
    this.base.classList.add('visible');
    event.preventDefault();
  }

  private onPointerMove(event: PointerEvent): void {
    const j = this.joystick;
    if (event.pointerId !== j.pointerId) return;
    let dx = event.clientX - j.originX;
    let dy = event.clientY - j.originY;
    const distance = Math.hypot(dx, dy);
    if (distance > JOYSTICK_RADIUS) {
      dx *= JOYSTICK_RADIUS / distance;
      dy *= JOYSTICK_RADIUS / distance;
    }
    this.knob.style.transform = `translate(calc(-50% + ${dx}px), calc(-50% + ${dy}px))`;
    const strength = distance < DEAD_ZONE ? 0 : Math.min(1, (distance - DEAD_ZONE) / (JOYSTICK_RADIUS - DEAD_ZONE));
    const scale = distance > 0 ? strength / Math.min(distance, JOYSTICK_RADIUS) : 0;
    // Screen up is "away from the camera".
    j.forward = -dy * scale;
    j.right = dx * scale;
  }

  private onPointerUp(event: PointerEvent): void {
    this.touches.delete(event.pointerId);
    if (event.pointerId === this.joystick.pointerId) this.release();
    if (event.pointerId === this.press.id && event.type === 'pointerup') this.tapped(event);
  }

  /** A finger lifted: a second tap close to the first, soon after it, frames the pair again. */
  private tapped(event: PointerEvent): void {
    const { press, lastTap } = this;
    press.id = -1;
    const still = Math.hypot(event.clientX - press.x, event.clientY - press.y) < TAP_PX;
    if (!still || event.timeStamp - press.t > TAP_MS) return;
    if (event.timeStamp - lastTap.t < DOUBLE_TAP_MS && Math.hypot(event.clientX - lastTap.x, event.clientY - lastTap.y) < DOUBLE_TAP_PX) {
      lastTap.t = -Infinity;
      this.options.onFrame?.();
      return;
    }
    Object.assign(lastTap, { t: event.timeStamp, x: event.clientX, y: event.clientY });
  }

  private release(): void {
    this.joystick.pointerId = -1;
    this.joystick.forward = 0;
    this.joystick.right = 0;
    this.base.classList.remove('visible');
  }
}

/** Whether keys typed at `target` are text: a text field keeps its keys (arrows, Space, R). */
function typesText(target: EventTarget | null): boolean {
  if (target instanceof HTMLTextAreaElement) return true;
  if (target instanceof HTMLInputElement) return !NOT_TEXT.has(target.type);
  return target instanceof HTMLElement && target.isContentEditable;
}

const NOT_TEXT = new Set(['button', 'checkbox', 'color', 'file', 'image', 'radio', 'range', 'reset', 'submit']);

/**
 * After a click or tap on a button or checkbox inside `root` (the panel, the buttons by the title),
 * or a choice in one of its menus, give the focus back to the page: a control that keeps the focus
 * after a click takes Enter (and, but for Controls, Space) as another press of itself. A click
 * made with the keyboard (Enter on a control reached with Tab) leaves the focus where it is, so
 * that Tab goes on from there.
 */
export function releaseFocusAfterUse(root: HTMLElement): void {
  let pointer = false;
  let pointerType = '';
  root.addEventListener('pointerdown', (event) => {
    pointer = true;
    pointerType = event.pointerType;
  }, { capture: true });
  window.addEventListener('keydown', () => (pointer = false), { capture: true });
  guideNumberBoxes(root, () => (pointer ? pointerType : 'keyboard'));
  root.addEventListener('click', () => {
    const active = document.activeElement;
    // A click on a menu opens it: the menu keeps the focus until a choice is made ('change').
    if (!pointer || !(active instanceof HTMLElement) || active === document.body || !root.contains(active)) return;
    if (!typesText(active) && !(active instanceof HTMLSelectElement)) active.blur();
  });
  root.addEventListener('change', (event) => {
    if (event.target instanceof HTMLSelectElement) event.target.blur();
  });
}

/** How long a number box clicked with the mouse keeps the keys with nothing typed into it, ms. */
export const NUMBER_BOX_IDLE_MS = 2500;

/**
 * A number box (the text field beside a slider) keeps the arrow keys while it has the focus: they
 * change its number, and a visitor who clicked it and then pressed ↑ to lead saw the dancer stand
 * still and the number creep up. So while one has the focus, a line over it says what the arrows
 * do now and how to give them back; Enter gives them back (lil-gui blurs), and so does a moment
 * with nothing typed after a mouse click (NUMBER_BOX_IDLE_MS: typing a number takes keys, which
 * restart the wait). A box reached with Tab keeps the keys until Tab or Enter moves on. A box
 * tapped on a touch screen gets neither (its keyboard has no arrows, and typing takes a while).
 * `focusedBy()`: how the focus came, 'mouse', 'touch', 'pen' or 'keyboard'.
 */
function guideNumberBoxes(root: HTMLElement, focusedBy: () => string): void {
  const hint = document.createElement('div');
  hint.className = 'keys-hint';
  hint.setAttribute('role', 'status');
  hint.hidden = true;
  hint.textContent = '↑ ↓ change this number · Enter gives the arrows back to the dance';
  document.body.append(hint);
  let box: HTMLInputElement | null = null;
  /** The box had the focus from a mouse click (not Tab). */
  let byMouse = false;
  let timer = 0;
  const wait = () => {
    clearTimeout(timer);
    const held = box;
    if (held && byMouse) timer = window.setTimeout(() => document.activeElement === held && held.blur(), NUMBER_BOX_IDLE_MS);
  };
  root.addEventListener('focusin', (event) => {
    const target = event.target;
    if (!(target instanceof HTMLInputElement) || !typesText(target) || !target.closest('.lil-number')) return;
    box = target;
    const by = focusedBy();
    byMouse = by === 'mouse';
    if (by === 'touch') return;
    hint.hidden = false;
    // Over the box, inside the window (a panel at the right edge).
    const r = target.getBoundingClientRect();
    const width = hint.offsetWidth;
    hint.style.left = `${Math.max(4, Math.min(window.innerWidth - width - 4, r.left + r.width / 2 - width / 2))}px`;
    hint.style.top = `${Math.max(4, r.top - hint.offsetHeight - 6)}px`;
    wait();
  });
  root.addEventListener('focusout', (event) => {
    if (event.target !== box) return;
    box = null;
    hint.hidden = true;
    clearTimeout(timer);
  });
  // In the capture phase: lil-gui keeps its keys from bubbling out of the panel.
  root.addEventListener('keydown', (event) => {
    if (box && event.target === box) wait();
  }, { capture: true });
}
