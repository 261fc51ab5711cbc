// Delta snapshots, the page's side (protocol/snapshot_delta.h says the format
// and protocol/received_snapshots.h the bookkeeping; this is their twin in
// TypeScript). FlatBuffers decoding is flatc's; this rebuilds the quantised
// positions from a Snapshot's `unchanged` mask and `changes` bit stream.
//
//   Snapshot ─► positions(s) ─ok─► Ack(s.tick)            base kept
//                            └ error (base unknown, corrupt) ─► Ack(want_keyframe)

import type { Snapshot } from 'fishtank-wire';

// Snapshots sent to this page that the server may code against, at most (kKeptBases in received_snapshots.h).
const KEPT_BASES = 32;
// Below this a move from prior to base is jitter, not velocity (kMovingQuanta).
const MOVING_QUANTA = 4;
// A zigzagged difference of two 16-bit values has at most 17 leading zeros in its code.
const MAX_LEADING_ZEROS = 17;
const ORDER_BITS = 3;

// Least-significant-bit first, like the server's BitWriter.
class BitReader {
  private pos = 0;
  private readonly bits: number;

  constructor(private readonly data: Uint8Array) {
    this.bits = 8 * data.length;
  }

  // The next n (<= 32, all within the stream) bits without moving past them.
  // Plain arithmetic, not 32-bit operators: up to 5 bytes are combined.
  private peek(n: number): number {
    const first = this.pos >>> 3;
    const last = (this.pos + n + 7) >>> 3;
    let word = 0;
    for (let b = last - 1; b >= first; --b) word = word * 256 + this.data[b];
    return Math.floor(word / 2 ** (this.pos & 7)) % 2 ** n;
  }

  get(n: number): number | null {
    if (this.pos + n > this.bits) return null;
    const v = this.peek(n);
    this.pos += n;
    return v;
  }

  // Order 0: n zeros, a one, then the n bits of v + 1 below its leading one.
  private golomb0(): number | null {
    const window = this.peek(Math.min(MAX_LEADING_ZEROS + 1, this.bits - this.pos));
    if (window === 0) return null;  // more zeros than any code has, or the stream ends among them
    const n = 31 - Math.clz32(window & -window);
    this.pos += n + 1;
    const low = this.get(n);
    return low === null ? null : 2 ** n + low - 1;
  }

  golomb(k: number): number | null {
    const high = this.golomb0();
    if (high === null) return null;
    if (k === 0) return high;
    const low = this.get(k);
    return low === null ? null : high * 2 ** k + low;
  }

  onlyPaddingLeft(): boolean {
    const left = this.bits - this.pos;
    return left < 8 && this.get(left) === 0;
  }
}

export interface Kept {
  tick: number;
  positions: Uint16Array;  // 3 per ball
}

// Where ball i is expected in snapshot `tick`: its base position, carried on at
// its velocity from prior to base when that was more than jitter. Integer
// arithmetic truncating towards zero, as the server predicts.
function predict(base: Kept, prior: Kept | null, tick: number, i: number, out: Int32Array): void {
  const b = base.positions;
  for (let axis = 0; axis < 3; ++axis) out[axis] = b[3 * i + axis];
  if (!prior || 3 * i >= prior.positions.length) return;
  const ahead = tick - base.tick;
  const behind = base.tick - prior.tick;
  if (ahead <= 0 || behind <= 0) return;
  const a = prior.positions;
  let moving = false;
  for (let axis = 0; axis < 3; ++axis) {
    const moved = b[3 * i + axis] - a[3 * i + axis];
    moving = moving || moved >= MOVING_QUANTA || moved <= -MOVING_QUANTA;
  }
  if (!moving) return;
  for (let axis = 0; axis < 3; ++axis) {
    const moved = b[3 * i + axis] - a[3 * i + axis];
    out[axis] = Math.min(65535, Math.max(0, b[3 * i + axis] + Math.trunc((moved * ahead) / behind)));
  }
}

// Rebuilds 3 * count values of snapshot `tick`; returns them or why it cannot.
export function decodePositionsDelta(base: Kept, prior: Kept | null, tick: number, unchanged: Uint8Array,
                                     changes: Uint8Array, count: number): Uint16Array | string {
  const baseCount = base.positions.length / 3;
  const common = Math.min(baseCount, count);
  if (unchanged.length !== Math.ceil(common / 8))
    return `the unchanged mask has ${unchanged.length} bytes, ${Math.ceil(common / 8)} expected`;
  const out = new Uint16Array(3 * count);
  const reader = new BitReader(changes);
  const order = reader.get(ORDER_BITS);
  if (order === null) return 'the changes stream is empty';
  const expected = new Int32Array(3);
  for (let i = 0; i < common; ++i) {
    if ((unchanged[i >>> 3] >>> (i & 7)) & 1) {
      out.set(base.positions.subarray(3 * i, 3 * i + 3), 3 * i);
      continue;
    }
    predict(base, prior, tick, i, expected);
    for (let axis = 0; axis < 3; ++axis) {
      const z = reader.golomb(order);
      if (z === null) return `the changes stream ends inside ball ${i}`;
      const value = expected[axis] + ((z >>> 1) ^ -(z & 1));
      if (value < 0 || value > 65535) return `ball ${i} moves outside the quantisation range`;
      out[3 * i + axis] = value;
    }
  }
  for (let v = 3 * common; v < 3 * count; ++v) {
    const raw = reader.get(16);
    if (raw === null) return 'the changes stream ends inside the new balls';
    out[v] = raw;
  }
  if (!reader.onlyPaddingLeft()) return 'the changes stream has bytes after its last ball';
  return out;
}

// The newest few snapshots' positions, as bases for the deltas that follow.
export class ReceivedSnapshots {
  private kept: Kept[] = [];  // oldest first

  clear(): void {
    this.kept = [];
  }

  // The quantised positions of s (full or delta), kept as a base; or why not.
  positions(s: Snapshot): Uint16Array | string {
    const count = s.ballCount();
    const unchanged = s.unchangedArray();
    let out: Uint16Array | string;
    if (!unchanged) {
      const full = s.positionsArray();
      if (!full || full.length !== 3 * count) return `snapshot ${s.tick()} has no positions for its ${count} balls`;
      out = full.slice();  // a copy: the message's buffer is not kept
    } else {
      const base = this.find(s.baseTick());
      const prior = s.predicted() ? this.find(s.priorTick()) : null;
      const what = `delta snapshot ${s.tick()}`;
      if (!base || (s.predicted() && !prior))
        return `${what} is coded against snapshots ${s.baseTick()}${s.predicted() ? ` and ${s.priorTick()}` : ''}, ` +
               'which this page does not hold';
      if (!(s.tick() > base.tick && (!prior || base.tick > prior.tick)))
        return `${what} is not newer than its base, or its base not newer than its prior`;
      if (base.positions.length / 3 !== s.baseBallCount())
        return `${what} says its base has ${s.baseBallCount()} balls; it has ${base.positions.length / 3}`;
      out = decodePositionsDelta(base, prior, s.tick(), unchanged, s.changesArray() ?? new Uint8Array(0), count);
      if (typeof out === 'string') return `${what}: ${out}`;
    }
    this.kept.push({ tick: s.tick(), positions: out });
    if (this.kept.length > KEPT_BASES) this.kept.shift();
    return out;
  }

  private find(tick: number): Kept | null {
    return this.kept.find((k) => k.tick === tick) ?? null;
  }
}
