#!/usr/bin/env python3
"""Measure the height of the pile while balls pour into the tank, and plot it.

    PYTHONPATH=build/python python3 docs/examples/pile_height.py --port 7878 --out pile_height.png

The tank scene is started again (everyone connected sees it) and resumed if
another client left it paused, balls pour in from the top, and four times a
second the pile's height is measured: the height below which the tops of 99 %
of the balls at rest lie (a ball at rest moved less than 2 cm in a tenth of a
second), so balls still falling, and the odd one at the top of its bounce, do
not count. A ball's radius comes from its kind (Client.kinds). The plot shows
the height and the balls in the tank against simulated time since the restart.
"""

import argparse
import math
import os
import sys
import time

import matplotlib

matplotlib.use("Agg")  # write a file; no display needed
import matplotlib.pyplot as plt
import numpy as np

from fishtank import Client, FishtankError

REST_DISTANCE = 0.02  # metres in REST_WINDOW: below it a ball counts as resting
REST_WINDOW = 0.1  # seconds of wall time between the two snapshots compared


def pile_height(tank, radii):
    """The pile's height (metres above the floor), the balls in the tank, and the simulated time."""
    a = tank.snapshot()
    time.sleep(REST_WINDOW)
    b = tank.snapshot()
    n = min(len(a.ids), len(b.ids))
    if n == 0 or a.scene_start != b.scene_start:
        return 0.0, len(b.ids), b.sim_time
    moved = np.linalg.norm(b.positions[:n] - a.positions[:n], axis=1)
    resting = moved < REST_DISTANCE
    tops = b.positions[:n, 1] + radii[b.kinds[:n]] - b.tank_min[1]
    return float(np.percentile(tops[resting], 99)) if resting.any() else 0.0, len(b.ids), b.sim_time


def whole_number(lowest, highest):
    def parse(text):
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or not lowest <= value <= highest:
            raise argparse.ArgumentTypeError(f"a whole number from {lowest} to {highest}, got {text!r}")
        return value
    return parse


def positive_seconds(text):
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"a positive number of seconds, got {text!r}")
    return value


def check_out(parser, out):
    """Refuses a plot that could not be written, before the measuring time rather than after it."""
    folder = os.path.dirname(os.path.abspath(out))
    if os.path.isdir(out):
        example = os.path.join(out, "pile_height.png")
        parser.error(f"argument --out: {out} is a folder; give a file in it, e.g. {example}")
    if not os.path.isdir(folder):
        parser.error(f"argument --out: the folder {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        parser.error(f"argument --out: the folder {folder} is not writable")
    suffix = os.path.splitext(out)[1].lstrip(".").lower()
    formats = plt.figure().canvas.get_supported_filetypes()
    plt.close("all")
    if suffix and suffix not in formats:
        parser.error(f"argument --out: matplotlib cannot write .{suffix} files; use one of "
                     + ", ".join(f".{f}" for f in sorted(formats)))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--host", default="127.0.0.1")
    parser.add_argument("--port", type=whole_number(1, 65535), default=7878)
    parser.add_argument("--seconds", type=positive_seconds, default=20.0, help="wall seconds to measure for")
    parser.add_argument("--seed", type=whole_number(0, 2**64 - 1), default=1, help="seed of the tank scene's restart")
    parser.add_argument("--add", type=whole_number(0, 2**32 - 1), default=0,
                        help="balls to pour in besides the scene's own")
    parser.add_argument("--out", default="pile_height.png", help="the plot (PNG)")
    args = parser.parse_args()
    check_out(parser, args.out)

    with Client(args.host, args.port) as tank:
        radii = np.array([diameter / 2 for diameter, _ in tank.kinds], dtype=np.float32)
        start = tank.scene("tank", seed=args.seed)
        if start.paused:  # left so by another client: no ball would pour in, and the pile would stay at 0 m
            print("pile_height.py: the simulation was paused; resuming it to measure", file=sys.stderr)
            tank.resume()
        if args.add:
            tank.add_balls(args.add)
        times, heights, counts = [], [], []
        end = time.monotonic() + args.seconds
        while not times or time.monotonic() < end:  # one measurement at least, for the plot and the summary
            height, balls, sim_time = pile_height(tank, radii)
            times.append(sim_time - start.sim_time)
            heights.append(height)
            counts.append(balls)
            time.sleep(max(0.0, 0.25 - REST_WINDOW))

    fig, left = plt.subplots(figsize=(7, 4))
    left.plot(times, heights, color="tab:blue")
    left.set_xlabel("simulated time since the restart (s)")
    left.set_ylabel("pile height (m)", color="tab:blue")
    right = left.twinx()
    right.plot(times, counts, color="tab:gray", linestyle="--")
    right.set_ylabel("balls in the tank", color="tab:gray")
    left.set_title("Balls pouring into the tank")
    fig.tight_layout()
    fig.savefig(args.out, dpi=100)
    print(f"{len(times)} measurements; final pile height {heights[-1]:.2f} m with {counts[-1]} balls; plot in {args.out}")


if __name__ == "__main__":
    try:
        main()
    except FishtankError as e:  # the server's or the connection's reason says what to do: no traceback
        sys.exit(f"pile_height.py: {e}")
