// The page's messages to the server, built with flatc's generated code. Over
// the WebSocket each binary message is one Message buffer with file
// identifier "FTNK", without the TCP stream's 4-byte length prefix.

import { Builder, ByteBuffer } from 'flatbuffers';
import {
  Ack, AddBalls, Hello, Message, Pause, Payload, Ping, PlayerInput, Reset, SetTimeScale, Step, Vec3f, Watching,
} from 'fishtank-wire';

// Set by esbuild from protocol/frame_codec.h's kProtocolVersion (web/CMakeLists.txt).
declare const FISHTANK_PROTOCOL_VERSION: number;
const PROTOCOL_VERSION = FISHTANK_PROTOCOL_VERSION;
const IDENTIFIER = 'FTNK';

function frame(type: Payload, build: (b: Builder) => number): Uint8Array {
  const b = new Builder(64);
  const payload = build(b);
  b.finish(Message.createMessage(b, type, payload), IDENTIFIER);
  return b.asUint8Array();
}

// The page acknowledges every snapshot it decodes, so the server may pace it from the first.
export const hello = (name: string, wantsPlayer: boolean): Uint8Array =>
  frame(Payload.Hello, (b) => Hello.createHello(b, PROTOCOL_VERSION, b.createString(name), wantsPlayer, true));

export const ack = (tick: number, wantKeyframe = false): Uint8Array =>
  frame(Payload.Ack, (b) => Ack.createAck(b, tick, wantKeyframe));

// Off: no snapshots until on again.
export const watching = (on: boolean): Uint8Array =>
  frame(Payload.Watching, (b) => Watching.createWatching(b, on));

export const playerInput = (sequence: number, v: readonly number[]): Uint8Array =>
  frame(Payload.PlayerInput, (b) => {
    PlayerInput.startPlayerInput(b);
    PlayerInput.addSequence(b, sequence);
    PlayerInput.addVelocity(b, Vec3f.createVec3f(b, v[0], v[1], v[2]));
    return PlayerInput.endPlayerInput(b);
  });

export const addBalls = (count: number): Uint8Array =>
  frame(Payload.AddBalls, (b) => AddBalls.createAddBalls(b, count));

export const ping = (clientTimeUs: number): Uint8Array =>
  frame(Payload.Ping, (b) => Ping.createPing(b, clientTimeUs >>> 0));

export const pause = (paused: boolean): Uint8Array => frame(Payload.Pause, (b) => Pause.createPause(b, paused));

export const step = (count: number): Uint8Array => frame(Payload.Step, (b) => Step.createStep(b, count));

// An empty scene restarts the scene running, with its last seed.
export const reset = (scene: string): Uint8Array =>
  frame(Payload.Reset, (b) => {
    const name = scene ? b.createString(scene) : 0;
    Reset.startReset(b);
    if (name) Reset.addScene(b, name);
    return Reset.endReset(b);
  });

export const setTimeScale = (scale: number): Uint8Array =>
  frame(Payload.SetTimeScale, (b) => SetTimeScale.createSetTimeScale(b, scale));

// The Message in one binary WebSocket message, or null when it is not a Fishtank buffer.
export function readMessage(data: ArrayBuffer): Message | null {
  const bb = new ByteBuffer(new Uint8Array(data));
  if (data.byteLength < 8 || !bb.__has_identifier(IDENTIFIER)) return null;
  return Message.getRootAsMessage(bb);
}
