// The start's watchdog (web/engine/watchdog.ts): a start that stops moving for STALL_MS restarts,
// at most MAX_RESTARTS times in a row; progress, or a hidden tab, is no stall.

import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { BootWatchdog, MAX_RESTARTS, STALL_MS, clearRestarts, restartsSoFar, takeRestart } from '../../web/engine/watchdog';

/** sessionStorage and document, as much of them as the watchdog uses. */
function fakeBrowser() {
  const items = new Map<string, string>();
  const listeners = new Set<() => void>();
  const doc = {
    hidden: false,
    addEventListener: (_: string, f: () => void) => listeners.add(f),
    removeEventListener: (_: string, f: () => void) => listeners.delete(f),
    show(hidden: boolean) {
      this.hidden = hidden;
      for (const f of listeners) f();
    },
  };
  vi.stubGlobal('document', doc);
  vi.stubGlobal('window', {
    sessionStorage: {
      getItem: (k: string) => items.get(k) ?? null,
      setItem: (k: string, v: string) => items.set(k, v),
      removeItem: (k: string) => items.delete(k),
    },
  });
  return doc;
}

describe('BootWatchdog', () => {
  let doc: ReturnType<typeof fakeBrowser>;
  beforeEach(() => {
    vi.useFakeTimers({ toFake: ['setInterval', 'clearInterval', 'setTimeout', 'clearTimeout', 'performance'] });
    doc = fakeBrowser();
  });
  afterEach(() => {
    vi.useRealTimers();
    vi.unstubAllGlobals();
  });

  it('calls onStall once after STALL_MS without progress, and counts the restart', () => {
    const stalls: [number, boolean][] = [];
    const dog = new BootWatchdog(() => 'same', (ms, again) => stalls.push([ms, again]));
    dog.start();
    vi.advanceTimersByTime(STALL_MS - 1000);
    expect(stalls).toEqual([]);
    vi.advanceTimersByTime(2000);
    expect(stalls.length).toBe(1);
    expect(stalls[0][0]).toBeGreaterThanOrEqual(STALL_MS);
    expect(stalls[0][1]).toBe(true);
    expect(restartsSoFar()).toBe(1);
    vi.advanceTimersByTime(5 * STALL_MS);
    expect(stalls.length).toBe(1); // it stopped itself
  });

  it('progress resets the clock: a slow but moving start is never restarted', () => {
    let bytes = 0;
    const stalls: number[] = [];
    const dog = new BootWatchdog(() => String(bytes), (ms) => stalls.push(ms));
    dog.start();
    for (let s = 0; s < 10; s++) {
      vi.advanceTimersByTime(STALL_MS - 2000);
      bytes += 1;
    }
    expect(stalls).toEqual([]);
    dog.stop();
  });

  it('a hidden tab is no stall, and coming back starts the clock afresh', () => {
    const stalls: number[] = [];
    const dog = new BootWatchdog(() => 'same', (ms) => stalls.push(ms));
    dog.start();
    doc.show(true);
    vi.advanceTimersByTime(3 * STALL_MS);
    expect(stalls).toEqual([]);
    doc.show(false);
    vi.advanceTimersByTime(STALL_MS - 2000);
    expect(stalls).toEqual([]);
    vi.advanceTimersByTime(3000);
    expect(stalls.length).toBe(1);
  });

  it(`gives up after ${MAX_RESTARTS} restarts in a row; a start that danced clears the count`, () => {
    for (let i = 0; i < MAX_RESTARTS; i++) expect(takeRestart()).toBe(true);
    expect(takeRestart()).toBe(false);
    const stalls: boolean[] = [];
    new BootWatchdog(() => 'same', (_, again) => stalls.push(again)).start();
    vi.advanceTimersByTime(STALL_MS + 1000);
    expect(stalls).toEqual([false]);
    clearRestarts();
    expect(restartsSoFar()).toBe(0);
    expect(takeRestart()).toBe(true);
  });

  it('without sessionStorage there is no restart (nothing could stop a reload loop)', () => {
    vi.stubGlobal('window', {
      get sessionStorage(): Storage {
        throw new Error('denied');
      },
    });
    expect(takeRestart()).toBe(false);
    expect(restartsSoFar()).toBe(0);
  });
});
