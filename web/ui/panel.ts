// The settings panel (lil-gui). It edits the Settings object in place and tells main.ts what
// changed; main.ts decides what that means for the simulation.

import GUI from 'lil-gui';
import type { Settings } from './share';
import { LIMITS } from './share';
import type { FollowerChoice } from '../engine/types';

export interface PanelOptions {
  settings: Settings;
  /** Which follower choices the shipped models allow (compare needs both followers). */
  models: FollowerChoice[];
  onModel(model: FollowerChoice): void;
  onGhosts(count: number): void;
  onReset(): void;
  onShare(): void;
}

/** What the intention adds on this data, as measured (docs/results.md, "The paper's claim,
 * cross-validated by take" and "Proximity augmentation"); shown on the follower menu. */
export const INTENTION_NOTE =
  'Measured on the CMU salsa takes: the intention does not make the follower more accurate here ' +
  '(6-fold cross-validation: same pose error as CCM within 0.1 cm; CCM has the better FID). ' +
  'In steered duets (8 × 60 s) ours meets ' +
  "the leader's hands more often than CCM (28.7 % against 22.0 % of frames) and its leader turns faster " +
  '(0.51 against 0.59 s). Details: docs/results.md.';

export class Panel {
  readonly gui: GUI;

  constructor(options: PanelOptions) {
    const { settings } = options;
    this.gui = new GUI({ title: 'duet' });
    // Phones: start folded so the dancers are visible.
    if (window.matchMedia('(max-width: 600px)').matches) this.gui.close();

    const labels: Record<FollowerChoice, string> = { ours: 'ours (intention)', ccm: 'CCM (no intention)', compare: 'compare both' };
    const choices = Object.fromEntries(options.models.map((m) => [labels[m], m]));
    const model = this.gui.add(settings, 'model', choices).name('follower').onChange((m: FollowerChoice) => options.onModel(m));
    model.domElement.title = INTENTION_NOTE;
    this.gui.add(settings, 'temperature', ...LIMITS.temperature, 0.05).name('temperature');
    this.gui.add(settings, 'speed', ...LIMITS.speed, 0.25).name('speed');
    this.gui.add(settings, 'ghosts', ...LIMITS.ghosts, 1).name('ghost samples').onChange((k: number) => options.onGhosts(k));
    this.gui.add(settings, 'trajectories').name('trajectories');
    this.gui.add(settings, 'intentions').name('intentions');
    this.gui.add({ reset: options.onReset }, 'reset').name('reset (R)');
    this.gui.add({ share: options.onShare }, 'share').name('copy share link');
  }

  /** Show values changed from elsewhere (keyboard, URL). */
  refresh(): void {
    for (const controller of this.gui.controllersRecursive()) controller.updateDisplay();
  }
}
