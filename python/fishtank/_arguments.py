"""Checks of what a script passes to the Client: each wrong value is refused with a ValueError that names
it and its range, before anything reaches the socket."""

import numbers
import threading
from collections.abc import Sequence

import numpy as np

_UINT32_MAX = 2**32 - 1  # AddBalls.count
_MAX_STEPS = 100_000  # protocol/frame_codec.h: kMaxStepsPerRequest, the most one Step runs
_UINT64_MAX = 2**64 - 1  # Reset.seed
_MAX_NAME_BYTES = 64  # protocol/frame_codec.h: kMaxClientNameBytes; the server refuses a longer Hello
_MIN_TIME_SCALE = np.float32(0.1)  # protocol/frame_codec.h: kMinTimeScale .. kMaxTimeScale
_MAX_TIME_SCALE = np.float32(1.0)
_MAX_SECONDS = threading.TIMEOUT_MAX  # the longest wait Python's locks and sockets take


def _whole_number(value, what, lowest, highest):
    """value as an int, or ValueError naming what and its range: the wire's unsigned fields would refuse it
    less clearly (FlatBuffers' TypeError), and a fraction would be cut silently."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not lowest <= value <= highest:
        raise ValueError(f"{what} must be a whole number from {lowest} to {highest}, got {value!r}")
    return int(value)


def _seconds(value, what):
    """value as float seconds, or ValueError naming what: True would pass for one second, and a wait beyond
    _MAX_SECONDS (infinity too) fails in the lock's or socket's words (OverflowError)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not 0 < value <= _MAX_SECONDS:
        raise ValueError(f"{what} must be a positive number of seconds, at most {_MAX_SECONDS:.0f}, got {value!r}")
    return float(value)


def _float32s(values):
    """values as floats, or None where one of them does not fit a float32 (the wire's floats)."""
    try:
        floats = [float(v) for v in values]
    except OverflowError:  # an int beyond any float
        return None
    with np.errstate(over="ignore"):
        return floats if np.all(np.isfinite(np.array(floats, dtype=np.float32))) else None


def _velocity(velocity):
    """velocity as three floats, or ValueError: a string or a mapping would pass as its characters or keys, and
    FlatBuffers would refuse a value beyond float32 as OverflowError."""
    three = velocity.shape == (3,) if isinstance(velocity, np.ndarray) else (
        isinstance(velocity, Sequence) and not isinstance(velocity, (str, bytes, bytearray)) and len(velocity) == 3)
    if not three or not all(isinstance(c, numbers.Real) and not isinstance(c, bool) for c in velocity):
        raise ValueError("velocity must be three numbers (x, y, z) in m/s, as a tuple, list or numpy array, got "
                         f"{velocity!r}")
    floats = _float32s(velocity)
    if floats is None:
        raise ValueError(f"velocity must be finite, within a float32's range (3.4e38), got {velocity!r}")
    return floats


def _time_scale(scale):
    """scale as the float32 the server receives, checked as the server checks it (frame_codec.cpp): a value
    that rounds into the range is taken, 1.0000001 (a float32 above 1) is not."""
    if not isinstance(scale, bool) and isinstance(scale, numbers.Real) and (floats := _float32s([scale])):
        wire = np.float32(floats[0])
        if _MIN_TIME_SCALE <= wire <= _MAX_TIME_SCALE:
            return float(wire)
    raise ValueError("time_scale's scale must be a number from 0.1 to 1 (simulated seconds per wall second), "
                     f"got {scale!r}")


def _client_name(name):
    """name, or ValueError: FlatBuffers would refuse a non-string after the socket is open, and the server a
    longer one, closing the connection."""
    if not isinstance(name, str):
        raise ValueError(f"name must be a string of at most {_MAX_NAME_BYTES} bytes in UTF-8, got {name!r}")
    try:
        size = len(name.encode())
    except UnicodeEncodeError:
        raise ValueError(f"name must be text UTF-8 can encode, got {name!r}") from None
    if size > _MAX_NAME_BYTES:
        raise ValueError(f"name must be at most {_MAX_NAME_BYTES} bytes in UTF-8 (the server's limit), got {size} "
                         f"bytes: {name[:20]!r}...")
    return name
