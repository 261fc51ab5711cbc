// On-screen controls for a touch screen: a phone or tablet in a classroom has no keys. A stick moves the
// player sphere on the ground plane (up: away from the camera, as W), two buttons raise and lower it (E, Q),
// and three stand for B, H and F1. The pad appears at the first touch, so a desk with a mouse never sees it;
// an observer's has no stick and no ▲ ▼, as it has no sphere to move.

export type PadButton = 'addBalls' | 'help' | 'hud';

export class TouchPad {
  private readonly root: HTMLElement;
  private readonly knob: HTMLElement;
  private readonly moves: HTMLElement[];  // the stick and ▲ ▼: shown only to a player
  private right = 0;  // the stick's deflection, each in -1 .. 1 and together at most 1
  private forward = 0;
  private vertical = 0;  // +1 while ▲ is held, -1 while ▼ is

  constructor(parent: HTMLElement, onButton: (b: PadButton) => void) {
    this.root = element('div', 'touchpad', parent);
    this.root.hidden = true;
    const stick = element('div', 'stick', this.root);
    this.knob = element('div', 'knob', stick);
    stick.addEventListener('pointerdown', (e) => {
      stick.setPointerCapture(e.pointerId);
      this.deflect(stick, e);
    });
    stick.addEventListener('pointermove', (e) => stick.hasPointerCapture(e.pointerId) && this.deflect(stick, e));
    for (const end of ['pointerup', 'pointercancel'] as const) stick.addEventListener(end, () => this.deflect(stick, null));

    const buttons = element('div', 'buttons', this.root);
    const hold = (label: string, direction: number): HTMLElement => {
      const b = button(label, buttons);
      b.addEventListener('pointerdown', (e) => {
        b.setPointerCapture(e.pointerId);
        this.vertical = direction;
      });
      for (const end of ['pointerup', 'pointercancel'] as const) b.addEventListener(end, () => (this.vertical = 0));
      return b;
    };
    this.moves = [stick, hold('▲', 1), hold('▼', -1)];
    const labels: [PadButton, string][] = [['addBalls', '+1000'], ['hud', 'HUD'], ['help', '?']];
    for (const [name, label] of labels) button(label, buttons).addEventListener('click', () => onButton(name));
  }

  show(): void {
    this.root.hidden = false;
  }

  // Whether this page has a sphere to move (an observer has none).
  setPlayer(hasPlayer: boolean): void {
    for (const e of this.moves) if (e.hidden === hasPlayer) e.hidden = !hasPlayer;
  }

  // The stick and the ▲ ▼ buttons: [right, up, forward], each in -1 .. 1.
  direction(): [number, number, number] {
    return [this.right, this.vertical, this.forward];
  }

  private deflect(stick: HTMLElement, e: PointerEvent | null): void {
    const r = stick.getBoundingClientRect();
    const half = r.width / 2;
    let x = e ? (e.clientX - r.left - half) / half : 0;
    let y = e ? (r.top + half - e.clientY) / half : 0;
    const length = Math.hypot(x, y);
    if (length > 1) [x, y] = [x / length, y / length];
    [this.right, this.forward] = [x, y];
    this.knob.style.transform = `translate(${x * half}px, ${-y * half}px)`;
  }
}

function element(tag: string, className: string, parent: HTMLElement): HTMLElement {
  const e = document.createElement(tag);
  e.className = className;
  parent.append(e);
  return e;
}

function button(label: string, parent: HTMLElement): HTMLElement {
  const b = element('button', '', parent);
  b.textContent = label;
  return b;
}
