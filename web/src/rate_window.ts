// A count per second over a window of time: the HUD's frames a second, and the link's snapshots and bytes.
// A hidden page draws no frames and its timers are throttled, so its windows restart when it is shown
// again: the first figure after covers only time the page was shown, as the GLFW viewer leaves the time it
// was minimised out of its frame rate.

export class RateWindow {
  perSecond = 0;  // over the last window closed
  meanGap = 0;  // seconds per counted event over it, 0 where none was counted
  private counted = 0;
  private started: number;

  constructor(now: number) {
    this.started = now;
  }

  add(n = 1): void {
    this.counted += n;
  }

  // Closes the window at `now` (seconds) where it is at least `least` seconds long: whether it did.
  close(now: number, least = 0): boolean {
    const span = now - this.started;
    if (span <= 0 || span < least) return false;
    this.perSecond = this.counted / span;
    this.meanGap = this.counted > 0 ? span / this.counted : 0;
    this.restart(now);
    return true;
  }

  // A new window from `now`, forgetting what the open one counted.
  restart(now: number): void {
    this.counted = 0;
    this.started = now;
  }
}
