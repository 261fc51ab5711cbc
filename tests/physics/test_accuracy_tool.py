"""fishtank-accuracy's command line: --help lists its flags (exit 0); a bad flag is named with exit code 2
before any sweep runs: an unknown one, --scalar with --avx2 (each picks the kernels), and an --out that
cannot hold files (checked first, so that minutes of sweeps cannot end in "cannot write"); a missing --out
folder is made."""

import os
import subprocess

TOOL = os.path.join(os.environ["FISHTANK_BUILD_DIR"], "server", "fishtank-accuracy")


def run(*flags, cwd=None):
    return subprocess.run([TOOL, *flags], capture_output=True, text=True, timeout=120, cwd=cwd)


def test_help_lists_every_flag():
    done = run("--help")
    assert done.returncode == 0 and done.stderr == ""
    for flag in ("--out", "--quick", "--scalar", "--avx2", "--collisions-only"):
        assert flag in done.stdout


def test_bad_flags_are_refused_by_name_before_any_sweep(tmp_path):
    afile = tmp_path / "a-file"
    afile.write_text("")
    for flags, said in [(["--bogus"], "unrecognised option '--bogus'"),
                        (["--scalar", "--avx2"], "--scalar and --avx2 each choose the kernels; give one of them"),
                        (["--out", str(afile)], f"--out {afile}: cannot create {afile}")]:
        done = run(*flags, cwd=tmp_path)
        assert done.returncode == 2, (flags, done.stderr)
        lines = done.stderr.splitlines()
        assert lines[0].startswith("fishtank-accuracy: ") and said in lines[0], done.stderr
        assert lines[1] == "Try --help for the list of options."
        assert done.stdout == ""
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a-file"]


def test_a_missing_out_folder_is_made_and_holds_the_csvs(tmp_path):
    out = tmp_path / "new" / "folder"
    done = run("--quick", "--collisions-only", "--out", str(out))
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in out.iterdir()) == ["collisions.csv", "restitutions.csv"]
