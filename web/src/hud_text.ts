// What the HUD says, the same words as the GLFW viewer's (viewer/hud_text.h).

// Below this the world runs in slow motion (kSlowMotionBelow, common/time_scale.h).
const SLOW_MOTION_BELOW = 0.98;
// A resting overlap deeper than this share of the smaller radius says k is too soft, and balls count as
// resting below this mean kinetic energy per ball, J (common/overlap.h).
const OVERLAP_WARNING = 0.10;
const RESTING_ENERGY_PER_BALL = 5e-3;

// "0.4 % of the smaller radius", with ": stiffness too soft for the load" (warn) once the balls rest
// (an impact's overlap, while balls fly in, is no sign of a soft k).
export function overlapText(fraction: number, energyPerBall: number): { text: string; warn: boolean } {
  const warn = fraction > OVERLAP_WARNING && energyPerBall <= RESTING_ENERGY_PER_BALL;
  return { text: `${(100 * fraction).toFixed(1)} % of the smaller radius${warn ? ': stiffness too soft for the load' : ''}`, warn };
}

// Why the server's figures are not live, or '' when they are.
export function freshnessNote(connected: boolean, now: number, lastUpdate: number): string {
  if (connected) return '';
  if (lastUpdate < 0) return 'not connected, no update yet';
  // Whole seconds, so the count ticks up once a second like a clock.
  return `disconnected, last update ${Math.floor(Math.max(0, now - lastUpdate))} s ago`;
}

export function threadsText(stepping: number, available: number): string {
  const plural = available === 1 ? '' : 's';
  return stepping === 0 ? `${available} thread${plural} at most` : `stepping on ${stepping} of ${available} thread${plural}`;
}

// "paused"; "real time"; "×0.50 as set"; "slow motion ×0.42" (with "(×0.50 set)"
// when slowed too); "-" when the server did not say. A set scale of 0 counts as 1.
export function timeScaleText(timeScale: number, timeScaleSet: number, paused: boolean): string {
  if (paused) return 'paused';
  if (!(timeScale > 0)) return '-';
  const set = timeScaleSet > 0 ? timeScaleSet : 1;
  const slowed = set < SLOW_MOTION_BELOW;
  if (timeScale < SLOW_MOTION_BELOW * set)
    return `slow motion \u00d7${timeScale.toFixed(2)}${slowed ? ` (\u00d7${set.toFixed(2)} set)` : ''}`;
  return slowed ? `\u00d7${set.toFixed(2)} as set` : 'real time';
}

// How the server chose its time step: "1.08 ms, 13 steps per contact: each
// collision's e within 0.005"; "0.7 ms (given), 20.0 steps per contact"; "1.08 ms"
// from a server that does not say; "-" without a dt.
export function stepText(dt: number, stepsPerContact: number, tolerance: number): string {
  if (!(dt > 0)) return '-';
  const ms = Number((1e3 * dt).toPrecision(3));
  if (!(stepsPerContact > 0)) return `${ms} ms`;
  if (tolerance > 0)
    return `${ms} ms, ${stepsPerContact.toFixed(0)} steps per contact: each collision's e within ${Number(tolerance.toPrecision(6))}`;
  return `${ms} ms (given), ${stepsPerContact.toFixed(1)} steps per contact`;
}

// Who may use the controls: this page's part, then the policy.
export function controlText(mayControl: boolean, policy: string): string {
  return (mayControl ? 'yours (P O R [ ] 1-4): ' : 'not yours: ') + policy;
}

// The Player line while in line for a sphere (InLine): next, or how many are ahead.
export function inLineText(ahead: number): string {
  return ahead === 0 ? 'observing, next in line for a sphere' : `observing, in line for a sphere: ${ahead} ahead of you`;
}

// The smallest step performance.now() takes here, over `increments` of its steps (at most forMs, and a bounded
// number of reads): browsers coarsen it against timing attacks, by 0.1 ms in most pages and up to 1 ms or more in
// some browsers and privacy settings. Several steps, not a fixed time: on a busy machine the page may lose the
// processor for longer than a short window, which would read as one coarse step.
export function clockStepMs(now: () => number = () => performance.now(), increments = 10, forMs = 50): number {
  let last = now();
  const until = last + forMs;
  let step = Infinity;
  for (let reads = 0, seen = 0, t = now(); t < until && seen < increments && reads < 1e7; t = now(), ++reads) {
    if (t > last) {
      step = Math.min(step, t - last);
      last = t;
      ++seen;
    }
  }
  return Number.isFinite(step) ? step : forMs;
}

// A round trip no finer than the clock that timed it: "0.3 ms" on a 0.1 ms clock, "3 ms" or "< 1 ms" on a
// 1 ms one; "-" before the first.
export function roundTripText(rttMs: number, clockStep: number): string {
  if (!(rttMs >= 0)) return '-';
  const decimals = Math.min(2, Math.max(0, Math.ceil(-Math.log10(clockStep) - 1e-6)));
  if (rttMs < clockStep) return `< ${clockStep.toFixed(decimals)} ms`;
  return `${rttMs.toFixed(decimals)} ms`;
}
