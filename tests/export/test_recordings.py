"""Recordings made by the real server (--record) open in the analysis tools
people use, read with Debian's python3-ase and python3-mdanalysis: a pour from
t = 0 in ASE, frame by frame at every N-th step, with the count, box and positions the file holds
and the final frame equal to --dump's CSV; a settled tank recorded with
--record-constant-count in MDAnalysis, every frame's positions, velocities and
box. FISHTANK_SERVER names the server executable."""

import os
import re
import subprocess

import numpy as np
import pytest

ase_io = pytest.importorskip("ase.io")
ase_units = pytest.importorskip("ase.units")
mda = pytest.importorskip("MDAnalysis")

TANK_LO = np.array([-20.0, 0.0, -20.0])  # the tank scene's box: x and z in [-20, 20], y in [0, 40]
TANK_SIZE = np.array([40.0, 40.0, 40.0])


def record(tmp_path, *args):
    """Runs the server until its --duration ends; returns the recording, --dump's rows and the log."""
    trajectory, dump = tmp_path / "run.dump", tmp_path / "final.csv"
    done = subprocess.run(
        [os.environ["FISHTANK_SERVER"], "--bind", "127.0.0.1", "--port", "0", "--no-web", "--threads", "1",
         "--record", str(trajectory), "--dump", str(dump), *args],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    final = np.loadtxt(dump, delimiter=",", skiprows=1, ndmin=2)  # x,y,z,vx,vy,vz,diameter,mass by id
    return trajectory, final, done.stderr


def frames_as_written(path):
    """Each frame's step and rows (id type x y z vx vy vz radius) sorted by id, read without any tool."""
    lines = path.read_text().splitlines()
    frames, i = [], 0
    while i < len(lines):
        assert lines[i] == "ITEM: TIMESTEP" and lines[i + 2] == "ITEM: NUMBER OF ATOMS"
        step, count = int(lines[i + 1]), int(lines[i + 3])
        rows = np.array([line.split() for line in lines[i + 9:i + 9 + count]], dtype=np.float64)
        assert rows.shape == (count, 9)
        frames.append((step, rows[np.argsort(rows[:, 0])]))
        i += 9 + count
    return frames


def test_a_pour_recorded_from_t0_opens_in_ase_frame_by_frame_and_ends_at_the_dumped_state(tmp_path):
    balls = 400  # more than one spawn round's worth, so the count grows between frames
    trajectory, final, _ = record(tmp_path, "--balls", str(balls), "--duration", "3", "--record-every", "50")
    written = frames_as_written(trajectory)
    images = ase_io.read(str(trajectory), index=":", format="lammps-dump-text")

    assert len(images) == len(written) >= 20
    counts = [len(atoms) for atoms in images]
    assert counts == [rows.shape[0] for _, rows in written]
    assert counts[0] > 0 and counts[0] < balls  # no empty frame, and the pour seen under way
    assert all(a <= b for a, b in zip(counts, counts[1:]))  # a pour only adds
    steps = [step for step, _ in written]
    assert steps[:-1] == list(range(50, 50 * len(steps), 50))  # every 50th step; the last frame is the final state
    assert counts[-1] == balls == final.shape[0]
    for atoms, (step, rows) in zip(images, written):
        assert np.allclose(atoms.cell.lengths(), TANK_SIZE) and np.allclose(atoms.get_celldisp().ravel(), TANK_LO)
        assert np.array_equal(atoms.positions, rows[:, 2:5]), step  # ASE keeps the file's metres, in id order
        assert np.array_equal(atoms.numbers, rows[:, 1].astype(int))  # type 1, 2, 3: diameter 1, 2, 3

    # The last frame is the state --dump wrote, to the 7 significant digits both files keep.
    last = images[-1]
    assert np.allclose(last.positions, final[:, :3], rtol=5e-7, atol=0.0)
    assert np.array_equal(last.numbers, final[:, 6].astype(int))
    # The manual's recipe for masses and kinetic energy gives --dump's (ASE would take H, He and Li's).
    v = last.get_velocities() * 1000 * ase_units.fs  # first: ASE keeps momenta, which new masses would rescale
    last.set_masses(last.numbers)
    assert np.array_equal(last.get_masses(), final[:, 7])
    assert 0.5 * (last.get_masses()[:, None] * v**2).sum() == pytest.approx(
        0.5 * (final[:, 7:8] * final[:, 3:6]**2).sum(), rel=1e-5)
    assert np.all(last.positions[:, 1] > 0.0) and np.all(last.positions[:, 1] < 40.0)


def test_a_settled_tank_recorded_with_a_constant_count_opens_in_mdanalysis_with_velocities_and_box(tmp_path):
    balls, every, start = 100, 100, 3.5  # e = 0.1: at rest on the floor about 3.2 s after the start
    trajectory, final, log = record(tmp_path, "--balls", str(balls), "--restitution", "0.1", "--duration", "5",
                                    "--record-from", str(start), "--record-constant-count", "--record-every",
                                    str(every))
    dt = float(re.search(r"dt = (\S+) s", log).group(1))  # printed to 3 significant digits
    written = frames_as_written(trajectory)
    universe = mda.Universe(str(trajectory), format="LAMMPSDUMP")

    assert universe.atoms.n_atoms == balls
    assert len(universe.trajectory) == len(written) >= 8
    for ts, (step, rows) in zip(universe.trajectory, written):
        assert ts.data["step"] == step
        assert np.allclose(ts.dimensions, [40.0, 40.0, 40.0, 90.0, 90.0, 90.0])
        # MDAnalysis moves the box's lower corner to the origin, in float32.
        assert np.allclose(ts.positions + TANK_LO, rows[:, 2:5], rtol=0.0, atol=1e-5), step
        assert ts.has_velocities and np.allclose(ts.velocities, rows[:, 5:8], rtol=1e-6, atol=1e-12), step
        assert np.all(ts.positions >= 0.0) and np.all(ts.positions <= TANK_SIZE)
        assert np.abs(ts.velocities).max() < 0.01  # settled: every ball at rest on the floor
    steps = [step for step, _ in written]
    assert steps[0] * dt >= start * (1 - 1e-3)  # nothing before --record-from
    assert all(step % every == 0 for step in steps[:-1])  # the last frame is the final state
    assert all(b - a == every for a, b in zip(steps[:-2], steps[1:-1]))
    assert universe.atoms.types.astype(int).tolist() == final[:, 6].astype(int).tolist()

    # The last frame is the state --dump wrote.
    universe.trajectory[-1]
    assert np.allclose(universe.atoms.positions + TANK_LO, final[:, :3], rtol=0.0, atol=1e-5)
    assert np.allclose(universe.atoms.velocities, final[:, 3:6], rtol=1e-6, atol=1e-12)
