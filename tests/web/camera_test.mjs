// The page's orbit camera (web/src/camera.ts, bundled for node by tests/web/CMakeLists.txt): its first view
// holds the whole tank whatever the canvas's shape, a phone held upright as well as a wide monitor.

import assert from 'node:assert/strict';
import { test } from 'node:test';
import { need } from './harness.mjs';

const { OrbitCamera } = await import(need('FISHTANK_WEB_MODULE'));

// The largest |x| and |y| of the tank's eight corners in normalised device coordinates.
function cornersReach(min, max, aspect) {
  const camera = new OrbitCamera();
  camera.frame(min, max);
  const m = camera.viewProjection(aspect);  // column-major
  let x = 0;
  let y = 0;
  for (let i = 0; i < 8; ++i) {
    const c = [i & 1 ? max[0] : min[0], i & 2 ? max[1] : min[1], i & 4 ? max[2] : min[2], 1];
    const clip = [0, 1, 2, 3].map((row) => c.reduce((sum, v, col) => sum + m[col * 4 + row] * v, 0));
    assert.ok(clip[3] > 0, 'every corner in front of the camera');
    x = Math.max(x, Math.abs(clip[0] / clip[3]));
    y = Math.max(y, Math.abs(clip[1] / clip[3]));
  }
  return { x, y };
}

test('the first view holds the whole tank on a tall, square or wide canvas, the 40-unit one not small', () => {
  const tanks = [
    { name: 'the 40-unit tank', min: [-20, 0, -20], max: [20, 40, 20], notSmall: true },
    { name: 'about the wide scene\'s at 100 000 balls', min: [-143, 0, -143], max: [143, 40, 143], notSmall: false },
  ];
  for (const t of tanks)
    for (const aspect of [0.46, 0.75, 1, 1.25, 1.78, 2.4]) {
      const { x, y } = cornersReach(t.min, t.max, aspect);
      const where = `${t.name} at aspect ${aspect}: reaches x ${x.toFixed(3)}, y ${y.toFixed(3)}`;
      assert.ok(x < 1 && y < 1, `${where}; a corner is off the canvas`);
      if (t.notSmall) assert.ok(Math.max(x, y) > 0.5, `${where}; not even halfway to an edge`);
    }
});
