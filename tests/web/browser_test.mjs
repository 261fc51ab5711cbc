// The browser viewer (web/) in a real, headless Chromium against a real
// fishtank-server: what a student sees and does from a URL. One browser and
// one server for all the checks, in order (each leaves the world as the next
// expects); node --test reports each by name.

import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { after, before, test } from 'node:test';
import { countColours, launchBrowser, sleep, startServer, waitForState } from './harness.mjs';

// Few balls: SwiftShader draws on the CPU, and two tabs share the test's cores.
const SERVER_BALLS = 400;
const SERVER_ARGS = ['--threads', '1', '--balls', String(SERVER_BALLS)];
const outDir = process.env.FISHTANK_WEB_TEST_OUT || '.';
let server;
let browser;
let page;
const pageErrors = [];

async function openPage() {
  const p = await browser.newPage();
  p.on('pageerror', (e) => pageErrors.push(String(e)));
  p.on('console', (m) => m.type() === 'error' && !/WebSocket/.test(m.text()) && pageErrors.push(m.text()));
  await p.goto(server.url);
  return p;
}

const hudText = (p) => p.$eval('#stats', (e) => e.textContent);

// The HUD is rewritten once per frame, and a software-rendered frame can take a third of a
// second or more: poll its text until it says what is expected, then return it.
async function waitForHud(p, pred, timeoutMs = 10000) {
  const deadline = Date.now() + timeoutMs;
  let text = '';
  while (Date.now() < deadline) {
    text = await hudText(p);
    if (pred(text)) return text;
    await sleep(100);
  }
  return text;
}
const own = (s) => s.players.find((p) => p.id === s.playerId);

before(async () => {
  server = await startServer(SERVER_ARGS);
  browser = await launchBrowser();
  page = await openPage();
});

after(async () => {
  await browser?.close();
  await server?.stop();
});

test('the page gets a WebGL2 context and a screenshot shows red, green and blue balls and the white player in its ring', async () => {
  const s = await waitForState(page, (st) => st.drawnBalls > 0 && st.ownPlayerDrawn, 'balls and the player drawn');
  assert.ok(s.webgl2, 'a WebGL2 context');
  // The player starts amid the pouring balls; lifted above them (E), it is in plain view.
  const y0 = own(s).pos[1];
  await page.keyboard.down('KeyE');
  await waitForState(page, (st) => own(st).pos[1] > y0 + 5, 'the player lifted 5 m');
  await page.keyboard.up('KeyE');
  await waitForState(page, (st) => st.ownPlayerDrawn[1] > y0 + 5, 'the lifted player drawn');
  await page.keyboard.press('F1');  // the HUD off: its text is not the scene
  // Balls still pouring past the lifted sphere can hide it in one frame: up to ten frames, 300 ms apart.
  const screenshot = async (done) => {
    let c, png;
    for (let tries = 0; tries < 10 && !(c && done(c)); ++tries) {
      await sleep(300);
      png = await page.screenshot({ type: 'png' });
      c = await countColours(page, png);
    }
    return [c, png];
  };
  // From the first view the sphere is about 4 px in radius: its ring reaches 8 px (OUTLINE_MIN_PX), about
  // 150 px of amber where the ring of a 1.35 times larger sphere would be 50.
  const [ring] = await screenshot((c) => c.amber >= 100);
  assert.ok(ring.amber >= 100, `the amber ring around it 8 px in radius: ${JSON.stringify(ring)}`);
  // Three wheel steps nearer (0.73 of the distance), so that the sphere's white is counted in 40-odd pixels,
  // not 20-odd; undone afterwards.
  const far = (await waitForState(page, (st) => st.cameraDistance > 0, 'a camera')).cameraDistance;
  await page.mouse.move(400, 300);
  for (let i = 0; i < 3; ++i) await page.mouse.wheel({ deltaY: -100 });
  await waitForState(page, (st) => st.cameraDistance < 0.75 * far, 'the camera three steps nearer');
  const [c, png] = await screenshot((n) => n.white >= 20);
  fs.writeFileSync(path.join(outDir, 'web-page.png'), png);
  for (let i = 0; i < 3; ++i) await page.mouse.wheel({ deltaY: 100 });
  await waitForState(page, (st) => Math.abs(st.cameraDistance - far) < 0.01 * far, 'the camera back where it was');
  await page.keyboard.press('F1');
  const summary = JSON.stringify(c);
  assert.ok(c.background < 0.995 * c.total, `not blank: ${summary}`);
  assert.ok(c.red >= 100 && c.green >= 100 && c.blue >= 100, `red, green and blue balls visible: ${summary}`);
  assert.ok(c.blue > c.red && c.green > c.red, `the larger green and blue balls cover more than red: ${summary}`);
  assert.ok(c.white >= 20 && c.white < 0.01 * c.total, `the small white player sphere: ${summary}`);
});

test('the HUD says how the server chose dt: 13 steps per contact from the default tolerance', async () => {
  assert.match(await hudText(page), /Step[\d.]+ ms, 13 steps per contact: each collision's e within 0\.005/);
});

test('the HUD shows the round trip with the decimals the browser clock resolves, as that clock measures itself', async () => {
  const step = await page.evaluate(() => {
    let last = performance.now(), smallest = Infinity;
    for (let i = 0, steps = 0; i < 1e6 && steps < 20; ++i) {
      const t = performance.now();
      if (t > last) [smallest, last, steps] = [Math.min(smallest, t - last), t, steps + 1];
    }
    return smallest;
  });
  const decimals = step >= 0.999 ? 0 : step >= 0.0999 ? 1 : 2;
  const shown = (await waitForHud(page, (t) => /Round trip[<\d]/.test(t))).match(/Round trip(< )?([\d.]+) ms/);
  assert.ok(shown, 'a round trip shown');
  assert.equal(shown[2].split('.')[1]?.length ?? 0, decimals, `${shown[0]} on a clock of ${step} ms steps`);
});

test('the page decodes delta snapshots against its Acks without asking for a keyframe', async () => {
  const s = await waitForState(page, (st) => st.deltas >= 30, '30 delta snapshots');
  assert.equal(s.keyframeRequests, 0);
});

test('a lost WebGL context is said in the HUD, and once the browser restores it the page draws the balls again', async () => {
  // WEBGL_lose_context does what a GPU reset or a phone reclaiming a background tab's memory does.
  await page.evaluate(() => {
    window.loseContext = document.getElementById('view').getContext('webgl2').getExtension('WEBGL_lose_context');
    window.loseContext.loseContext();
  });
  await waitForState(page, (st) => st.contextLost, 'the context lost');
  assert.match(await waitForHud(page, (t) => /context lost/.test(t)), /WebGL context lost\): it draws again/);
  await page.evaluate(() => window.loseContext.restoreContext());
  await waitForState(page, (st) => st.contextLost === false, 'the context restored');
  let c;
  for (let tries = 0; tries < 10 && !(c?.red >= 100 && c?.green >= 100 && c?.blue >= 100); ++tries) {
    await sleep(300);
    c = await countColours(page, await page.screenshot({ type: 'png' }));
  }
  assert.ok(c.red >= 100 && c.green >= 100 && c.blue >= 100, `red, green and blue balls drawn again: ${JSON.stringify(c)}`);
  assert.doesNotMatch(await waitForHud(page, (t) => !/context lost/.test(t)), /context lost/);
});

test('B pours 1000 balls in: the server\'s count rises and the HUD shows it', async () => {
  const before = (await waitForState(page, (st) => st.serverBalls > 0, 'a snapshot')).serverBalls;
  await page.keyboard.press('KeyB');
  await waitForState(page, (st) => st.serverBalls >= before + 1000, `${before + 1000} balls`);
  const ballsShown = (t) => Number(t.match(/Balls(\d+)/)?.[1]);
  const shown = ballsShown(await waitForHud(page, (t) => ballsShown(t) >= before + 1000));
  assert.ok(shown >= before + 1000, `the HUD shows ${shown} balls, ${before} + 1000 at least expected`);
});

test('pressed under the pile (Q), the page\'s own sphere shows through the balls in amber', async () => {
  await page.keyboard.down('KeyQ');
  await waitForState(page, (st) => own(st).pos[1] < 1.5, 'the player on the floor');
  await page.keyboard.up('KeyQ');
  await waitForState(page, (st) => st.ownPlayerDrawn[1] < 1.5, 'the player drawn on the floor');
  await page.keyboard.press('F1');
  let c;
  for (let tries = 0; tries < 10 && !(c?.white < 20 && c?.amber >= 20); ++tries) {
    await sleep(300);
    c = await countColours(page, await page.screenshot({ type: 'png' }));
  }
  await page.keyboard.press('F1');
  const summary = JSON.stringify(c);
  assert.ok(c.white < 20, `no white sphere in view, the pile hides the player: ${summary}`);
  assert.ok(c.amber >= 20, `its amber shows through the balls: ${summary}`);
});

test('holding D moves the player sphere to the camera\'s right (+x at the start)', async () => {
  const start = own(await waitForState(page, (st) => own(st), 'the own player'));
  // Held until the move shows: a software-rendered page on a busy machine can be slow to send its input.
  await page.keyboard.down('KeyD');
  let moved;
  try {
    moved = own(await waitForState(page, (st) => own(st).pos[0] > start.pos[0] + 2, 'the player moved 2 m along +x'));
  } finally {
    await page.keyboard.up('KeyD');
  }
  assert.ok(Math.abs(moved.pos[2] - start.pos[2]) < 0.5, `not along z: ${JSON.stringify([start, moved])}`);
});

test('on a touch screen a pad appears at the first touch: a pinch zooms, the stick moves the sphere forward, +1000 pours balls, ? opens a help a tap closes; on its side the statistics leave the pile in view', async () => {
  const phone = await browser.newPage();
  phone.on('pageerror', (e) => pageErrors.push(String(e)));
  await phone.setViewport({ width: 420, height: 640, hasTouch: true, isMobile: true });
  await phone.goto(server.url);
  const s0 = await waitForState(phone, (st) => st.connection === 'connected' && own(st), 'the phone\'s player');
  assert.equal(s0.touchPadShown, false, 'no pad before a touch: a mouse user never sees it');
  await phone.touchscreen.tap(210, 200);
  assert.ok((await waitForState(phone, (st) => st.touchPadShown, 'the pad shown after a touch')).touchStickShown,
            'a player\'s pad has the stick');

  const far = s0.cameraDistance;
  const a = await phone.touchscreen.touchStart(180, 300);
  const b = await phone.touchscreen.touchStart(240, 300);
  for (let spread = 1; spread <= 4; ++spread) {  // the fingers 60 px apart, then 180: a third of the distance
    await a.move(180 - 15 * spread, 300);
    await b.move(240 + 15 * spread, 300);
  }
  await a.end();
  await b.end();
  const near = (await waitForState(phone, (st) => st.cameraDistance < 0.5 * far, 'the camera pinched nearer')).cameraDistance;
  assert.ok(Math.abs(near / far - 1 / 3) < 0.05, `spread x3, distance ${far} -> ${near}`);

  // The stick pushed to its top edge: forward, away from the camera, -z at the start.
  const stick = await phone.$eval('.touchpad .stick', (e) => JSON.parse(JSON.stringify(e.getBoundingClientRect())));
  const [cx, cy] = [stick.x + stick.width / 2, stick.y + stick.height / 2];
  const start = own(await waitForState(phone, (st) => own(st), 'the phone\'s player'));
  const finger = await phone.touchscreen.touchStart(cx, cy);
  await finger.move(cx, stick.y + 2);
  try {
    const moved = own(await waitForState(phone, (st) => own(st).pos[2] < start.pos[2] - 2, 'the player moved 2 m along -z'));
    assert.ok(Math.abs(moved.pos[0] - start.pos[0]) < 0.5, `not along x: ${JSON.stringify([start, moved])}`);
  } finally {
    await finger.end();
  }

  const before = (await waitForState(phone, (st) => st.serverBalls > 0, 'a snapshot')).serverBalls;
  const add = await phone.$$eval('.touchpad button', (bs) => {
    const r = bs.find((b) => b.textContent === '+1000').getBoundingClientRect();
    return [r.x + r.width / 2, r.y + r.height / 2];
  });
  await phone.touchscreen.tap(add[0], add[1]);
  await waitForState(phone, (st) => st.serverBalls >= before + 1000, `${before + 1000} balls`);

  // ? opens the help over the pad's buttons, ? among them; a tap on the help closes it.
  const centre = (selector, text) => phone.$$eval(selector, (es, t) => {
    const e = es.find((x) => t === undefined || x.textContent === t);
    const r = e.getBoundingClientRect();
    return [r.x + r.width / 2, r.y + r.height / 2];
  }, text);
  const question = await centre('.touchpad button', '?');
  await phone.touchscreen.tap(question[0], question[1]);
  await phone.waitForFunction(() => !document.getElementById('help').hidden, { timeout: 10000 });
  // Where a button of the pad lies under the help, the help is what shows there.
  const covered = await phone.evaluate(() => {
    const h = document.getElementById('help').getBoundingClientRect();
    return [...document.querySelectorAll('.touchpad button')].map((b) => b.getBoundingClientRect())
      .filter((r) => r.bottom > h.top + 1 && r.top < h.bottom - 1 && r.right > h.left + 1 && r.left < h.right - 1)
      .map((r) => {
        const x = (Math.max(r.left, h.left) + Math.min(r.right, h.right)) / 2;
        const y = (Math.max(r.top, h.top) + Math.min(r.bottom, h.bottom)) / 2;
        return document.elementFromPoint(x, y)?.closest('#help') !== null;
      });
  });
  assert.ok(covered.length > 0, 'the help reaches over the pad\'s buttons on a phone held upright');
  assert.ok(covered.every(Boolean), `the help is drawn above the pad's buttons: ${JSON.stringify(covered)}`);
  const help = await centre('#help');
  await phone.touchscreen.tap(help[0], help[1]);
  await phone.waitForFunction(() => document.getElementById('help').hidden, { timeout: 10000 });

  // Turned on its side, the statistics take two columns across the top and leave the pile in view.
  await phone.setViewport({ width: 844, height: 390, hasTouch: true, isMobile: true });
  await sleep(500);
  const stats = await phone.$eval('#stats', (e) => JSON.parse(JSON.stringify(e.getBoundingClientRect())));
  assert.ok(stats.height < 0.45 * 390, `the statistics ${stats.height} px tall of 390 on a phone on its side`);
  await phone.close();
});

test('two tabs see one world: each sees the other\'s player, and one tab\'s move in the other', async () => {
  // Two windows side by side: tab 1 stays visible, and so watching, while tab 2 is in front. Left to
  // Chromium it would be a hidden tab, and a software-rendered tab 2 can take over two seconds to move.
  await page.evaluate(() => Object.defineProperty(document, 'visibilityState', { get: () => 'visible', configurable: true }));
  const second = await openPage();
  const s2 = await waitForState(second, (st) => st.connection === 'connected' && own(st), 'the second tab\'s player');
  const s1 = await waitForState(page, (st) => st.players.some((p) => p.id === s2.playerId), 'tab 1 sees tab 2\'s player');
  assert.notEqual(s1.clientId, s2.clientId);
  assert.ok(s2.players.some((p) => p.id === s1.playerId), 'tab 2 sees tab 1\'s player');
  assert.equal(s2.serverBalls, s1.serverBalls, 'the same balls');
  const x0 = s1.players.find((p) => p.id === s2.playerId).pos[0];
  // Held until tab 1 sees the move: a software-rendered page may take seconds to send its first input.
  await second.bringToFront();
  await second.keyboard.down('KeyA');
  try {
    await waitForState(page, (st) => st.players.find((p) => p.id === s2.playerId).pos[0] < x0 - 2,
                       'tab 1 sees tab 2\'s player move 2 m along -x');
  } finally {
    await second.keyboard.up('KeyA');
  }
  await second.close();
});

test('a page hidden over two seconds asks for no snapshots, and shown again decodes the world without asking for a keyframe', async () => {
  // Returns the page's clock at the change.
  const setVisibility = (p, state) => p.evaluate((s) => {
    Object.defineProperty(document, 'visibilityState', { get: () => s, configurable: true });
    document.dispatchEvent(new Event('visibilitychange'));
    return performance.now();
  }, state);
  await page.bringToFront();
  const shown = await waitForState(page, (st) => st.connection === 'connected' && st.watching, 'a watching page');
  const hiddenAt = await setVisibility(page, 'hidden');
  await sleep(1000);
  // Read with the time since the page was hidden: a busy main thread may answer only after the 2 s grace.
  const glance = await page.evaluate((t0) => ({ watching: window.fishtank.state().watching, ms: performance.now() - t0 }),
    hiddenAt);
  if (glance.ms < 1900) assert.equal(glance.watching, true, `a glance away keeps the snapshots: ${JSON.stringify(glance)}`);
  else console.log(`# the glance-away check was skipped: the page answered ${glance.ms.toFixed(0)} ms after it was hidden`);
  const off = await waitForState(page, (st) => !st.watching, 'watching off after the grace');
  // Snapshots already on their way still arrive: wait for a quiet half second (a busy machine may take longer).
  let quiet = await waitForState(page, () => true, 'state');
  for (let tries = 0; tries < 10; ++tries) {
    await sleep(500);
    const now = await waitForState(page, () => true, 'state');
    if (now.decoded === quiet.decoded) break;
    quiet = now;
  }
  await sleep(1500);
  const later = await waitForState(page, () => true, 'state');
  assert.equal(later.decoded, quiet.decoded, 'no snapshot decoded while hidden');
  assert.equal(later.bytes - quiet.bytes < 2000, true, `at most a few Pongs received while hidden, got ${later.bytes - quiet.bytes} bytes`);
  await setVisibility(page, 'visible');
  const back = await waitForState(page, (st) => st.watching && st.decoded > later.decoded + 30, 'snapshots again');
  assert.equal(back.keyframeRequests, shown.keyframeRequests, 'the server sent what the page could decode');
  assert.equal(back.connection, 'connected');
  assert.ok(off.serverBalls > 0 && back.serverBalls >= off.serverBalls);
});

test('the HUD says why and "disconnected" when the server stops, also with the statistics hidden, and the page reconnects when it returns', async () => {
  const port = server.port;
  await server.stop();
  await waitForState(page, (st) => st.connection !== 'connected', 'the page to notice');
  const why = /server_stopping: the server is stopping: it was stopped \(Ctrl-C or SIGTERM\); reconnecting/;
  assert.match(await waitForHud(page, (t) => /server_stopping/.test(t)), why, 'the server\'s last word, kept on close');
  const gone = /disconnected, last update [1-9]\d* s ago; trying again every second/;
  assert.match(await waitForHud(page, (t) => gone.test(t)), gone);
  await page.keyboard.press('F1');  // the statistics hidden (a phone's HUD button): the loss still shows
  const alone = await page.waitForFunction(() => {
    const a = document.getElementById('alerts');
    return a && !a.hidden && /disconnected, last update/.test(a.textContent) ? a.textContent : '';
  }, { timeout: 10000 });
  assert.match(await alone.jsonValue(), gone);
  await page.keyboard.press('F1');
  await page.waitForFunction(() => document.getElementById('alerts').hidden, { timeout: 10000 });
  assert.match(await waitForHud(page, (t) => gone.test(t)), gone, 'with the statistics shown, the warnings are in them');
  server = await startServer(SERVER_ARGS, port);
  const s = await waitForState(page, (st) => st.welcomes >= 2 && st.connection === 'connected' && st.serverBalls > 0,
                               'a new Welcome and a snapshot');
  assert.ok(s.serverBalls <= SERVER_BALLS, `the new server's world, not the old one's ${SERVER_BALLS + 1000} balls`);
  assert.doesNotMatch(await waitForHud(page, (t) => !/disconnected/.test(t)), /disconnected/);
  assert.match(await hudText(page), /connected again: the server is back/, 'the return is said');
});

test('where every player sphere is taken, the page observes in line, says why, offers no stick, P is refused, and it gets the sphere its holder frees', async () => {
  const full = await startServer(['--threads', '1', '--balls', '100', '--max-players', '1']);
  try {
    const holder = await browser.newPage();
    await holder.goto(full.url);
    assert.equal((await waitForState(holder, (st) => st.connection === 'connected', 'a Welcome')).hasPlayer, true);
    const p = await browser.newPage();
    await p.setViewport({ width: 800, height: 600, hasTouch: true });
    await p.goto(full.url);
    const s = await waitForState(p, (st) => st.connection === 'connected' && st.serverBalls > 0, 'a snapshot');
    assert.equal(s.hasPlayer, false);
    const why = await waitForHud(p, (t) => /player_limit/.test(t));
    assert.match(why, /player_limit: .*in line for the next one freed/, 'the server\'s words, below the statistics');
    await p.touchscreen.tap(400, 200);
    const pad = await waitForState(p, (st) => st.touchPadShown, 'the pad shown after a touch');
    assert.equal(pad.touchStickShown, false, 'an observer\'s pad has no stick: it has no sphere to move');
    await p.keyboard.press('KeyP');
    const hud = await waitForHud(p, (t) => /not_permitted/.test(t));
    assert.match(hud, /Playerobserving, next in line for a sphere/);
    assert.doesNotMatch(hud, /reload the page/, 'one in line needs no reload: the server hands it the next sphere');
    assert.match(hud, /Controlnot yours/);
    assert.match(hud, /not_permitted/);

    await holder.close();  // its sphere is freed, and this page is first in line
    const granted = await waitForState(p, (st) => st.hasPlayer && st.touchStickShown, 'the freed sphere, and the stick');
    assert.ok(granted.players.some((pl) => pl.id === granted.playerId), 'the granted sphere is in the snapshots');
    const playing = await waitForHud(p, (t) => /Playeryours/.test(t));
    assert.match(playing, /Playeryours is the white sphere with the amber ring/);
    assert.match(playing, /Controlyours/);
    await p.close();
  } finally {
    await full.stop();
  }
});

test('the page threw no errors', () => {
  assert.deepEqual(pageErrors, []);
});
