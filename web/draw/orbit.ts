// Where the camera may stand around the pair: the orbit web/draw/scene.ts keeps to, and the one a
// link carries (web/ui/share.ts).

export interface CameraOrbit {
  /** Degrees around the vertical axis; 0 looks along +z (from behind the leader at start). */
  azimuth: number;
  /** Degrees down from straight above. */
  polar: number;
  /** Metres from the pair's midpoint. */
  distance: number;
}

/** Degrees down from straight above; metres from the pair, at most 12, short of the fog (from 14 m). */
export const ORBIT_LIMITS = {
  polar: [5, 88],
  distance: [1.5, 12],
} as const;
