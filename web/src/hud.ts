// The statistics panel and the help overlay, as HTML over the canvas. Figures
// that came from the server are greyed, with the reason, when the link is down;
// with the panel hidden, its warnings still show on their own.

import {
  clockStepMs, controlText, freshnessNote, inLineText, overlapText, roundTripText, stepText, threadsText,
  timeScaleText,
} from './hud_text';
import type { Connection } from './net';

const HELP: [string, string][] = [
  ['W / S', 'move your sphere forward / back (away from / towards the camera)'],
  ['A / D', 'move your sphere left / right'],
  ['E or Space', 'move your sphere up'],
  ['Q or Shift', 'move your sphere down'],
  ['Left-drag', 'orbit the camera around the tank'],
  ['Wheel', 'zoom in / out'],
  ['B', 'pour 1000 more balls in from the top'],
  ['P', 'pause / resume the simulation (for everyone)'],
  ['O', 'one step (pauses first)'],
  ['R', 'reset: the scene from its start'],
  ['[ / ]', 'time scale slower / faster: 0.1, 0.25, 0.5, 1'],
  ['1 2 3 4', 'scene: tank, wide, dam-break, drop'],
  ['', '(P O R [ ] 1-4 as the server\'s --control allows: see Control)'],
  ['T', 'show / hide the tank\'s edges'],
  ['F1', 'show / hide the statistics'],
  ['H', 'show / hide this help'],
  ['Touch', 'drag: orbit; pinch: zoom; the stick moves your sphere, ▲ ▼ raise and lower it,'],
  ['', '+1000, HUD and ? stand for B, F1 and H; a tap on this help closes it'],
];

export interface HudView {
  fps: number;
  frameMs: number;
  now: number;  // seconds, the clock of Connection.lastUpdate
  renderDelayMs: number;
  observerAsked: boolean;
  webgl: string;  // '' when WebGL2 works, else why not
}

export class Hud {
  private readonly stats: HTMLElement;
  private readonly alerts: HTMLElement;  // the statistics' warnings while they are hidden
  private readonly help: HTMLElement;
  private readonly clockStep = clockStepMs();  // round trips are shown no finer than this

  constructor(root: HTMLElement) {
    this.stats = document.createElement('div');
    this.stats.id = 'stats';
    this.alerts = document.createElement('div');
    this.alerts.id = 'alerts';
    this.alerts.hidden = true;
    this.help = document.createElement('div');
    this.help.id = 'help';
    this.help.hidden = true;
    const table = document.createElement('table');
    for (const [key, what] of HELP) {
      const row = table.insertRow();
      row.insertCell().textContent = key;
      row.insertCell().textContent = what;
    }
    const title = document.createElement('h2');
    title.textContent = 'Controls';
    this.help.append(title, table);
    this.help.addEventListener('click', () => (this.help.hidden = true));  // on a touch screen it covers the ? button
    root.append(this.stats, this.alerts, this.help);
  }

  toggleHelp(): void {
    this.help.hidden = !this.help.hidden;
  }

  toggleStats(): void {
    this.stats.hidden = !this.stats.hidden;
    if (!this.stats.hidden) this.alerts.hidden = true;  // the panel says them itself from its next update
  }

  update(net: Connection, v: HudView): void {
    const s = net.snapshots.newest();
    const note = freshnessNote(net.state === 'connected', v.now, s ? net.lastUpdate : -1);
    const live = note === '';
    // A lost server, a refusal or no WebGL is said whether or not the statistics are shown.
    const alerts: string[] = [];
    if (v.webgl) alerts.push(`<div class="warn">${escape(v.webgl)}</div>`);
    const retry = net.retrying ? '; trying again every second' : '';  // after the server's notice has gone
    if (!live) alerts.push(`<div class="warn" id="freshness">${escape(note + retry)}</div>`);
    const notice = net.currentNotice();
    if (notice) alerts.push(`<div class="warn notice">${escape(notice)}</div>`);
    this.alerts.hidden = !this.stats.hidden || alerts.length === 0;
    if (this.stats.hidden) {
      this.alerts.innerHTML = alerts.join('');
      return;
    }
    const info = net.info;
    const rows: [string, string, string][] = [];  // label, value, class: live (the page's own figures always are)
    const row = (label: string, value: string, fromServer = true, warn = false): void => {
      rows.push([label, value, !fromServer || live ? (warn ? ' warn' : '') : ' stale']);
    };
    row('Frames', `${v.fps.toFixed(1)} fps   ${v.frameMs.toFixed(2)} ms/frame`, false);
    row('Physics', s ? `${s.stepsPerS.toFixed(0)} steps/s   load ${(100 * s.load).toFixed(0)} %` : '-');
    row('Time', s ? timeScaleText(s.timeScale, s.timeScaleSet, s.paused) : '-');
    row('Scene', s ? `${s.scene || '-'} (start ${s.sceneStart})` : '-');
    row('Balls', s ? `${s.ballCount}` : '-');
    const overlap = s ? overlapText(s.maxOverlap, s.kineticEnergyPerBall) : null;
    row('Overlap', overlap ? overlap.text : '-', true, overlap?.warn);
    row('Threads', info ? threadsText(s ? s.threadsStepping : 0, info.threads) : '-');
    row('Server', info ? `${info.variant} (SIMD ${info.simd})` : location.host);
    row('Step', info ? stepText(info.dt, info.stepsPerContact, info.tolerance) : '-');
    row('Snapshots', `${net.snapshotsPerS.toFixed(1)} /s   render delay ${v.renderDelayMs.toFixed(0)} ms`);
    const perBall = s && s.ballCount > 0 && net.snapshotsPerS > 0 ? `, ${(net.bytesPerS / (net.snapshotsPerS * s.ballCount)).toFixed(2)} B per ball` : '';
    row('Bandwidth', `${(net.bytesPerS / 1024).toFixed(1)} KiB/s in${perBall}`);
    row('Round trip', roundTripText(net.rttMs, this.clockStep));
    if (info) {
      row('Player', info.hasPlayer ? 'yours is the white sphere with the amber ring'
        : v.observerAsked ? 'observing, as asked (?observer)'
          : net.inLine && net.aheadInLine >= 0 ? inLineText(net.aheadInLine)
          // One in line gets the next sphere freed; one whose sphere was freed asks again by a reload.
          : `observing: ${net.observing || 'the server gave no player sphere'}${net.inLine ? '' : '; reload the page to ask for one again'}`);
      row('Control', controlText(info.mayControl, info.controlPolicy));
    }

    const lines = rows.map(([label, value, kind]) =>
      `<div class="row${kind}"><span class="label">${label}</span><span>${escape(value)}</span></div>`);
    const webgl = v.webgl ? 1 : 0;  // why nothing is drawn comes first
    this.stats.innerHTML = [...alerts.slice(0, webgl), ...lines, ...alerts.slice(webgl),
      '<div class="dim">H (or ? on a touch screen): help</div>'].join('');
  }
}

function escape(text: string): string {
  return text.replace(/[&<>"]/g, (c) => `&#${c.charCodeAt(0)};`);
}
