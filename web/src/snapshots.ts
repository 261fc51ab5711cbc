// Snapshot interpolation, as the GLFW viewer does it (viewer/net/snapshot_buffer.h):
// a frame at local time `now` shows the server's state at now - offset - delay,
// where offset maps local time to simulated time (from the least delayed
// arrival) and delay is about 1.5 snapshot intervals, so the newer snapshot of
// the pair has almost always arrived already.

export interface Player {
  id: number;
  pos: [number, number, number];
}

// One decoded Snapshot; `quantised` and `kinds` are what the renderer uploads as they are.
export interface Frame {
  tick: number;
  simTime: number;
  received: number;  // performance.now() seconds at arrival
  ballCount: number;
  quantised: Uint16Array;  // 3 per ball, over [tankMin, tankMax]
  kinds: Uint8Array;  // one per ball, an index into Welcome.ball_kinds
  tankMin: [number, number, number];
  tankMax: [number, number, number];
  players: Player[];
  stepsPerS: number;
  load: number;
  threadsStepping: number;
  timeScale: number;
  timeScaleSet: number;
  maxOverlap: number;  // the deepest overlap, a share of the smaller radius
  kineticEnergyPerBall: number;  // J
  paused: boolean;
  scene: string;
  sceneStart: number;
}

export interface Pair {
  from: Frame;
  to: Frame;
  alpha: number;  // 0: from, 1: to
}

const SMOOTHING = 0.05;  // weight of one new sample
const DELAY_INTERVALS = 1.5;
const MIN_DELAY = 0.02;  // seconds
const MAX_DELAY = 0.25;
const KEPT = 8;  // enough for a delay of several intervals

export class SnapshotBuffer {
  private frames: Frame[] = [];  // oldest first
  private offset = 0;  // local time - simulated time of the least delayed arrival
  private meanInterval = 0;  // of simulated time between snapshots, smoothed

  clear(): void {
    this.frames = [];
    this.offset = 0;
    this.meanInterval = 0;
  }

  push(f: Frame): void {
    const sample = f.received - f.simTime;
    const last = this.newest();
    if (!last) {
      this.offset = sample;
    } else {
      // A late arrival says little; drifting up slowly follows a server that falls behind.
      this.offset = sample < this.offset ? sample : this.offset + SMOOTHING * (sample - this.offset);
      const interval = f.simTime - last.simTime;
      if (interval > 0)
        this.meanInterval = this.meanInterval === 0 ? interval : this.meanInterval + SMOOTHING * (interval - this.meanInterval);
    }
    this.frames.push(f);
    if (this.frames.length > KEPT) this.frames.shift();
  }

  newest(): Frame | null {
    return this.frames.length ? this.frames[this.frames.length - 1] : null;
  }

  renderDelay(): number {
    return Math.min(MAX_DELAY, Math.max(MIN_DELAY, DELAY_INTERVALS * this.meanInterval));
  }

  // The pair that brackets the render time; both the newest once it is past it.
  frameAt(now: number): Pair | null {
    if (!this.frames.length) return null;
    const t = now - this.offset - this.renderDelay();
    for (let i = this.frames.length - 1; i > 0; --i) {
      const a = this.frames[i - 1];
      const b = this.frames[i];
      if (t < a.simTime) continue;
      if (t >= b.simTime) return { from: b, to: b, alpha: 0 };
      const span = b.simTime - a.simTime;
      return { from: a, to: b, alpha: span > 0 ? Math.min((t - a.simTime) / span, 1) : 1 };
    }
    return { from: this.frames[0], to: this.frames[0], alpha: 0 };  // older than anything kept
  }
}
