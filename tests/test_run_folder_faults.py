"""Run folders under attack: names that look like patterns, symbolic links, an interrupt in the
middle of the swap, names too long for the staging folder beside them. Each test failed on the
code before these rules (noted in its docstring)."""

from __future__ import annotations

import os
import shutil
import signal
from pathlib import Path

import pytest

from gearcheck import output
from gearcheck.cli import _interrupted, main
from gearcheck.output import RUN_MARKER, RunFolder
from gearcheck.params import ParamError


def write_run(folder: Path, files: dict[str, str]) -> None:
    with RunFolder(folder) as run:
        for name, text in files.items():
            (run.staging / name).write_text(text)
        run.commit()


def test_a_target_named_like_a_pattern_removes_no_other_runs_staging(tmp_path):
    """Before: a run into ``D/t*`` globbed ``.t*.staging-*`` and deleted the staging folder of a
    concurrent run into ``D/track`` (which then failed)."""
    other = tmp_path / ".track.staging-abcd1234"
    other.mkdir()
    (other / "part.stl").write_text("being written")
    also = tmp_path / ".t.old-123"  # another run's old folder, and a user's hidden folder
    also.mkdir()
    mine = tmp_path / ".t*.staging-left_ov1"  # what a killed run into "t*" left: removed
    mine.mkdir()
    write_run(tmp_path / "t*", {"a.txt": "1"})
    assert (other / "part.stl").read_text() == "being written"
    assert also.is_dir()
    assert not mine.exists()


def test_a_staging_name_of_another_shape_is_not_taken_for_a_leftover(tmp_path):
    """Only ``.NAME.staging-`` and mkdtemp's eight characters are this run's: a run into
    ``track`` leaves ``.track.staging-x.staging-abcd1234`` (the staging folder of a run into
    ``track.staging-x``) alone."""
    other = tmp_path / ".track.staging-x.staging-abcd1234"
    other.mkdir()
    write_run(tmp_path / "track", {"a.txt": "1"})
    assert other.is_dir()


def test_an_out_that_is_a_symlink_is_followed_and_stays_a_link(tmp_path):
    """Before: the link was turned into a folder and the link itself left as
    ``.LINK.staging-*`` for good."""
    real = tmp_path / "runs" / "today"
    write_run(real, {"a.txt": "old"})
    link = tmp_path / "latest"
    link.symlink_to(real)
    write_run(link, {"a.txt": "new"})
    assert link.is_symlink() and link.resolve() == real.resolve()
    assert (real / "a.txt").read_text() == "new"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["latest", "runs"]  # nothing beside the link
    assert sorted(p.name for p in real.parent.iterdir()) == [".today.lock", "today"]


def test_a_dangling_symlink_out_creates_the_folder_it_points_to(tmp_path):
    link = tmp_path / "latest"
    link.symlink_to(tmp_path / "new")
    write_run(link, {"a.txt": "1"})
    assert link.is_symlink() and (tmp_path / "new" / "a.txt").read_text() == "1"


def test_an_interrupt_while_the_old_run_is_removed_leaves_the_new_run_and_says_so(tmp_path, monkeypatch):
    """Before: the message said "nothing written" while the folder held the new run, and the
    half-deleted old run stayed beside it as ``.NAME.staging-*``."""
    target = tmp_path / "run"
    write_run(target, {"a.txt": "old", "b.txt": "old"})
    real_rmtree = shutil.rmtree
    calls = []

    def interrupted_rmtree(path, *args, **kwargs):
        calls.append(Path(path).name)
        if len(calls) == 1:  # the old run: half removed, then the interrupt
            os.unlink(Path(path) / "a.txt")
            raise KeyboardInterrupt
        return real_rmtree(path, *args, **kwargs)

    monkeypatch.setattr(output.shutil, "rmtree", interrupted_rmtree)
    with pytest.raises(KeyboardInterrupt):
        write_run(target, {"a.txt": "new"})
    assert calls[0].startswith(".run.old-")  # the old run was named as what it is before removal
    assert (target / "a.txt").read_text() == "new" and (target / RUN_MARKER).is_file()
    assert sorted(p.name for p in tmp_path.iterdir()) == [".run.lock", "run"]
    assert RunFolder.written == str(target) and RunFolder.abandoned is None


def test_the_interrupt_line_names_what_the_folder_holds(capsys):
    RunFolder.written, RunFolder.abandoned = "out/x", None
    assert _interrupted(2) == 130
    assert "out/x holds the new run" in capsys.readouterr().err
    RunFolder.written, RunFolder.abandoned = None, "out/y"
    _interrupted(15)
    assert "out/y unchanged" in capsys.readouterr().err
    RunFolder.written = RunFolder.abandoned = None


def test_a_signal_during_the_swap_takes_effect_after_it(tmp_path, monkeypatch, request):
    """An interrupt between the exchange and the bookkeeping would leave a run swapped in but
    not known to be: the swap defers SIGINT/SIGTERM to its end."""
    target = tmp_path / "run"
    write_run(target, {"a.txt": "old"})
    real_rename = os.rename
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)  # not the CLI's (imported above)
    request.addfinalizer(lambda: signal.signal(signal.SIGINT, previous))

    def rename_then_signal(a, b):
        real_rename(a, b)
        signal.raise_signal(signal.SIGINT)  # arrives inside the swap

    monkeypatch.setattr(output.os, "rename", rename_then_signal)
    with pytest.raises(KeyboardInterrupt):
        write_run(target, {"a.txt": "new"})
    assert (target / "a.txt").read_text() == "new"
    assert RunFolder.written == str(target)
    assert sorted(p.name for p in tmp_path.iterdir()) == [".run.lock", "run"]


def test_a_name_too_long_for_its_staging_folder_is_one_line_naming_out(tmp_path, capsys):
    """Before: a 240-byte folder name failed on the staging folder beside it, naming that
    hidden path (``.NAME.staging-…: File name too long``)."""
    long = tmp_path / ("r" * 240)
    code = main(["build", "templates/eod_track_drive.toml", "--out", str(long)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1, err
    assert err.startswith("gearcheck: error: --out = ") and "at most 237 bytes" in err and ".staging-" not in err
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(ParamError):
        RunFolder(tmp_path / ("é" * 119))  # 238 bytes


def test_templates_copy_into_a_file_names_copy(tmp_path, capsys):
    """Before: ``templates --copy FILE`` blamed ``--out``."""
    file = tmp_path / "f"
    file.write_text("x")
    assert main(["templates", "--copy", str(file)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("gearcheck: error: --copy = ") and "--out" not in err
