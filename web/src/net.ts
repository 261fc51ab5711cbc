// The connection to fishtank-server's /ws (viewer/net/client.h is its twin):
// Hello, then Welcome; BallKinds and Snapshots (full or delta) decoded into
// Frames for the SnapshotBuffer, each acknowledged so later ones can be
// deltas; the player's velocity 30 times a second; a Ping a second. When the
// socket closes it tries again every second, for as long as the page is open.

import {
  BallKinds, Error as WireError, ErrorCode, InLine, Message, Payload, PlayerGranted, Pong, Snapshot, Welcome,
} from 'fishtank-wire';
import { ReceivedSnapshots } from './delta';
import type { BallKind } from './render';
import { Frame, Player, SnapshotBuffer } from './snapshots';
import { RateWindow } from './rate_window';
import * as wire from './wire';

const INPUT_PERIOD_MS = 1000 / 30;
const RECONNECT_MS = 1000;
const NOTICE_SECONDS = 8;
// A page hidden this long asks for no snapshots: it draws none, and decoding
// them would cost the student's processor. A glance at another tab keeps them.
const HIDDEN_GRACE_MS = 2000;

export interface ServerInfo {
  clientId: number;
  variant: string;
  simd: string;
  threads: number;
  tankMin: [number, number, number];
  tankMax: [number, number, number];
  dt: number;
  stepsPerContact: number;  // contact duration of the lightest pair / dt; 0: not reported
  tolerance: number;  // the per-collision error dt was chosen for; 0: dt given
  kinds: BallKind[];
  hasPlayer: boolean;
  playerId: number;
  snapshotRateHz: number;
  controlPolicy: string;
  mayControl: boolean;
  observersMayControl: boolean;  // whether it may without a sphere (once the server frees its own)
}

export type State = 'connecting' | 'connected' | 'disconnected';

const seconds = (): number => performance.now() / 1000;

export class Connection {
  state: State = 'connecting';
  retrying = false;  // a connection was lost and is tried again every RECONNECT_MS
  info: ServerInfo | null = null;
  readonly snapshots = new SnapshotBuffer();
  lastUpdate = -1;  // seconds() of the newest snapshot, -1 before any
  rttMs = -1;
  // Counted for the tests and the curious: decoded deltas, keyframes asked for, connections made.
  deltas = 0;
  keyframeRequests = 0;
  welcomes = 0;
  decodeMs = 0;  // spent turning Snapshots into Frames, in all
  decoded = 0;
  bytes = 0;  // received, in all
  observing = '';  // the server's reason when this page has no player sphere, if it gave one
  inLine = false;  // refused a sphere for want of one: the server gives this page the next one freed
  aheadInLine = -1;  // while in line, how many clients are before this page (InLine); -1: not told
  watching = true;  // whether the server is asked for snapshots (Watching)
  private notice = '';
  private noticeTime = 0;
  // The newest message's words where it was an Error: the server sends nothing after the Error that ends a connection.
  private lastError = '';
  private socket: WebSocket | null = null;
  private kinds = new Uint8Array(0);
  private readonly received = new ReceivedSnapshots();
  private inputSequence = 0;
  private hiddenTimer: ReturnType<typeof setTimeout> | undefined;
  private readonly snapshotRate = new RateWindow(seconds());
  private readonly byteRate = new RateWindow(seconds());

  // velocity() is sampled at each input tick, not per drawn frame: a slow or
  // hidden tab draws few frames but still steers.
  constructor(private readonly url: string, private readonly wantsPlayer: boolean, private readonly name: string,
              private readonly velocity: () => number[]) {
    this.connect();
    setInterval(() => this.sendInput(), INPUT_PERIOD_MS);
    setInterval(() => this.everySecond(), 1000);
  }

  // The newest server notice (an Error's words, a lost connection), while it is recent.
  currentNotice(): string {
    return this.notice && seconds() - this.noticeTime < NOTICE_SECONDS ? this.notice : '';
  }

  get snapshotsPerS(): number {
    return this.snapshotRate.perSecond;
  }

  get bytesPerS(): number {
    return this.byteRate.perSecond;
  }

  // The page shown or hidden (document.visibilityState).
  setVisible(visible: boolean): void {
    clearTimeout(this.hiddenTimer);
    if (!visible) {
      this.hiddenTimer = setTimeout(() => this.watch(false), HIDDEN_GRACE_MS);
      return;
    }
    this.watch(true);
    this.snapshotRate.restart(seconds());
    this.byteRate.restart(seconds());
  }

  private watch(on: boolean): void {
    if (on === this.watching) return;
    this.watching = on;
    this.send(wire.watching(on));  // a new connection starts on; onWelcome says off again
  }

  send(frame: Uint8Array): void {
    if (this.state === 'connected' && this.socket) this.socket.send(frame);
  }

  private say(text: string): void {
    this.notice = text;
    this.noticeTime = seconds();
  }

  private connect(): void {
    this.state = 'connecting';
    let socket: WebSocket;
    try {
      socket = new WebSocket(this.url);
    } catch (error) {
      this.state = 'disconnected';
      return this.say(`cannot connect to ${this.url}: ${error}`);  // a malformed ?ws= address: retrying cannot help
    }
    socket.binaryType = 'arraybuffer';
    this.socket = socket;
    socket.onopen = () => socket.send(wire.hello(this.name, this.wantsPlayer));
    socket.onmessage = (e: MessageEvent) => {
      if (socket !== this.socket || !(e.data instanceof ArrayBuffer)) return;
      this.byteRate.add(e.data.byteLength);
      this.bytes += e.data.byteLength;
      const m = wire.readMessage(e.data);
      if (!m) return this.lose('the server sent something that is not a Fishtank message');
      this.lastError = '';
      // JavaScript's FlatBuffers has no verifier: a damaged message throws while it is read.
      try {
        this.handle(m);
      } catch (error) {
        this.lose(`the server sent a message the page cannot read (${error}); reconnecting`);
      }
    };
    socket.onclose = (e: CloseEvent) => {
      if (socket !== this.socket) return;
      // 1001 (going away) and 1008 (policy) are the server's own end, after the Error that says why.
      const farewell = (e.code === 1001 || e.code === 1008) && this.lastError;
      if (farewell) this.say(`${this.lastError}; reconnecting`);
      else if (this.state === 'connected')
        this.say(`connection closed${e.reason ? `: ${e.reason}` : ''} (code ${e.code}); reconnecting`);
      this.lastError = '';
      this.state = 'disconnected';
      this.socket = null;
      this.retrying = true;
      setTimeout(() => this.connect(), RECONNECT_MS);
    };
  }

  // Drops the connection; onclose then tries again.
  private lose(why: string): void {
    this.say(why);
    this.socket?.close();
  }

  private handle(m: Message): void {
    switch (m.payloadType()) {
      case Payload.Welcome:
        return this.onWelcome(m.payload(new Welcome()) as Welcome);
      case Payload.BallKinds:
        return this.onBallKinds(m.payload(new BallKinds()) as BallKinds);
      case Payload.Snapshot:
        return this.onSnapshot(m.payload(new Snapshot()) as Snapshot);
      case Payload.Error: {
        const e = m.payload(new WireError()) as WireError;
        const text = `${ErrorCode[e.code()] ?? `error ${e.code()}`}: ${e.message() ?? ''}`;
        this.lastError = text;
        // Why this page observes stays on the HUD, not only for a notice's few seconds.
        if (e.code() === ErrorCode.player_limit || e.code() === ErrorCode.player_idle) this.observing = text;
        if (e.code() === ErrorCode.player_limit) this.inLine = true;
        if (e.code() === ErrorCode.player_idle) this.inLine = false;
        // The sphere was freed: from now on this page observes.
        if (e.code() === ErrorCode.player_idle && this.info) {
          this.info.hasPlayer = false;
          this.info.mayControl = this.info.observersMayControl;
        }
        return this.say(text);
      }
      case Payload.PlayerGranted: {
        // Another client's sphere was freed and this page, in line for one, has it now.
        const g = m.payload(new PlayerGranted()) as PlayerGranted;
        if (!this.info) return this.lose('the server granted a player sphere before Welcome');
        this.info.hasPlayer = true;
        this.info.playerId = g.playerId();
        this.info.mayControl = g.mayControl();
        this.observing = '';
        this.inLine = false;
        this.aheadInLine = -1;
        return this.say('a player sphere was freed and is yours now (the white one with the amber ring)');
      }
      case Payload.InLine:
        this.aheadInLine = (m.payload(new InLine()) as InLine).ahead();
        return;
      case Payload.Pong: {
        const p = m.payload(new Pong()) as Pong;
        this.rttMs = ((Math.round(seconds() * 1e6) - p.clientTimeUs()) >>> 0) / 1000;
        return;
      }
      default:
        return;
    }
  }

  private onWelcome(w: Welcome): void {
    const vec = (v: { x(): number; y(): number; z(): number } | null): [number, number, number] =>
      v ? [v.x(), v.y(), v.z()] : [0, 0, 0];
    const kinds: BallKind[] = [];
    for (let i = 0; i < w.ballKindsLength(); ++i) {
      const k = w.ballKinds(i)!;
      kinds.push({ diameter: k.diameter(), rgb: [k.r(), k.g(), k.b()] });
    }
    this.info = {
      clientId: w.clientId(),
      variant: w.serverVariant() ?? '?',
      simd: w.simdLevel() ?? '?',
      threads: w.workerThreads(),
      tankMin: vec(w.tankMin()),
      tankMax: vec(w.tankMax()),
      dt: w.dt(),
      stepsPerContact: w.stepsPerContact(),
      tolerance: w.tolerance(),
      kinds,
      hasPlayer: w.hasPlayer(),
      playerId: w.playerId(),
      snapshotRateHz: w.snapshotRateHz(),
      controlPolicy: w.controlPolicy() ?? 'not stated by the server',
      mayControl: w.mayControl(),
      observersMayControl: w.observersMayControl(),
    };
    this.observing = '';
    this.inLine = false;
    this.aheadInLine = -1;
    this.kinds = new Uint8Array(0);
    this.received.clear();
    this.snapshots.clear();
    this.state = 'connected';
    if (this.retrying) this.say('connected again: the server is back');
    this.retrying = false;
    ++this.welcomes;
    if (!this.watching) this.send(wire.watching(false));
  }

  private onBallKinds(k: BallKinds): void {
    const first = k.firstNewBall();
    // Earlier than the kinds known: a scene started again and ids restart; later: a gap.
    if (first > this.kinds.length) return this.lose('the server skipped ball kinds');
    const more = k.kindsArray() ?? new Uint8Array(0);
    const known = this.info?.kinds.length ?? 0;
    if (more.some((kind) => kind >= known)) return this.lose('the server sent a ball kind it did not describe');
    // A new array, not an update in place: frames already decoded keep theirs.
    const kinds = new Uint8Array(first + more.length);
    kinds.set(this.kinds.subarray(0, first));
    kinds.set(more, first);
    this.kinds = kinds;
  }

  private onSnapshot(s: Snapshot): void {
    if (!this.info) return;
    const count = s.ballCount();
    if (count > this.kinds.length) return this.lose('the server sent balls of unknown kind');
    const started = performance.now();
    const quantised = this.received.positions(s);
    if (typeof quantised === 'string') {
      this.send(wire.ack(s.tick(), true));
      ++this.keyframeRequests;
      return this.say(`${quantised}; asked for a keyframe`);
    }
    this.send(wire.ack(s.tick()));
    if (s.unchangedArray()) ++this.deltas;
    const players: Player[] = [];
    for (let i = 0; i < s.playerPositionsLength(); ++i) {
      const p = s.playerPositions(i)!;
      players.push({ id: s.playerIds(i) ?? 0, pos: [p.x(), p.y(), p.z()] });
    }
    const min = s.tankMin();
    const max = s.tankMax();
    const f: Frame = {
      tick: s.tick(),
      simTime: s.simTime(),
      received: seconds(),
      ballCount: count,
      quantised,
      kinds: this.kinds,
      tankMin: min ? [min.x(), min.y(), min.z()] : this.info.tankMin,
      tankMax: max ? [max.x(), max.y(), max.z()] : this.info.tankMax,
      players,
      stepsPerS: s.stepsPerS(),
      load: s.load(),
      threadsStepping: s.threadsStepping(),
      timeScale: s.timeScale(),
      timeScaleSet: s.timeScaleSet(),
      maxOverlap: s.maxOverlap(),
      kineticEnergyPerBall: s.kineticEnergyPerBall(),
      paused: s.paused(),
      scene: s.scene() ?? '',
      sceneStart: s.sceneStart(),
    };
    // Other balls under the same ids after a scene start: nothing to blend with the old scene's.
    const last = this.snapshots.newest();
    if (last && last.sceneStart !== f.sceneStart) this.snapshots.clear();
    this.snapshots.push(f);
    this.decodeMs += performance.now() - started;
    ++this.decoded;
    this.lastUpdate = f.received;
    this.snapshotRate.add();
  }

  private sendInput(): void {
    if (this.info?.hasPlayer) this.send(wire.playerInput(++this.inputSequence >>> 0, this.velocity()));
  }

  private everySecond(): void {
    const now = seconds();
    // At least half a second: a window restarted by setVisible just before this tick stays open to the next.
    this.snapshotRate.close(now, 0.5);
    this.byteRate.close(now, 0.5);
    this.send(wire.ping(Math.round(now * 1e6) >>> 0));
  }
}
