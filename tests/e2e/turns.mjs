// Leading a turn, measured in the page: shared by tests/e2e/turns.test.mjs and
// scripts/turns_probe.mjs.
//
// window.duet (the page's test hook) publishes each dancer's root and heading, not the joints, so
// these helpers reach the simulation through its module: on the Vite dev server
// `import('/web/engine/simulation.ts')` inside the page is the very module instance the page
// imported (web/ui/main.ts loads it with `import('../engine/simulation')`), and a wrapper around
// `DuetSimulation.prototype.step` sees the page's simulation (`this`) at every step. The wrapper
// changes nothing in the dance: it reads the views after each step and, at the step asked for,
// asks the turn just before that step runs (as a key press between two animation frames would),
// through window.duet.askTurn (what T and the turn buttons call) when the page has it, else
// through the simulation's askTurn. Dev server only (the built site has no such module URL).
//
// Facing is measured from the joints as docs/features.md defines the heading (unsmoothed):
// across = (lThigh − rThigh) + (lShldr − rShldr), forward = normalize(cross(across, up)) on the
// floor, angle atan2(fx, fz); +angle is counterclockwise seen from above, as askTurn's +1.

export const FPS = 30;
/** Joint indices (docs/features.md). */
export const J = { hip: 0, head: 4, lShldr: 5, lHand: 7, rShldr: 8, rHand: 10, lThigh: 11, rThigh: 14 };

/**
 * In the page: install the step wrapper (once) and arm a recording: `askAt` steps after the page
 * started dancing (window.duet.frame, not reset by R), ask a turn in `direction` (0: ask nothing),
 * or each of `asks` ([{at, direction}]), and keep every step's joints of both dancers until `until`
 * steps. Resolves when installed.
 */
export function armProbe(page, { askAt, direction, until, asks }) {
  const planned = asks ?? (direction ? [{ at: askAt, direction }] : []);
  return page.evaluate(
    async ({ planned, until }) => {
      const module = await import('/web/engine/simulation.ts');
      const proto = module.DuetSimulation.prototype;
      if (!proto.__turnProbe) {
        // Where the leader's input holds the figure block and the hands plan, from the page's own
        // layout table (web/mirror/features.ts): figure 660-763, hands plan from 764.
        const features = await import('/web/mirror/features.ts');
        const { NOW } = await import('/web/mirror/rollout.ts');
        const { POSITIONS_SIZE } = await import('/web/mirror/skeleton.ts');
        const blocks = features.blockSlices(features.LEADER_INPUT_LAYOUT);
        // The networks' own body of a dancer this step (before the contact layer): its track at NOW.
        const ownBody = (dancer) => Array.from(dancer.track.positions.subarray(NOW * POSITIONS_SIZE, (NOW + 1) * POSITIONS_SIZE));
        const [figureAt, figureEnd, plannedAt] = [blocks.figure.start, blocks.figure.end, blocks.hands_plan.start];
        const step = proto.step;
        proto.step = async function (steer, temperature) {
          const probe = window.__turnProbe;
          window.__turnSim = this;
          for (const ask of probe?.asks ?? []) {
            if (ask.done || window.duet.frame !== ask.at) continue;
            // The page's own way when it has one (window.duet.askTurn, what T and the turn buttons
            // call), else the simulation's.
            const hook = window.duet.askTurn;
            probe.via = hook ? 'window.duet.askTurn' : 'simulation.askTurn';
            ask.took = hook ? hook(ask.direction) : this.askTurn(ask.direction);
            probe.took = ask.took;
            ask.done = probe.asked = true;
          }
          await step.call(this, steer, temperature);
          // window.duet.frame is incremented right after step() returns: this state is step frame + 1.
          if (probe && window.duet.frame + 1 <= probe.until) {
            probe.steps.push({
              frame: window.duet.frame + 1,
              // As drawn (the views, after the contact layer), and the networks' own bodies.
              leader: Array.from(this.leader.positions),
              follower: Array.from(this.followers[0].positions),
              leaderOwn: ownBody(this.duet.leader),
              followerOwn: ownBody(this.duet.followers[0]),
              // The count this step danced on (beats since the music started) and its tempo.
              beat: this.beat,
              tempo: this.tempo,
              leaderHeading: this.leader.heading,
              followerHeading: this.followers[0].heading,
              turnAsked: this.turnAsked,
              // The figure danced on this step or coming ({name, way, asked, coming}: Simulation.figure).
              led: this.figure ? { ...this.figure } : null,
              // The figure block both dancers read this step (the leader's inputs 660-763, 104
              // numbers: per key t-30..t+30, per kind (features FIGURE_KINDS: her turn to her left,
              // to her right, his turn to his left, to his right), inside and progress), and the first
              // numbers of his hands plan (764: shown, then the left hand's first move).
              figure: Array.from(this.leaderPolicy?.input?.slice(figureAt, figureEnd) ?? []),
              handsPlan: Array.from(this.leaderPolicy?.input?.slice(plannedAt, plannedAt + 4) ?? []),
              steerActive: steer.active,
              t: performance.now(),
            });
          }
        };
        proto.__turnProbe = true;
      }
      window.__turnProbe = { asks: planned.map((a) => ({ ...a, done: false, took: null })), until, asked: false, took: null, steps: [] };
      return true;
    },
    { planned, until },
  );
}

/** A page reloaded under a probe (the dev server reloads it when someone edits the page's source). */
export class Reloaded extends Error {}

/** Wait until the armed recording holds its last step, then return it (plain data). */
export async function readProbe(page, timeoutMs) {
  const done = await page
    .waitForFunction(() => !window.__turnProbe || window.__turnProbe.steps.some((s) => s.frame >= window.__turnProbe.until), null, {
      timeout: timeoutMs,
      polling: 50,
    })
    .then((handle) => handle.jsonValue())
    .catch((error) => {
      if (/Execution context was destroyed|navigation/.test(String(error))) return false;
      throw error;
    });
  const probe = done ? await page.evaluate(() => window.__turnProbe ?? null) : null;
  if (!probe) throw new Reloaded('the page reloaded during the recording');
  return probe;
}

/** Facing angle (radians) of a 17×3 position array from the shoulder and hip lines. */
export function facing(p) {
  const ax = p[3 * J.lThigh] - p[3 * J.rThigh] + p[3 * J.lShldr] - p[3 * J.rShldr];
  const az = p[3 * J.lThigh + 2] - p[3 * J.rThigh + 2] + p[3 * J.lShldr + 2] - p[3 * J.rShldr + 2];
  // forward = cross(across, up) with up = (0, 1, 0): (−az, 0, ax).
  return Math.atan2(-az, ax);
}

/** Unwrap a list of angles (radians) so that consecutive values differ by less than π. */
export function unwrap(angles) {
  const out = [];
  for (const a of angles) {
    if (!out.length) out.push(a);
    else {
      const prev = out[out.length - 1];
      out.push(prev + Math.atan2(Math.sin(a - prev), Math.cos(a - prev)));
    }
  }
  return out;
}

/**
 * The follower's turn over the recorded steps after `from` (the state the request was made in):
 * the facing change in degrees at every later step (unwrapped, + counterclockwise), the largest in
 * `direction`, and the first time (s after the request) it reaches `full` degrees that way.
 */
/**
 * The turn rule of training/evaluation/figures.py `turns`, on an unwrapped facing (radians, one a
 * step): [index, direction ±1] at each index where the facing has changed by `degrees` from some
 * index at most `seconds` before it (and after the previous turn). The page's tests and `lead` in
 * Python count her turns with it, on the same facing.
 */
export function turns(angle, degrees = 300, seconds = 2.5) {
  const span = Math.round(seconds * FPS);
  const need = (degrees * Math.PI) / 180;
  const out = [];
  let anchor = 0;
  for (let t = 1; t < angle.length; t++) {
    let best = 0;
    for (let k = Math.max(anchor, t - span); k < t; k++) {
      const change = angle[t] - angle[k];
      if (Math.abs(change) > Math.abs(best)) best = change;
    }
    if (Math.abs(best) >= need) {
      out.push([t, Math.sign(best)]);
      anchor = t;
    }
  }
  return out;
}

/**
 * Her turns over the recorded steps from the state the request was made in (step `from`) to step
 * `from + frames`, as `lead` counts them after a request (figures.turns on her facing from that
 * state on): [[seconds after the request, direction], ...].
 */
export function followerTurns(steps, from, frames) {
  const window_ = steps.filter((s) => s.frame >= from && s.frame <= from + frames);
  const angle = unwrap(window_.map((s) => facing(s.follower)));
  return turns(angle).map(([i, d]) => [(window_[i].frame - from) / FPS, d]);
}

export function followerTurn(steps, from, direction, full = 300) {
  const window_ = steps.filter((s) => s.frame >= from);
  const angles = unwrap(window_.map((s) => facing(s.follower)));
  const deltas = angles.map((a) => ((a - angles[0]) * 180) / Math.PI);
  let best = 0;
  let at = null;
  for (let i = 0; i < deltas.length; i++) {
    const signed = direction * deltas[i];
    if (signed > best) best = signed;
    if (at === null && signed >= full) at = (window_[i].frame - from) / FPS;
  }
  const absolute = Math.max(...deltas.map(Math.abs));
  return { deltas, net: deltas[deltas.length - 1], best, at, turned: at !== null, absolute };
}

/** The height (m) of the leader's higher hand at each recorded step from `from` on. */
export function leaderHand(steps, from) {
  return steps.filter((s) => s.frame >= from).map((s) => Math.max(s.leader[3 * J.lHand + 1], s.leader[3 * J.rHand + 1]));
}

/** Largest distance (m) between the same joint of two 17×3 position arrays. */
export function poseDistance(a, b) {
  let worst = 0;
  for (let j = 0; j < a.length; j += 3) worst = Math.max(worst, Math.hypot(a[j] - b[j], a[j + 1] - b[j + 1], a[j + 2] - b[j + 2]));
  return worst;
}

/** Per step frame: the largest joint distance between the leaders of two recordings. */
export function leaderDivergence(asked, control) {
  const byFrame = new Map(control.steps.map((s) => [s.frame, s]));
  return asked.steps.filter((s) => byFrame.has(s.frame)).map((s) => ({ frame: s.frame, distance: poseDistance(s.leader, byFrame.get(s.frame).leader) }));
}

/**
 * In the page: copy the stage canvas at the request's step and then every `every` steps, `frames`
 * times (dance time, not wall time: a busy machine dances in slow motion, the strip does not), each
 * right after the page has drawn; compose the copies into a grid with captions and return it as a
 * PNG data URL, with a snapshot of window.duet per frame and each cell's luminance variance.
 * Pass this function to page.evaluate (it is serialized: it uses nothing from this module).
 * `since` names the first step in the captions (a strip of a duet nobody leads: 'from its first frame').
 */
export function captureLedTurn({ askAt, frames, every, crop, scale, columns, title, timeoutMs, since = 'after the request' }) {
  return (async () => {
    const stage = document.querySelector('canvas.stage');
    const w = Math.round(crop.width * scale);
    const h = Math.round(crop.height * scale);
    const header = 36;
    const strip = document.createElement('canvas');
    strip.width = columns * w;
    strip.height = header + Math.ceil(frames / columns) * h;
    const c = strip.getContext('2d', { willReadFrequently: true });
    c.fillStyle = '#ffffff';
    c.fillRect(0, 0, strip.width, strip.height);
    c.fillStyle = '#222';
    c.font = '18px sans-serif';
    c.fillText(title, 10, 24);
    const states = [];
    const deadline = performance.now() + timeoutMs;
    for (let k = 0; k < frames; k++) {
      const target = askAt + k * every;
      while (window.duet.frame < target) {
        if (performance.now() > deadline) throw new Error(`the page stopped at step ${window.duet.frame} before step ${target}`);
        await new Promise((resolve) => setTimeout(resolve, 4));
      }
      await new Promise((resolve) => requestAnimationFrame(resolve));
      const x = (k % columns) * w;
      const y = header + Math.floor(k / columns) * h;
      const sx = stage.width / stage.clientWidth;
      c.drawImage(stage, crop.x * sx, crop.y * sx, crop.width * sx, crop.height * sx, x, y, w, h);
      const state = JSON.parse(JSON.stringify(window.duet));
      states.push(state);
      c.strokeStyle = '#bbb';
      c.strokeRect(x + 0.5, y + 0.5, w - 1, h - 1);
      c.fillStyle = 'rgba(255,255,255,0.8)';
      c.fillRect(x + 4, y + 4, 170, 22);
      c.fillStyle = '#222';
      c.font = '14px sans-serif';
      c.fillText(`+${((state.frame - askAt) / 30).toFixed(2)} s ${since}`, x + 10, y + 20);
    }
    const variances = [];
    for (let k = 0; k < frames; k++) {
      const { data } = c.getImageData((k % columns) * w, header + Math.floor(k / columns) * h + 30, w, h - 30);
      let sum = 0;
      let squares = 0;
      for (let i = 0; i < data.length; i += 4) {
        const l = 0.299 * data[i] + 0.587 * data[i + 1] + 0.114 * data[i + 2];
        sum += l;
        squares += l * l;
      }
      const n = data.length / 4;
      variances.push(squares / n - (sum / n) ** 2);
    }
    return { png: strip.toDataURL('image/png'), states, variances };
  })();
}
