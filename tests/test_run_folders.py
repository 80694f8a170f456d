"""Every output folder holds exactly one complete run: the transaction (staging, verify, swap),
the lock, leftovers of killed runs, write failures, interrupts at every stage, odd names, and
`--all` anywhere. Each fault is reproduced as a user met it, then the new behaviour is checked."""

from __future__ import annotations

import errno
import hashlib
import json
import os
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import ROOT, TEMPLATES, messages
from gearcheck.cli import main
from gearcheck.design import load_template
from gearcheck.output import RUN_MARKER, OutputError, RunFolder
from gearcheck.params import ParamError

TRACK = TEMPLATES / "eod_track_drive.toml"
GEARCHECK = [sys.executable, "-m", "gearcheck"]


def snapshot(folder: Path) -> dict[str, str]:
    """Every file below ``folder`` (hidden ones too) with its sha256."""
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def strays(parent: Path, name: str) -> list[str]:
    """What a run may leave beside its folder: staging folders, swapped-out old runs, temp files."""
    return sorted(p.name for p in parent.iterdir() if p.name.startswith(f".{name}.") and not p.name.endswith(".lock"))


# --------------------------------------------------------------------------------------------
# The transaction on its own (no CAD)


def write_run(folder: Path, files: dict[str, str], fail: bool = False) -> None:
    with RunFolder(folder) as run:
        for name, text in files.items():
            (run.staging / name).write_text(text)
        if fail:
            raise RuntimeError("the run failed half-way")
        run.commit()


def test_a_run_replaces_the_previous_one_whole(tmp_path):
    target = tmp_path / "out" / "run"
    write_run(target, {"a.txt": "1", "b.txt": "1", "c.txt": "1"})
    write_run(target, {"a.txt": "2"})
    assert sorted(p.name for p in target.iterdir()) == [RUN_MARKER, "a.txt"]  # no b/c of the old run
    assert (target / "a.txt").read_text() == "2"
    assert strays(target.parent, "run") == []


def test_a_failed_run_leaves_the_previous_one_untouched(tmp_path):
    target = tmp_path / "run"
    write_run(target, {"a.txt": "1"})
    before = snapshot(target)
    with pytest.raises(RuntimeError):
        write_run(target, {"a.txt": "2", "new.txt": "2"}, fail=True)
    assert snapshot(target) == before
    assert strays(tmp_path, "run") == []
    assert RunFolder.abandoned == str(target)


def test_a_second_run_into_the_same_folder_is_refused(tmp_path):
    target = tmp_path / "run"
    with RunFolder(target):
        with pytest.raises(ParamError) as err:
            with RunFolder(target):
                pass
        assert "another gearcheck run is writing this folder" in str(err.value)
    write_run(target, {"a.txt": "1"})  # free again afterwards


def test_leftovers_of_a_killed_run_are_removed_by_the_next(tmp_path):
    target = tmp_path / "run"
    write_run(target, {"a.txt": "1"})
    (tmp_path / ".run.staging-kil_led9").mkdir()
    (tmp_path / ".run.staging-kil_led9" / "big.stl").write_text("half")
    (tmp_path / ".run.old-99999").mkdir()
    write_run(target, {"a.txt": "2"})
    assert strays(tmp_path, "run") == []


def test_a_swap_cut_between_its_two_renames_is_completed(tmp_path):
    """Killed after moving the old run aside and before moving the new one in: the next run
    puts the old run back first (the folder never stays empty-handed)."""
    target = tmp_path / "run"
    write_run(target, {"a.txt": "old"})
    os.rename(target, tmp_path / ".run.old-12345")
    with RunFolder(target):
        assert (target / "a.txt").read_text() == "old"  # restored before anything else happens


def test_a_folder_that_is_not_a_run_is_never_replaced(tmp_path):
    mine = tmp_path / "my_project"
    mine.mkdir()
    (mine / "notes.txt").write_text("precious")
    with pytest.raises(ParamError, match="not a gearcheck run"):
        write_run(mine, {"a.txt": "1"})
    assert (mine / "notes.txt").read_text() == "precious"


def test_write_failures_are_one_line_naming_the_file_in_the_target(tmp_path, monkeypatch):
    import gearcheck.output as output

    target = tmp_path / "run"
    write_run(target, {"a.txt": "old"})
    before = snapshot(target)

    def full(path):
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr(output, "temp_path_beside", full)
    with pytest.raises(OutputError) as err:
        with RunFolder(target) as run:
            output.atomic_write_text(run.staging / "report.html", "x")
    assert str(err.value) == f"{target}/report.html: cannot write: No space left on device (ENOSPC)"
    assert snapshot(target) == before and strays(tmp_path, "run") == []


# --------------------------------------------------------------------------------------------
# Whole runs (CAD): faults as users met them


@pytest.fixture(scope="module")
def track_run(tmp_path_factory):
    """A complete `check` of the track drive, to be copied and disturbed."""
    out = tmp_path_factory.mktemp("track") / "run"
    assert main(["check", str(TRACK), "--out", str(out)]) == 0
    return out


def copy_run(src: Path, dst: Path) -> Path:
    import shutil

    shutil.copytree(src, dst)
    return dst


pytestmark = pytest.mark.cad


def test_the_manifest_lists_every_file_and_they_match(track_run):
    from gearcheck.verify import verify_run

    manifest = verify_run(track_run)
    files = {p.name for p in track_run.iterdir() if p.name not in ("manifest.json", RUN_MARKER)}
    assert set(manifest["files"]) == files >= {"summary.json", "report.html", "sweep.csv", "params.toml"}


def test_a_file_size_limit_is_exit_2_and_the_old_run_stays(track_run, tmp_path):
    """Before: under `ulimit -f 1200` build exited 0 with a STEP cut short, its hash in the
    manifest. Now: exit 2, one line naming the file, the previous run intact, no temp file."""
    target = copy_run(track_run, tmp_path / "run")
    before = snapshot(target)

    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (1200 * 1024, 1200 * 1024))

    proc = subprocess.run([*GEARCHECK, "build", str(TRACK), "--out", str(target)], cwd=tmp_path,
                          capture_output=True, text=True, preexec_fn=limit)
    assert proc.returncode == 2, proc.stderr
    last = proc.stderr.strip().splitlines()[-1]
    assert last.startswith(f"gearcheck: error: {target}/") and "cannot write" in last, proc.stderr
    assert "Traceback" not in proc.stderr
    assert snapshot(target) == before
    assert strays(tmp_path, "run") == []


def test_a_full_disk_is_exit_2_and_the_old_run_stays(track_run, tmp_path, monkeypatch, capsys):
    import gearcheck.output as output

    target = copy_run(track_run, tmp_path / "run")
    before = snapshot(target)
    calls = {"n": 0}
    real = output.temp_path_beside

    def fills_up(path):
        calls["n"] += 1
        if calls["n"] > 5:  # a few files fit, then the disk is full
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        return real(path)

    monkeypatch.setattr(output, "temp_path_beside", fills_up)
    assert main(["build", str(TRACK), "--out", str(target)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith(f"gearcheck: error: {target}/") and err[-1].endswith("(ENOSPC)")
    assert snapshot(target) == before and strays(tmp_path, "run") == []


def test_build_into_a_checked_folder_leaves_no_report_of_the_old_run(track_run, tmp_path):
    target = copy_run(track_run, tmp_path / "run")
    assert main(["build", str(TRACK), "--out", str(target), "--set", "track_plate.tip_gap_mm=0.8"]) == 0
    names = {p.name for p in target.iterdir()}
    assert not names & {"report.html", "summary.json", "sweep.csv"}
    manifest = json.loads((target / "manifest.json").read_text())
    assert names == set(manifest["files"]) | {"manifest.json", RUN_MARKER}


def test_all_with_one_name_for_every_template_is_refused(capsys):
    assert main(["build", "--all", "--set", "name=x", "--out", "/tmp/never"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--set" in err and "own result name" in err


@pytest.mark.parametrize("stem, field", [("..", "name"), ("my drive", "name")])
def test_odd_template_names_are_refused(tmp_path, capsys, stem, field):
    """Before: `...toml` wrote into out/.. and `my drive.toml` a params.toml that could not be
    re-run. Now: one line naming the name and the rule, exit 2, nothing written."""
    path = tmp_path / f"{stem}.toml"
    path.write_bytes(TRACK.read_bytes())
    assert main(["build", str(path), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert f"{field} = '{stem}'" in err and "file name" in err
    assert not (tmp_path / "o").exists()


def test_an_empty_out_is_refused(capsys):
    assert main(["build", str(TRACK), "--out", ""]) == 2
    assert "--out" in capsys.readouterr().err


def test_all_runs_the_shipped_templates_from_an_empty_folder(tmp_path):
    """Before: `build --all` outside the repository found no templates/ and exited 0 having
    built nothing. Now it builds the templates shipped in the package; a --templates folder
    without templates is exit 2."""
    proc = subprocess.run([*GEARCHECK, "build", "--all", "--out", "o"], cwd=tmp_path, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert sorted(p.name for p in (tmp_path / "o").iterdir() if not p.name.startswith(".")) == [
        "assembly_spur_pair", "eod_track_drive", "nose_wheel_steering", "roller_chain_12B_z21",
        "zhurong_differential"]
    (tmp_path / "empty").mkdir()
    proc = subprocess.run([*GEARCHECK, "check", "--all", "--templates", "empty"], cwd=tmp_path, capture_output=True,
                          text=True)
    assert proc.returncode == 2 and "--templates" in proc.stderr and "none found" in proc.stderr


def test_templates_are_listed_and_copied(tmp_path, capsys):
    assert main(["templates"]) == 0
    out = capsys.readouterr().out
    assert "zhurong_differential.toml" in out and "differential" in out
    assert main(["templates", "--copy", str(tmp_path / "mine")]) == 0
    copied = sorted(p.name for p in (tmp_path / "mine").glob("*.toml"))
    assert copied == ["assembly_spur_pair.toml", "eod_track_drive.toml", "nose_wheel_steering.toml",
                      "roller_chain_12B_z21.toml", "zhurong_differential.toml"]
    assert (tmp_path / "mine" / "assembly_spur_pair.step").is_file()  # the STEP it names, beside it
    assert load_template(tmp_path / "mine" / "assembly_spur_pair.toml").mechanism == "assembly"
    assert sorted(p.name for p in (tmp_path / "mine" / "schema").iterdir()) == [
        "assembly.json", "differential.json", "roller_chain.json", "steering.json", "track.json"]
    (tmp_path / "mine" / "eod_track_drive.toml").write_text("# my edits\n")
    assert main(["templates", "--copy", str(tmp_path / "mine")]) == 2  # never overwrites an edited copy
    assert (tmp_path / "mine" / "eod_track_drive.toml").read_text() == "# my edits\n"


# --------------------------------------------------------------------------------------------
# Reproducible from its own folder


def test_rerun_from_params_toml_with_set_and_tol_is_byte_identical(tmp_path):
    """Before: --tol was not recorded (a --tol 0.0025 run re-run from its params.toml exited 2).
    Now params.toml records every resolved value and the mesh tolerance."""
    first, again = tmp_path / "first", tmp_path / "again"
    assert main(["check", str(TRACK), "--set", "track_plate.tip_gap_mm=0.8", "--tol", "0.006",
                 "--out", str(first)]) == 0
    text = (first / "params.toml").read_text()
    assert "mesh_tol_mm = 0.006" in text and "tip_gap_mm = 0.8" in text
    assert text.startswith("# gearcheck ") and "--set track_plate.tip_gap_mm=0.8" in text.splitlines()[0]
    assert main(["check", str(first / "params.toml"), "--out", str(again)]) == 0
    for name in ("summary.json", "sweep.csv"):
        assert (again / name).read_bytes() == (first / name).read_bytes(), name


def test_params_toml_escapes_every_string(tmp_path):
    """Before: `--set 'materials.housing="7A09\\nAl"'` (accepted) wrote invalid TOML."""
    import tomllib

    out = tmp_path / "run"
    assert main(["build", str(TEMPLATES / "zhurong_differential.toml"), "--set",
                 'materials.housing="7A09\\naluminium"', "--out", str(out)]) == 0
    data = tomllib.loads((out / "params.toml").read_text())
    assert data["materials"]["housing"] == "7A09\naluminium"


# --------------------------------------------------------------------------------------------
# Interrupts


def run_and_signal(args: list[str], cwd: Path, sig: int, at: str | None,
                   settle: float = 0.0) -> tuple[int, str, list[int]]:
    """Start gearcheck (-v: it logs each stage), send ``sig`` when the stage ``at`` begins
    (None: right away, during start-up; ``settle``: once its worker processes have been
    running that long); return the exit code, stderr and the children it had."""
    proc = subprocess.Popen([*GEARCHECK, "-v", *args], cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True)
    lines, children = [], []
    if at is None:
        time.sleep(0.15)
    else:
        for line in proc.stderr:
            lines.append(line)
            if f"stage {at}" in line:
                break
        else:
            pytest.fail(f"stage {at} never began: {''.join(lines)}")
        def kids() -> list[int]:
            return [int(p) for p in subprocess.run(["pgrep", "-P", str(proc.pid)], capture_output=True,
                                                   text=True).stdout.split()]

        children = kids()
        if settle:
            deadline = time.monotonic() + 30
            while len(children) < 2 and time.monotonic() < deadline:
                time.sleep(0.05)
                children = kids()
            time.sleep(settle)
            children = kids()
    proc.send_signal(sig)
    rest = proc.stderr.read()
    code = proc.wait(timeout=120)
    return code, "".join(lines) + rest, children


def alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().split()[2] != "Z"  # a zombie has exited
    except FileNotFoundError:
        return False


@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)], ids=["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("at", [None, "build", "sweep", "confirm"], ids=lambda s: s or "start-up")
def test_interrupt_at_any_stage_leaves_the_folder_unchanged(track_run, tmp_path, sig, code, at):
    """Before: a 24–69-line traceback (exit 1), .part files left, the folder mixed, workers
    printing BrokenPipeError. Now: exit 130/143, one line, the folder as it was, nothing left
    beside it, no worker left running."""
    target = copy_run(track_run, tmp_path / "run")
    before = snapshot(target)
    got, err, children = run_and_signal(["check", str(TRACK), "--out", str(target)], tmp_path, sig, at)
    assert got == code, err
    said = [line for line in messages(err) if "worker(s)" not in line]
    assert len(said) == 1 and said[0].startswith(f"gearcheck: interrupted ({signal.Signals(sig).name})"), err
    assert "Traceback" not in err and "BrokenPipe" not in err
    assert snapshot(target) == before
    assert strays(tmp_path, "run") == []
    deadline = time.monotonic() + 5
    while any(alive(p) for p in children) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not [p for p in children if alive(p)]


def test_steering_rerun_from_params_toml_is_byte_identical(tmp_path):
    first, again = tmp_path / "first", tmp_path / "again"
    assert main(["check", str(TEMPLATES / "nose_wheel_steering.toml"), "--out", str(first)]) == 0
    assert main(["check", str(first / "params.toml"), "--out", str(again)]) == 0
    for name in ("summary.json", "sweep.csv"):
        assert (again / name).read_bytes() == (first / name).read_bytes(), name


def test_a_killed_run_leaves_no_worker_and_the_next_run_cleans_up(track_run, tmp_path):
    """SIGKILL (no chance to clean up) in the middle of the sweep: the workers die with their
    parent, silently (before: ~70 lines of BrokenPipeError); the staging folder left behind is
    removed by the next run into the same folder. (A SIGKILL in the instant a worker is being
    spawned can still leave that worker's one "pickle data was truncated" message: nothing
    can run in a process killed that way.)"""
    target = copy_run(track_run, tmp_path / "run")
    before = snapshot(target)
    code, err, children = run_and_signal(["check", str(TRACK), "--out", str(target)], tmp_path, signal.SIGKILL,
                                         "sweep", settle=0.5)
    assert code == -signal.SIGKILL
    assert children and "BrokenPipe" not in err and "Traceback" not in err
    deadline = time.monotonic() + 5
    while any(alive(p) for p in children) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not [p for p in children if alive(p)]
    assert snapshot(target) == before
    assert [n for n in strays(tmp_path, "run") if ".staging-" in n]  # what the killed run left ...
    assert main(["build", str(TRACK), "--out", str(target)]) == 0
    assert strays(tmp_path, "run") == []  # ... is gone after the next run
