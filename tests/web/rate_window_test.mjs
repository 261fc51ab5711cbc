// The page's rates (web/src/rate_window.ts, bundled for node by tests/web/CMakeLists.txt): frames and
// snapshots a second over a window, and a window restarted when a hidden page is shown again covering only
// the time it was shown.

import assert from 'node:assert/strict';
import { test } from 'node:test';
import { need } from './harness.mjs';

const { RateWindow } = await import(need('FISHTANK_WEB_MODULE'));

test('30 frames in half a second are 60 a second, 16.7 ms apart', () => {
  const w = new RateWindow(10);
  for (let i = 0; i < 30; ++i) w.add();
  assert.equal(w.close(10.5, 0.5), true);
  assert.equal(w.perSecond, 60);
  assert.ok(Math.abs(w.meanGap - 1 / 60) < 1e-12);
});

test('a window shorter than asked stays open and counts on', () => {
  const w = new RateWindow(0);
  w.add(10);
  assert.equal(w.close(0.3, 0.5), false);
  assert.equal(w.perSecond, 0);
  w.add(20);
  assert.equal(w.close(0.6, 0.5), true);
  assert.equal(w.perSecond, 50);
});

test('bytes count by their size, and a window with none reads 0 a second and no gap', () => {
  const w = new RateWindow(0);
  w.add(1500);
  w.add(500);
  w.close(2);
  assert.equal(w.perSecond, 1000);
  w.close(3);
  assert.equal(w.perSecond, 0);
  assert.equal(w.meanGap, 0);
});

test('a page hidden for 11 s and shown again: restarted, its first figure is of the shown time only', () => {
  const unrestarted = new RateWindow(0), restarted = new RateWindow(0);
  for (const w of [unrestarted, restarted]) w.add();  // the last frame before the page was hidden
  restarted.restart(11.5);  // shown again: no frames came while hidden
  for (const w of [unrestarted, restarted]) {
    for (let i = 0; i < 30; ++i) w.add();
    w.close(12, 0.5);
  }
  assert.ok(unrestarted.perSecond < 3, `the hidden time counted: ${unrestarted.perSecond}`);
  assert.equal(restarted.perSecond, 60);
});
