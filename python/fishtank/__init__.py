"""Python client for fishtank-server: script experiments against a running simulation.

    from fishtank import Client
    with Client("127.0.0.1", 7878) as tank:
        tank.pause()
        state = tank.snapshot()      # numpy arrays: state.positions, state.kinds, state.ids
        tank.step(100)

The wire code (fishtank.wire) is generated from protocol/fishtank.fbs by flatc
at build time; the package is assembled in the build folder (build/python).
"""

from fishtank.client import Client, FishtankError, Snapshot

__all__ = ["Client", "FishtankError", "Snapshot"]
