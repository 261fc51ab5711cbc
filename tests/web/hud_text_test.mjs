// The page's HUD words (web/src/hud_text.ts, bundled for node by tests/web/CMakeLists.txt): a round trip is
// shown no finer than the browser's clock can time it, that clock's step is found by sampling it, the
// control line says this page's part, then the policy, and the overlap warns as the viewer's does.

import assert from 'node:assert/strict';
import { test } from 'node:test';
import { need } from './harness.mjs';

const { clockStepMs, controlText, inLineText, overlapText, roundTripText } = await import(need('FISHTANK_WEB_MODULE'));

// A clock that reads `step`-coarsened time and advances `tick` ms per read, like a browser's performance.now().
const coarseClock = (step, tick = 0.013) => {
  let t = 1000;
  return () => Math.floor((t += tick) / step) * step;
};

test('the clock step is found from the clock itself: 1 ms, 0.1 ms, and 5 µs', () => {
  assert.equal(clockStepMs(coarseClock(1)), 1);
  assert.ok(Math.abs(clockStepMs(coarseClock(0.1)) - 0.1) < 1e-6);
  assert.ok(Math.abs(clockStepMs(coarseClock(0.005, 0.001)) - 0.005) < 1e-6);
});

test('a clock that never moves while sampled reads as coarse as the sampling', () => {
  assert.equal(clockStepMs(() => 7, 10, 5), 5);
});

test('the page losing the processor for 12 ms while sampling does not read as a 12 ms clock', () => {
  const clock = coarseClock(0.1);
  let reads = 0;
  const preempted = () => clock() + (++reads > 3 ? 12 : 0);  // descheduled after the third read
  assert.ok(Math.abs(clockStepMs(preempted) - 0.1) < 1e-6);
});

test('a round trip has only the decimals its clock resolves', () => {
  assert.equal(roundTripText(3, 1), '3 ms');
  assert.equal(roundTripText(0, 1), '< 1 ms');  // a 1 ms clock cannot time a sub-millisecond loop
  assert.equal(roundTripText(0.3000000001, 0.1), '0.3 ms');
  assert.equal(roundTripText(0.05, 0.1), '< 0.1 ms');
  assert.equal(roundTripText(0.2345, 0.005), '0.23 ms');
  assert.equal(roundTripText(-1, 0.1), '-');
});

test('the control line says whether this page may, then the policy', () => {
  assert.equal(controlText(true, 'players may'), 'yours (P O R [ ] 1-4): players may');
  assert.equal(controlText(false, 'observers may not'), 'not yours: observers may not');
});

test('in line for a sphere, the Player line says next, or how many are ahead (the viewer\'s twin words)', () => {
  assert.equal(inLineText(0), 'observing, next in line for a sphere');
  assert.equal(inLineText(3), 'observing, in line for a sphere: 3 ahead of you');
});

test('the overlap warns as the viewer does: beyond a tenth of the smaller radius once the balls rest, not on impact', () => {
  assert.deepEqual(overlapText(0.004, 0.0), { text: '0.4 % of the smaller radius', warn: false });
  assert.deepEqual(overlapText(0.28, 40.0), { text: '28.0 % of the smaller radius', warn: false });  // a pour's impacts
  assert.deepEqual(overlapText(0.15, 0.001),
    { text: '15.0 % of the smaller radius: stiffness too soft for the load', warn: true });
});
