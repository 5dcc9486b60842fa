// The audio clock a listener hears: shared by the band (groove.ts, loaded with the music) and the
// page's music control (web/ui/music.ts, in the page from the start).

/** The audio clock's time a listener hears now (what leaves the speakers), seconds. */
export function heardTime(ctx: AudioContext): number {
  const stamp = ctx.getOutputTimestamp?.();
  if (stamp && stamp.contextTime !== undefined && stamp.performanceTime !== undefined && stamp.contextTime > 0) {
    return stamp.contextTime + (performance.now() - stamp.performanceTime) / 1000;
  }
  return ctx.currentTime - (ctx.outputLatency || ctx.baseLatency || 0);
}
