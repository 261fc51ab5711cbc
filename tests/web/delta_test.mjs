// The page's delta decoder (web/src/delta.ts, bundled for node by tests/web/CMakeLists.txt)
// against the server's encoder: every case delta_vectors writes comes back value for
// value, and a damaged stream is refused with a reason.

import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { test } from 'node:test';
import { need } from './harness.mjs';

const { decodePositionsDelta } = await import(need('FISHTANK_WEB_MODULE'));
const cases = execFileSync(need('FISHTANK_DELTA_VECTORS')).toString().trim().split('\n').map((l) => JSON.parse(l));

const kept = (tick, values) => (values.length ? { tick, positions: Uint16Array.from(values) } : null);
const decode = (c, changes = c.changes) =>
  decodePositionsDelta(kept(c.baseTick, c.base), kept(c.priorTick, c.prior), c.tick, Uint8Array.from(c.unchanged),
                       Uint8Array.from(changes), c.now.length / 3);

test('the encoder wrote every case', () => assert.equal(cases.length, 9));

for (const c of cases) {
  test(`"${c.name}" decodes to exactly the positions coded`, () => {
    const out = decode(c);
    assert.equal(typeof out, 'object', `refused: ${out}`);
    assert.deepEqual(Array.from(out), c.now);
  });
}

test('a stream cut short, or with a byte too many, is refused with a reason', () => {
  const c = cases.find((k) => k.name === 'jitter');
  assert.match(decode(c, c.changes.slice(0, -2)), /ends inside/);
  assert.match(decode(c, [...c.changes, 0xff]), /bytes after its last ball/);
});
