// Keys, mouse and touch (viewer/input.h, viewer/sandbox_controls.h): held keys
// or the touch pad's stick become the player's velocity, key presses and pad
// buttons one-shot actions; a drag orbits the camera, the wheel or a pinch zooms.

import type { OrbitCamera, Vec3 } from './camera';
import { normalize, ZOOM_PER_STEP } from './camera';
import type { Frame } from './snapshots';
import { TouchPad } from './touch_pad';
import * as wire from './wire';

// The scene presets in the order keys 1-4 choose them (common/scene_names.h).
const SCENE_NAMES = ['tank', 'wide', 'dam-break', 'drop'];
// The time-scale ladder [ and ] move along (kTimeScaleLadder).
const TIME_SCALE_LADDER = [0.1, 0.25, 0.5, 1];

export interface Actions {
  toggleTank: boolean;  // T
  toggleHelp: boolean;  // H
  toggleHud: boolean;  // F1
  addBalls: number;  // B presses (a slow page may take several in one frame)
  togglePause: boolean;  // P
  singleStep: boolean;  // O: pauses first if running
  reset: boolean;  // R
  timeScaleChange: number;  // rungs: ] +1 faster, [ -1 slower, each press
  scene: number;  // 1-4 as 0-3; -1: none
}

const noActions = (): Actions => ({
  toggleTank: false, toggleHelp: false, toggleHud: false, addBalls: 0, togglePause: false, singleStep: false,
  reset: false, timeScaleChange: 0, scene: -1,
});

// The next rung from `current` in `direction` (-1 slower, +1 faster), staying on the ladder's ends.
function nextTimeScale(current: number, direction: number): number {
  if (direction > 0) return TIME_SCALE_LADDER.find((r) => r > current * 1.001) ?? TIME_SCALE_LADDER[TIME_SCALE_LADDER.length - 1];
  return [...TIME_SCALE_LADDER].reverse().find((r) => r < current * 0.999) ?? TIME_SCALE_LADDER[0];
}

// The frames the sandbox keys ask for, in order; nothing before the first snapshot.
export function sandboxFrames(a: Actions, newest: Frame | null): Uint8Array[] {
  const frames: Uint8Array[] = [];
  if (!newest) return frames;
  if (a.scene >= 0 && a.scene < SCENE_NAMES.length) frames.push(wire.reset(SCENE_NAMES[a.scene]));
  if (a.reset) frames.push(wire.reset(''));
  if (a.timeScaleChange !== 0) {
    let scale = newest.timeScaleSet > 0 ? newest.timeScaleSet : 1;  // a server that does not say runs at real time
    for (let rung = 0; rung < Math.abs(a.timeScaleChange); ++rung) scale = nextTimeScale(scale, Math.sign(a.timeScaleChange));
    frames.push(wire.setTimeScale(scale));
  }
  if (a.togglePause) frames.push(wire.pause(!newest.paused));
  if (a.singleStep) {
    if (!newest.paused && !a.togglePause) frames.push(wire.pause(true));
    frames.push(wire.step(1));
  }
  return frames;
}

export class Input {
  private pending = noActions();
  private readonly held = new Set<string>();
  private readonly pad: TouchPad;
  private readonly touches = new Map<number, [number, number]>();  // on the canvas, by pointer id
  private dragging = false;
  private lastX = 0;
  private lastY = 0;
  private dx = 0;
  private dy = 0;
  private wheel = 0;

  constructor(canvas: HTMLCanvasElement, overlay: HTMLElement) {
    this.pad = new TouchPad(overlay, (b) => {
      if (b === 'addBalls') ++this.pending.addBalls;
      else if (b === 'help') this.pending.toggleHelp = true;
      else this.pending.toggleHud = true;
    });
    window.addEventListener('keydown', (e) => {
      if (e.ctrlKey || e.metaKey || e.altKey) return;  // the browser's shortcuts (Ctrl+R reloads, not resets)
      this.held.add(e.code);
      if (!e.repeat && this.press(e.code)) e.preventDefault();
    });
    window.addEventListener('keyup', (e) => this.held.delete(e.code));
    window.addEventListener('blur', () => this.held.clear());  // keys released elsewhere never send keyup here
    canvas.addEventListener('pointerdown', (e) => {
      if (e.pointerType === 'touch') {
        this.pad.show();
        this.touches.set(e.pointerId, [e.clientX, e.clientY]);
      }
      this.dragging = e.button === 0 && this.touches.size <= 1;  // a second finger pinches instead
      this.lastX = e.clientX;
      this.lastY = e.clientY;
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointermove', (e) => {
      if (this.touches.has(e.pointerId) && this.touches.size === 2) return this.pinch(e);
      if (!this.dragging) return;
      this.dx += e.clientX - this.lastX;
      this.dy += e.clientY - this.lastY;
      this.lastX = e.clientX;
      this.lastY = e.clientY;
    });
    for (const end of ['pointerup', 'pointercancel'] as const) {
      canvas.addEventListener(end, (e) => {
        this.touches.delete(e.pointerId);
        this.dragging = false;  // after a pinch, the finger left does not orbit until it lifts
      });
    }
    canvas.addEventListener('wheel', (e) => {
      this.wheel += e.deltaY < 0 ? 1 : -1;
      e.preventDefault();
    }, { passive: false });
  }

  // Whether the touch pad offers the stick and ▲ ▼ (a player) or only its buttons (an observer).
  setPlayer(hasPlayer: boolean): void {
    this.pad.setPlayer(hasPlayer);
  }

  takeActions(): Actions {
    const a = this.pending;
    this.pending = noActions();
    return a;
  }

  // Direction, relative to the camera on the ground plane: W/S forward/back, A/D
  // left/right, E or Space up, Q or Shift down; or the touch pad's, as far as its
  // stick is pushed. At most unit length: diagonals no faster than straight moves.
  movement(camera: OrbitCamera): Vec3 {
    const key = (...codes: string[]): number => (codes.some((c) => this.held.has(c)) ? 1 : 0);
    const [padRight, padUp, padForward] = this.pad.direction();
    const right = key('KeyD') - key('KeyA') + padRight;
    const up = key('KeyE', 'Space') - key('KeyQ', 'ShiftLeft', 'ShiftRight') + padUp;
    const forward = key('KeyW') - key('KeyS') + padForward;
    const f = camera.forwardOnGround();
    const r = camera.rightOnGround();
    const d: Vec3 = [forward * f[0] + right * r[0], up, forward * f[2] + right * r[2]];
    return Math.hypot(...d) > 1 ? normalize(d) : d;
  }

  driveCamera(camera: OrbitCamera): void {
    if (this.dx || this.dy) camera.orbit(this.dx, this.dy);
    if (this.wheel) camera.zoom(this.wheel);
    this.dx = this.dy = this.wheel = 0;
  }

  // Two fingers apart or together: the camera's distance in the ratio of their spread, in wheel steps.
  private pinch(e: PointerEvent): void {
    const [a, b] = [...this.touches.values()];
    const before = Math.hypot(a[0] - b[0], a[1] - b[1]);
    this.touches.set(e.pointerId, [e.clientX, e.clientY]);
    const [c, d] = [...this.touches.values()];
    const after = Math.hypot(c[0] - d[0], c[1] - d[1]);
    if (before > 0 && after > 0) this.wheel += Math.log(after / before) / -Math.log(ZOOM_PER_STEP);
  }

  // True when the key is one of ours (the browser's default is then suppressed).
  private press(code: string): boolean {
    const a = this.pending;
    switch (code) {
      case 'KeyT': a.toggleTank = true; break;
      case 'KeyH': a.toggleHelp = true; break;
      case 'F1': a.toggleHud = true; break;
      case 'KeyB': ++a.addBalls; break;
      case 'KeyP': a.togglePause = true; break;
      case 'KeyO': a.singleStep = true; break;
      case 'KeyR': a.reset = true; break;
      case 'BracketLeft': --a.timeScaleChange; break;
      case 'BracketRight': ++a.timeScaleChange; break;
      case 'Digit1': case 'Digit2': case 'Digit3': case 'Digit4': a.scene = Number(code.slice(5)) - 1; break;
      case 'Space': break;  // held for up; not a page scroll
      default: return false;
    }
    return true;
  }
}
