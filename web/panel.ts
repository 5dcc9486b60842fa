// The settings panel (lil-gui). It edits the Settings object in place and tells main.ts what
// changed; main.ts decides what that means for the simulation.

import GUI from 'lil-gui';
import type { Settings } from './share';
import { LIMITS } from './share';
import type { FollowerChoice } from './types';

export interface PanelOptions {
  settings: Settings;
  /** Which follower choices the shipped models allow (compare needs both followers). */
  models: FollowerChoice[];
  onModel(model: FollowerChoice): void;
  onGhosts(count: number): void;
  onReset(): void;
  onShare(): void;
}

export class Panel {
  readonly gui: GUI;

  constructor(options: PanelOptions) {
    const { settings } = options;
    this.gui = new GUI({ title: 'duet' });
    // Phones: start folded so the dancers are visible.
    if (window.matchMedia('(max-width: 600px)').matches) this.gui.close();

    const labels: Record<FollowerChoice, string> = { ours: 'ours (intention)', ccm: 'CCM (no intention)', compare: 'compare both' };
    const choices = Object.fromEntries(options.models.map((m) => [labels[m], m]));
    this.gui.add(settings, 'model', choices).name('follower').onChange((m: FollowerChoice) => options.onModel(m));
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
