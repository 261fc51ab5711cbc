// The browser viewer: connects to the server that served the page (its /ws),
// draws what it sends, and sends back the keys. The loop, once per display frame:
//   input ─► velocity, commands ─► Connection      Connection ─► SnapshotBuffer
//   SnapshotBuffer.frameAt(now) ─► Renderer.draw ─► HUD
//
// URL options: ?observer (ask for no player sphere), ?ws=URL (another server).

import { OrbitCamera } from './camera';
import { Input, sandboxFrames } from './controls';
import { Hud } from './hud';
import { Connection } from './net';
import { RateWindow } from './rate_window';
import { Renderer } from './render';
import type { Player } from './snapshots';
import * as wire from './wire';

const PLAYER_SPEED = 8;  // m/s; the server clamps at its own maximum
const BALLS_PER_PRESS = 1000;

const params = new URLSearchParams(location.search);
const observerAsked = params.has('observer');
const wsUrl = params.get('ws') ?? `${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws`;

const canvas = document.getElementById('view') as HTMLCanvasElement;
const gl = canvas.getContext('webgl2', { antialias: true });
let renderer = gl ? new Renderer(gl) : null;
const webglProblem = gl ? '' : 'This browser gives the page no WebGL2 context: nothing can be drawn (the HUD still works); '
  + 'open the page in another browser, or turn hardware acceleration on in its settings.';
// A GPU reset, or a phone reclaiming memory from a tab in the background, takes
// the context and everything made in it; preventDefault asks for it back.
let contextLost = false;
let restoreProblem = '';  // why the page could not draw again after a restore
const CONTEXT_LOST = 'The GPU took this page\'s drawing away (WebGL context lost): it draws again once the browser gives it back.';
canvas.addEventListener('webglcontextlost', (e) => {
  e.preventDefault();
  contextLost = true;
  renderer = null;
  canvas.style.opacity = '0';  // the browser paints a lost canvas white, under the statistics; it keeps its events
});
canvas.addEventListener('webglcontextrestored', () => {
  try {
    renderer = new Renderer(gl!);
  } catch (e) {
    // Lost again while compiling: the next restore tries again; anything else will not mend itself.
    if (!gl!.isContextLost()) restoreProblem = `The page could not draw again after losing its WebGL context (${e}): reload it.`;
    return;
  }
  kindsOf = null;  // the new renderer is told the kinds again
  contextLost = false;
  canvas.style.opacity = '';
});
const overlay = document.getElementById('overlay')!;
const input = new Input(canvas, overlay);
const camera = new OrbitCamera();
const net = new Connection(wsUrl, !observerAsked, `web ${navigator.userAgent.split(' ').pop() ?? ''}`.slice(0, 64),
                           () => input.movement(camera).map((c) => c * PLAYER_SPEED));
const hud = new Hud(overlay);
let framed = '';  // the tank the camera was framed for: again only when a scene's tank differs
let kindsOf: unknown = null;
let showTank = true;
const frameRate = new RateWindow(performance.now() / 1000);
let ownPlayer: Player | null = null;
let drawnBalls = 0;
let framesDrawn = 0;

function resize(): void {
  const dpr = window.devicePixelRatio || 1;
  const w = Math.round(canvas.clientWidth * dpr);
  const h = Math.round(canvas.clientHeight * dpr);
  if (canvas.width !== w || canvas.height !== h) {
    canvas.width = w;
    canvas.height = h;
  }
}

function frame(nowMs: number): void {
  const now = nowMs / 1000;
  const info = net.info;
  if (info && kindsOf !== info) {
    renderer?.setKinds(info.kinds);
    kindsOf = info;
  }

  input.setPlayer(info?.hasPlayer ?? !observerAsked);
  const a = input.takeActions();
  if (a.toggleHelp) hud.toggleHelp();
  if (a.toggleHud) hud.toggleStats();
  if (a.toggleTank) showTank = !showTank;
  for (let press = 0; press < a.addBalls; ++press) net.send(wire.addBalls(BALLS_PER_PRESS));
  for (const f of sandboxFrames(a, net.snapshots.newest())) net.send(f);
  input.driveCamera(camera);

  resize();
  const pair = net.snapshots.frameAt(now);
  let players: Player[] = [];
  let own = -1;
  if (pair) {
    const tank = `${pair.to.tankMin} ${pair.to.tankMax}`;
    if (tank !== framed) {
      camera.frame(pair.to.tankMin, pair.to.tankMax);
      framed = tank;
    }
    // Players move a little between snapshots too; those new in `to` appear where they are.
    players = pair.to.players.map((pb) => {
      const pa = pair.from.players.find((p) => p.id === pb.id);
      const pos = pa ? pb.pos.map((c, i) => pa.pos[i] + (c - pa.pos[i]) * pair.alpha) as Player['pos'] : pb.pos;
      return { id: pb.id, pos };
    });
    if (info?.hasPlayer) own = players.findIndex((p) => p.id === info.playerId);
  }
  ownPlayer = own >= 0 ? players[own] : null;
  drawnBalls = pair ? pair.to.ballCount : 0;
  if (renderer) {  // frames count only where a picture is drawn (none while the context is lost)
    renderer.draw(camera.viewProjection(canvas.width / Math.max(1, canvas.height)), pair, players, own, showTank);
    frameRate.add();
    ++framesDrawn;
  }
  frameRate.close(now, 0.5);
  hud.update(net, { fps: frameRate.perSecond, frameMs: 1000 * frameRate.meanGap, now,
                    renderDelayMs: 1000 * net.snapshots.renderDelay(), observerAsked,
                    webgl: restoreProblem || (contextLost ? CONTEXT_LOST : webglProblem) });
  requestAnimationFrame(frame);
}
requestAnimationFrame(frame);
document.addEventListener('visibilitychange', () => {
  const visible = document.visibilityState !== 'hidden';
  if (visible) frameRate.restart(performance.now() / 1000);
  net.setVisible(visible);
});
net.setVisible(document.visibilityState !== 'hidden');

// What the browser tests (tests/web) read; plain values, so page.evaluate can return them.
(window as unknown as { fishtank: unknown }).fishtank = {
  state: () => ({
    webgl2: gl !== null,
    contextLost,
    connection: net.state,
    welcomes: net.welcomes,
    watching: net.watching,
    hasPlayer: net.info?.hasPlayer ?? false,
    playerId: net.info?.playerId ?? -1,
    clientId: net.info?.clientId ?? -1,
    ownPlayerDrawn: ownPlayer ? [...ownPlayer.pos] : null,
    drawnBalls,
    // From the newest snapshot, whether or not the tab is drawing (a hidden tab is not).
    serverBalls: net.snapshots.newest()?.ballCount ?? 0,
    players: net.snapshots.newest()?.players ?? [],
    deltas: net.deltas,
    keyframeRequests: net.keyframeRequests,
    decoded: net.decoded,
    decodeMs: net.decodeMs,
    framesDrawn,
    bytes: net.bytes,
    fps: frameRate.perSecond,
    cameraDistance: camera.distanceToTarget(),
    touchPadShown: !document.querySelector<HTMLElement>('.touchpad')!.hidden,
    touchStickShown: !document.querySelector<HTMLElement>('.touchpad .stick')!.hidden,
  }),
};
