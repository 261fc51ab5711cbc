// Keys and mouse (viewer/input.h, viewer/sandbox_controls.h): held keys become
// the player's velocity, key presses one-shot actions, a drag orbits the
// camera and the wheel zooms.

import type { OrbitCamera, Vec3 } from './camera';
import { normalize } from './camera';
import type { Frame } from './snapshots';
import * as wire from './wire';

// The scene presets in the order keys 1-4 choose them (common/scene_names.h).
export const SCENE_NAMES = ['tank', 'wide', 'dam-break', 'drop'];
// The time-scale ladder [ and ] move along (kTimeScaleLadder).
const TIME_SCALE_LADDER = [0.1, 0.25, 0.5, 1];

export interface Actions {
  toggleTank: boolean;  // T
  toggleHelp: boolean;  // H
  toggleHud: boolean;  // F1
  addBalls: boolean;  // B
  togglePause: boolean;  // P
  singleStep: boolean;  // O: pauses first if running
  reset: boolean;  // R
  timeScaleChange: number;  // ]: +1 faster, [: -1 slower
  scene: number;  // 1-4 as 0-3; -1: none
}

const noActions = (): Actions => ({
  toggleTank: false, toggleHelp: false, toggleHud: false, addBalls: false, togglePause: false, singleStep: false,
  reset: false, timeScaleChange: 0, scene: -1,
});

// The next rung from `current` in `direction` (-1 slower, +1 faster), staying on the ladder's ends.
export function nextTimeScale(current: number, direction: number): number {
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
    const current = newest.timeScaleSet > 0 ? newest.timeScaleSet : 1;  // a server that does not say runs at real time
    frames.push(wire.setTimeScale(nextTimeScale(current, a.timeScaleChange)));
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
  private dragging = false;
  private lastX = 0;
  private lastY = 0;
  private dx = 0;
  private dy = 0;
  private wheel = 0;

  constructor(canvas: HTMLCanvasElement) {
    window.addEventListener('keydown', (e) => {
      if (e.ctrlKey || e.metaKey || e.altKey) return;  // the browser's shortcuts (Ctrl+R reloads, not resets)
      this.held.add(e.code);
      if (!e.repeat && this.press(e.code)) e.preventDefault();
    });
    window.addEventListener('keyup', (e) => this.held.delete(e.code));
    window.addEventListener('blur', () => this.held.clear());  // keys released elsewhere never send keyup here
    canvas.addEventListener('pointerdown', (e) => {
      this.dragging = e.button === 0;
      this.lastX = e.clientX;
      this.lastY = e.clientY;
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointermove', (e) => {
      if (!this.dragging) return;
      this.dx += e.clientX - this.lastX;
      this.dy += e.clientY - this.lastY;
      this.lastX = e.clientX;
      this.lastY = e.clientY;
    });
    canvas.addEventListener('pointerup', () => (this.dragging = false));
    canvas.addEventListener('wheel', (e) => {
      this.wheel += e.deltaY < 0 ? 1 : -1;
      e.preventDefault();
    }, { passive: false });
  }

  takeActions(): Actions {
    const a = this.pending;
    this.pending = noActions();
    return a;
  }

  // Unit direction (or zero) from the held keys, relative to the camera on the
  // ground plane: W/S forward/back, A/D left/right, E or Space up, Q or Shift down.
  movement(camera: OrbitCamera): Vec3 {
    const f = camera.forwardOnGround();
    const r = camera.rightOnGround();
    const d: Vec3 = [0, 0, 0];
    const add = (v: Vec3, sign: number): void => v.forEach((c, i) => (d[i] += sign * c));
    if (this.held.has('KeyW')) add(f, 1);
    if (this.held.has('KeyS')) add(f, -1);
    if (this.held.has('KeyD')) add(r, 1);
    if (this.held.has('KeyA')) add(r, -1);
    if (this.held.has('KeyE') || this.held.has('Space')) d[1] += 1;
    if (this.held.has('KeyQ') || this.held.has('ShiftLeft') || this.held.has('ShiftRight')) d[1] -= 1;
    return normalize(d);  // diagonals no faster than straight moves
  }

  driveCamera(camera: OrbitCamera): void {
    if (this.dx || this.dy) camera.orbit(this.dx, this.dy);
    if (this.wheel) camera.zoom(this.wheel);
    this.dx = this.dy = this.wheel = 0;
  }

  // True when the key is one of ours (the browser's default is then suppressed).
  private press(code: string): boolean {
    const a = this.pending;
    switch (code) {
      case 'KeyT': a.toggleTank = true; break;
      case 'KeyH': a.toggleHelp = true; break;
      case 'F1': a.toggleHud = true; break;
      case 'KeyB': a.addBalls = true; break;
      case 'KeyP': a.togglePause = true; break;
      case 'KeyO': a.singleStep = true; break;
      case 'KeyR': a.reset = true; break;
      case 'BracketLeft': a.timeScaleChange = -1; break;
      case 'BracketRight': a.timeScaleChange = 1; break;
      case 'Digit1': case 'Digit2': case 'Digit3': case 'Digit4': a.scene = Number(code.slice(5)) - 1; break;
      case 'Space': break;  // held for up; not a page scroll
      default: return false;
    }
    return true;
  }
}
