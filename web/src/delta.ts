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

// Least-significant-bit first, like the server's BitWriter. 32-bit integer
// operators throughout: float arithmetic per bit made decoding a moving tank of
// 100 000 balls take longer than a frame.
class BitReader {
  private pos = 0;
  private readonly bits: number;

  constructor(private readonly data: Uint8Array) {
    this.bits = 8 * data.length;
  }

  // The 32 bits from bit `at`, zeros past the stream's end (a Uint8Array reads undefined there, which | makes 0).
  private peek(at: number): number {
    const d = this.data;
    const first = at >>> 3;
    const shift = at & 7;
    const low = (d[first] | (d[first + 1] << 8) | (d[first + 2] << 16) | (d[first + 3] << 24)) >>> shift;
    return shift === 0 ? low >>> 0 : (low | (d[first + 4] << (32 - shift))) >>> 0;
  }

  // n < 32 bits, or null when the stream ends first.
  get(n: number): number | null {
    if (this.pos + n > this.bits) return null;
    const v = this.peek(this.pos) & ((1 << n) - 1);
    this.pos += n;
    return v;
  }

  // Order k: n zeros, a one, the n bits of (v >> k) + 1 below its leading one, then the k low bits of v.
  golomb(k: number): number | null {
    const window = this.peek(this.pos);
    const zeros = window & ((1 << (MAX_LEADING_ZEROS + 1)) - 1);
    if (zeros === 0) return null;  // more zeros than any code has, or the stream ends among them
    const n = 31 - Math.clz32(zeros & -zeros);
    const length = 2 * n + 1 + k;
    if (this.pos + length > this.bits) return null;
    const rest = length <= 32 ? window >>> (n + 1) : this.peek(this.pos + n + 1);
    this.pos += length;
    const low = rest & ((1 << n) - 1);
    const lowK = (rest >>> n) & ((1 << k) - 1);
    return ((((1 << n) | low) - 1) << k) | lowK;
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

// Rebuilds 3 * count values of snapshot `tick`; returns them or why it cannot.
// A ball is expected at its base position, carried on at its velocity from
// prior to base when that was more than jitter; integer arithmetic truncating
// towards zero, as the server predicts.
export function decodePositionsDelta(base: Kept, prior: Kept | null, tick: number, unchanged: Uint8Array,
                                     changes: Uint8Array, count: number): Uint16Array | string {
  const b = base.positions;
  const common = Math.min(b.length / 3, count);
  if (unchanged.length !== Math.ceil(common / 8))
    return `the unchanged mask has ${unchanged.length} bytes, ${Math.ceil(common / 8)} expected`;
  const out = new Uint16Array(3 * count);
  const reader = new BitReader(changes);
  const order = reader.get(ORDER_BITS);
  if (order === null) return 'the changes stream is empty';
  const ahead = tick - base.tick;
  const behind = prior ? base.tick - prior.tick : 0;
  const a = prior && ahead > 0 && behind > 0 ? prior.positions : null;
  const carried = a ? Math.min(common, a.length / 3) : 0;  // balls whose prior is known
  const expected = new Int32Array(3);
  for (let i = 0; i < common; ++i) {
    const v = 3 * i;
    if ((unchanged[i >>> 3] >>> (i & 7)) & 1) {
      out[v] = b[v];
      out[v + 1] = b[v + 1];
      out[v + 2] = b[v + 2];
      continue;
    }
    expected[0] = b[v];
    expected[1] = b[v + 1];
    expected[2] = b[v + 2];
    if (i < carried) {
      const mx = b[v] - a![v], my = b[v + 1] - a![v + 1], mz = b[v + 2] - a![v + 2];
      if (Math.max(Math.abs(mx), Math.abs(my), Math.abs(mz)) >= MOVING_QUANTA) {
        expected[0] = Math.min(65535, Math.max(0, b[v] + Math.trunc((mx * ahead) / behind)));
        expected[1] = Math.min(65535, Math.max(0, b[v + 1] + Math.trunc((my * ahead) / behind)));
        expected[2] = Math.min(65535, Math.max(0, b[v + 2] + Math.trunc((mz * ahead) / behind)));
      }
    }
    for (let axis = 0; axis < 3; ++axis) {
      const z = reader.golomb(order);
      if (z === null) return `the changes stream ends inside ball ${i}`;
      const value = expected[axis] + ((z >>> 1) ^ -(z & 1));
      if (value < 0 || value > 65535) return `ball ${i} moves outside the quantisation range`;
      out[v + axis] = value;
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
