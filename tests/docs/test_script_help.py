"""Every script in scripts/ answers --help at once with how to call it (its own
name in the text) and exit status 0, before it installs, builds or measures
anything: the tools it would reach for first are replaced by ones that leave a
mark, and none may be left. A script whose arguments are only a folder or a
number refuses an option or an argument too many, before the same tools."""

import os
import shutil
import stat
import subprocess

import pytest

from conftest import SOURCE

FIRST_TOOLS = ["apt-get", "sudo", "dpkg-query", "cmake", "ninja", "npm", "gnuplot", "valgrind", "lmp"]


def scripts():
    folder = SOURCE / "scripts"
    return sorted(p.name for p in folder.iterdir() if p.is_file() and os.access(p, os.X_OK))


@pytest.fixture
def marking_path(tmp_path):
    """A PATH whose first tools write their name to tmp_path/used and fail."""
    shims = tmp_path / "shims"
    shims.mkdir()
    for tool in FIRST_TOOLS:
        shim = shims / tool
        shim.write_text(f'#!/bin/sh\necho {tool} >> "{tmp_path}/used"\nexit 1\n')
        shim.chmod(shim.stat().st_mode | stat.S_IXUSR)
    return f"{shims}{os.pathsep}{os.environ['PATH']}", tmp_path / "used"


def test_there_are_scripts_to_check():
    assert {"run", "test", "install-deps", "headline", "figures"} <= set(scripts())


@pytest.mark.parametrize("name", scripts())
def test_a_script_answers_help_with_its_usage_and_does_nothing_else(name, marking_path):
    if name == "figures-web" and shutil.which("node") is None:
        pytest.skip("node is not installed (scripts/install-deps web)")
    path, used = marking_path
    run = subprocess.run([str(SOURCE / "scripts" / name), "--help"], capture_output=True, text=True, timeout=30,
                         env={**os.environ, "PATH": path}, cwd=SOURCE)
    assert run.returncode == 0, run.stderr
    assert name in run.stdout, run.stdout
    assert not used.exists(), f"--help ran {used.read_text().split()}"


@pytest.mark.parametrize("name", ["abuse-table", "figures", "fuzz"])
def test_a_script_that_takes_a_folder_or_a_number_refuses_an_option_or_one_argument_too_many(name, marking_path):
    path, used = marking_path
    for args, said in [(["--bogus"], "unknown option '--bogus'"), (["1", "2"], "at most 1 argument(s), got 2")]:
        run = subprocess.run([str(SOURCE / "scripts" / name), *args], capture_output=True, text=True, timeout=30,
                             env={**os.environ, "PATH": path}, cwd=SOURCE)
        assert run.returncode == 2, run.stderr
        assert said in run.stderr and f"scripts/{name} --help" in run.stderr, run.stderr
        assert not used.exists(), f"{args} ran {used.read_text().split()}"
