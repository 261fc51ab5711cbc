// The page's orbit camera (web/src/camera.ts, bundled for node by tests/web/CMakeLists.txt): its first view
// holds the whole tank whatever the canvas's shape, a phone held upright as well as a wide monitor, and it
// measures how large a sphere is on screen (the own sphere's ring has a least size).

import assert from 'node:assert/strict';
import { test } from 'node:test';
import { need } from './harness.mjs';

const { OrbitCamera, outlineGrow, radiusOnScreen } = await import(need('FISHTANK_WEB_MODULE'));

const sub = (a, b) => a.map((v, i) => v - b[i]);
const add = (a, b) => a.map((v, i) => v + b[i]);
const scale = (a, k) => a.map((v) => v * k);
const norm = (a) => scale(a, 1 / Math.hypot(...a));
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];

// Where `p` lands on a canvas `heightPx` tall, in pixels from its centre.
function onScreen(m, p, heightPx, aspect) {
  const clip = [0, 1, 2, 3].map((row) => [...p, 1].reduce((sum, v, col) => sum + m[col * 4 + row] * v, 0));
  return [0.5 * heightPx * aspect * clip[0] / clip[3], 0.5 * heightPx * clip[1] / clip[3]];
}

// The largest |x| and |y| of the tank's eight corners in normalised device coordinates (m: column-major).
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

test('a sphere\'s radius on screen is the pixels from its centre to its outline\'s top, near or far, tall or wide', () => {
  for (const aspect of [0.46, 1.25])
    for (const wheel of [0, 10, -8]) {
      const camera = new OrbitCamera();
      camera.frame([-20, 0, -20], [20, 40, 20]);
      camera.zoom(wheel);
      const m = camera.viewProjection(aspect);
      // A sphere on the line of sight through the target (the view's centre); the top of its outline is where
      // the tangent from the eye along the camera's up axis touches it.
      const eye = camera.eye();
      const sight = norm(sub([0, 18, 0], eye));
      const up = norm(cross(cross(sight, [0, 1, 0]), sight));
      const distance = 0.6 * Math.hypot(...sub([0, 18, 0], eye));
      const centre = add(eye, scale(sight, distance));
      const radius = 0.5;
      const angle = Math.asin(radius / distance);
      const top = add(eye, scale(add(scale(sight, Math.cos(angle)), scale(up, Math.sin(angle))), distance));
      const [cx, cy] = onScreen(m, centre, 1000, aspect);
      const [tx, ty] = onScreen(m, top, 1000, aspect);
      const expected = Math.hypot(tx - cx, ty - cy);
      const got = radiusOnScreen(m, centre, radius, 1000);
      assert.ok(Math.abs(got - expected) < 0.01 * expected, `aspect ${aspect}, wheel ${wheel}: ${got} px, ${expected} expected`);
    }
});

test('the own sphere\'s ring reaches 8 px however small the sphere is on screen, and is 1.35 times a large one', () => {
  assert.ok(Math.abs(outlineGrow(2.5, 8, 1.35) * 2.5 - 8) < 1e-9, 'a phone\'s first view: 16 px across');
  assert.equal(outlineGrow(20, 8, 1.35), 1.35);
  assert.equal(outlineGrow(0, 8, 1.35), 1.35, 'behind the camera: nothing to grow');
});
