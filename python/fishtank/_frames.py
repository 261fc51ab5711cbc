"""The wire's frames (protocol/frame_codec.h): a 4-byte little-endian length, then a FlatBuffers Message
table with file identifier "FTNK"; and the decoding of what snapshots carry."""

import flatbuffers
import numpy as np

from fishtank._protocol import PROTOCOL_VERSION
from fishtank.wire import Ack, Hello, Message, Payload

_IDENTIFIER = b"FTNK"
_MAX_FRAME_BYTES = 64 << 20  # the server's cap (kMaxServerFrameBytes)
_QUANT_STEPS = np.float32(65535.0)  # protocol/quantize.h: kQuantSteps


def _vec(v):
    return np.array([v.X(), v.Y(), v.Z()], dtype=np.float32)


def dequantize(q, lo, hi):
    """protocol/quantize.h's dequantize, in float32 step by step: lo + q * ((hi - lo) / 65535)."""
    lo = np.asarray(lo, dtype=np.float32)
    step = (np.asarray(hi, dtype=np.float32) - lo) / _QUANT_STEPS
    return lo + q.astype(np.float32) * step


def _decimal(value):
    """A float32 the server sent as the shortest decimal that is that float: 0.1 as set, not 0.10000000149011612."""
    return float(str(np.float32(value)))


def _text(raw):
    """A server's words as str: bytes that are not UTF-8 (a foreign server's) as \\xNN instead of an exception."""
    return (raw or b"").decode(errors="backslashreplace")


def _frame(payload_type, build):
    b = flatbuffers.Builder(128)
    payload = build(b)
    Message.Start(b)
    Message.AddPayloadType(b, payload_type)
    Message.AddPayload(b, payload)
    b.FinishSizePrefixed(Message.End(b), _IDENTIFIER)
    return bytes(b.Output())


def _table(b, module, **fields):
    module.Start(b)
    for adder, value in fields.items():
        getattr(module, adder)(b, value)
    return module.End(b)


def _hello_frame(name, player=False, acknowledges=True):
    """The Hello a client opens with (also the WebSocket tests' and scripts/figures-web-observers')."""
    def build(b):
        text = b.CreateString(name)
        return _table(b, Hello, AddProtocolVersion=PROTOCOL_VERSION, AddClientName=text,
                      AddWantsPlayer=bool(player), AddAcknowledges=bool(acknowledges))

    return _frame(Payload.Payload.Hello, build)


def _ack_frame(tick, want_keyframe=False):
    return _frame(Payload.Payload.Ack, lambda b: _table(b, Ack, AddTick=tick, AddWantKeyframe=bool(want_keyframe)))
