"""Run folders under attack: names that look like patterns, symbolic links, an interrupt in the
middle of the swap, names too long for the staging folder beside them. Each test failed on the
code before these rules (noted in its docstring)."""

from __future__ import annotations

import os
import shutil
import signal
from pathlib import Path

import pytest

from conftest import TEMPLATES
from gearcheck import output
from gearcheck.cli import _interrupted, main
from gearcheck.design import load_template
from gearcheck.interrupts import outputs
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


def test_the_interrupt_line_names_what_the_outputs_hold(tmp_path, capsys):
    """One line, whatever the command writes: what was committed, and what keeps what it held."""
    old, new = tmp_path / "old", tmp_path / "new"
    write_run(old, {"a.txt": "1"})
    try:
        outputs.expect([old])
        assert _interrupted(2) == 130
        assert capsys.readouterr().err == (f"gearcheck: interrupted (SIGINT): nothing written, {old} keeps its "
                                           "previous run\n")
        outputs.expect([new])
        _interrupted(15)
        assert capsys.readouterr().err == "gearcheck: interrupted (SIGTERM): nothing written\n"
        outputs.expect([new, old])
        write_run(new, {"a.txt": "2"})
        _interrupted(2)
        assert capsys.readouterr().err == (f"gearcheck: interrupted (SIGINT): {new} was written: it is complete; "
                                           f"nothing else written, {old} keeps its previous run\n")
        write_run(old, {"a.txt": "3"})
        assert outputs.complete() and outputs.after() == f"after {new} and {old} were written: they are complete"
    finally:
        outputs.clear()


def test_outputs_written_by_another_process_are_found_on_the_file_system(tmp_path):
    """``--all --jobs N``: the workers commit their templates' folders; the parent sees them by
    the folder now there (another one than before, complete), not by its own record."""
    a, b = tmp_path / "a", tmp_path / "b"
    write_run(a, {"x": "old"})
    outputs.expect([a, b], "run", RUN_MARKER)
    outputs.elsewhere = True
    try:
        shutil.copytree(a, tmp_path / "copy")
        shutil.rmtree(a)
        os.rename(tmp_path / "copy", a)  # another folder in its place: as a worker's swap leaves it
        (b).mkdir()  # a folder without the run marker is no complete run
        assert outputs.written() == [str(a)] and not outputs.complete()
        (b / RUN_MARKER).write_text("x")
        assert outputs.complete()
    finally:
        outputs.clear()


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


# --------------------------------------------------------------------------------------------
# A signal at the commit of a command's output. The rule: once the output is committed (the
# rename done), the command's result stands — its normal outcome and exit code, and one line
# saying the output is complete; before, nothing of it is written and the line says so (exit
# 130 / 143). Before this rule, a signal just after the commit gave exit 130 / 143 with "nothing
# written" (`new`), or the new run swapped in and the line of an interrupted run (`check`), or
# no line at all and death by the signal while the interpreter exited.


@pytest.fixture
def cli_handlers():
    """The command line's own handlers in force, as in `gearcheck ...` (another test may have put
    others); the previous ones back afterwards."""
    from gearcheck import cli

    previous = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    for s in previous:
        signal.signal(s, cli._on_signal)
    yield
    for s, handler in previous.items():
        signal.signal(s, handler)
    outputs.clear()


def signal_at_commit(monkeypatch, sig: int, when: str, nth: int = 1) -> list[str]:
    """Send ``sig`` to this process at the ``nth`` commit of one of the command's outputs:
    ``after``: just after its rename, inside the stretch that defers signals across it;
    ``returned``: once the commit has returned; ``before``: just before the commit begins.
    Returns the outputs committed (to see when the signal went)."""
    from gearcheck import interrupts

    seen: list[str] = []
    real_committed = interrupts.Outputs.committed

    def committed(self, path):
        real_committed(self, path)
        if self.declares(path):
            seen.append(str(path))
            if when == "after" and len(seen) == nth:
                os.kill(os.getpid(), sig)

    monkeypatch.setattr(interrupts.Outputs, "committed", committed)
    calls: list[int] = []

    def around(real, path_of):
        def commit(*args, **kwargs):
            mine = outputs.declares(path_of(*args))  # not a file inside a staging folder
            if mine:
                calls.append(1)
            if mine and when == "before" and len(calls) == nth:
                os.kill(os.getpid(), sig)
            done = real(*args, **kwargs)
            if mine and when == "returned" and len(calls) == nth:
                os.kill(os.getpid(), sig)
            return done
        return commit

    monkeypatch.setattr(RunFolder, "commit", around(RunFolder.commit, lambda run: run.shown))
    # `new`'s template: one file, renamed into place
    monkeypatch.setattr(output, "replace_atomically", around(output.replace_atomically, lambda path, *_: path))
    return seen


def interrupt_lines(err: str) -> list[str]:
    return [line for line in err.splitlines() if "interrupted" in line]


def complete_run(folder: Path, parent_name: str | None = None) -> None:
    """``folder`` holds one complete run (its manifest verified), nothing beside it."""
    from gearcheck.verify import verify_run

    verify_run(folder)
    assert (folder / RUN_MARKER).is_file()
    name = parent_name or folder.name
    assert sorted(p.name for p in folder.parent.iterdir() if p.name.startswith(f".{name}.")) == [f".{name}.lock"]


SIGS = [(signal.SIGINT, "SIGINT"), (signal.SIGTERM, "SIGTERM")]


@pytest.mark.parametrize("when", ["after", "returned"])
@pytest.mark.parametrize("sig, name", SIGS, ids=["SIGINT", "SIGTERM"])
def test_new_interrupted_once_its_template_is_written_says_so_and_exits_0(tmp_path, capsys, monkeypatch,
                                                                         cli_handlers, sig, name, when):
    """Before: exit 130 / 143 and "nothing written", the template complete on disk."""
    out = tmp_path / "d.toml"
    seen = signal_at_commit(monkeypatch, sig, when)
    code = main(["new", "differential", "--module", "3", "--teeth", "14/30", "--out", str(out)])
    cap = capsys.readouterr()
    assert seen == [str(out)]
    assert code == 0, cap.err
    assert cap.out.startswith(f"wrote {out}: ")
    assert interrupt_lines(cap.err) == [f"gearcheck: interrupted ({name}) after {out} was written: it is complete"]
    assert load_template(out).mechanism == "differential"  # complete, and valid
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.toml", "schema"]  # (the schema it points at)


@pytest.mark.cad
def test_new_assembly_interrupted_once_its_template_is_written_says_so(tmp_path, capsys, monkeypatch,
                                                                      cli_handlers):
    """The issue's own case: `new assembly --step FILE`, SIGINT as the template lands."""
    out = tmp_path / "a.toml"
    signal_at_commit(monkeypatch, signal.SIGINT, "after")
    code = main(["new", "assembly", "--step", str(TEMPLATES / "assembly_spur_pair.step"), "--out", str(out)])
    cap = capsys.readouterr()
    assert code == 0, cap.err
    assert interrupt_lines(cap.err) == [f"gearcheck: interrupted (SIGINT) after {out} was written: it is complete"]
    assert "[[part]]" in out.read_text()


def test_new_interrupted_before_its_template_is_written_keeps_the_previous_file(tmp_path, capsys, monkeypatch,
                                                                               cli_handlers):
    out = tmp_path / "d.toml"
    out.write_text("# mine\n")
    signal_at_commit(monkeypatch, signal.SIGTERM, "before")
    code = main(["new", "differential", "--module", "3", "--teeth", "14/30", "--out", str(out), "--force"])
    cap = capsys.readouterr()
    assert code == 143 and cap.out == ""
    assert interrupt_lines(cap.err) == [f"gearcheck: interrupted (SIGTERM): nothing written, {out} keeps its "
                                        "previous version"]
    assert out.read_text() == "# mine\n" and sorted(p.name for p in tmp_path.iterdir()) == ["d.toml"]


STEERING = TEMPLATES / "nose_wheel_steering.toml"  # the quickest template to build


@pytest.mark.cad
@pytest.mark.parametrize("when", ["after", "returned"])
def test_build_interrupted_once_its_run_is_swapped_in_says_so_and_exits_0(tmp_path, capsys, monkeypatch,
                                                                         cli_handlers, when):
    """Before: exit 130 and "… holds the new run" (the line of an interrupted run)."""
    out = tmp_path / "run"
    write_run(out, {"old.txt": "the previous run"})
    signal_at_commit(monkeypatch, signal.SIGINT, when)
    code = main(["build", str(STEERING), "--out", str(out)])
    cap = capsys.readouterr()
    assert code == 0, cap.err
    assert cap.out.startswith(f"wrote {out}/ ")
    assert interrupt_lines(cap.err) == [f"gearcheck: interrupted (SIGINT) after {out} was written: it is complete"]
    assert not (out / "old.txt").exists()
    complete_run(out)


@pytest.mark.cad
def test_build_interrupted_before_its_run_is_swapped_in_keeps_the_previous_run(tmp_path, capsys, monkeypatch,
                                                                              cli_handlers):
    out = tmp_path / "run"
    write_run(out, {"old.txt": "the previous run"})
    signal_at_commit(monkeypatch, signal.SIGINT, "before")
    code = main(["build", str(STEERING), "--out", str(out)])
    cap = capsys.readouterr()
    assert code == 130 and cap.out == ""
    assert interrupt_lines(cap.err) == [f"gearcheck: interrupted (SIGINT): nothing written, {out} keeps its "
                                        "previous run"]
    assert sorted(p.name for p in out.iterdir()) == [RUN_MARKER, "old.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == [".run.lock", "run"]


def quick_check(monkeypatch, level: str = "pass") -> None:
    """pipeline.check stood in for by a real build (its run folder a real transaction, committed as
    a check's is) and one verdict at ``level``: what is tested is the command line around the
    commit, not the sweep."""
    from gearcheck import pipeline
    from gearcheck.results import CheckResult, Verdict

    def check(design, folder, *, tol_mm=None, progress=pipeline.no_progress, overrides=(), **_kw):
        build = pipeline.build(design, folder, tol_mm=tol_mm, progress=progress, overrides=overrides)
        verdict = Verdict.graded("stand_in", "a stand-in for the sweep's verdicts", level, "measured nothing")
        result = CheckResult(section=design.mechanism, summary={}, verdicts=[verdict], rows=[])
        return pipeline.CheckRun(build, result, build.files, {})

    monkeypatch.setattr(pipeline, "check", check)


@pytest.mark.cad
@pytest.mark.parametrize("level, expected", [("pass", 0), ("fail", 1)])
def test_check_interrupted_once_its_run_is_swapped_in_keeps_the_verdicts_exit_code(tmp_path, capsys, monkeypatch,
                                                                                  cli_handlers, level, expected):
    """Before: the new run in the folder, the previous one gone, exit 130."""
    out = tmp_path / "run"
    write_run(out, {"old.txt": "the previous run"})
    quick_check(monkeypatch, level)
    signal_at_commit(monkeypatch, signal.SIGINT, "after")
    code = main(["check", str(STEERING), "--out", str(out)])
    cap = capsys.readouterr()
    assert code == expected, cap.err
    assert f"{level.upper()} nose_wheel_steering" in cap.out and f"wrote {out}/ " in cap.out
    assert interrupt_lines(cap.err) == [f"gearcheck: interrupted (SIGINT) after {out} was written: it is complete"]
    complete_run(out)


@pytest.mark.cad
def test_check_all_interrupted_between_two_runs_is_one_line(tmp_path, capsys, monkeypatch, cli_handlers):
    """The first template's run is written, the second's not begun: one line says both (N9)."""
    templates = tmp_path / "templates"
    templates.mkdir()
    for name in ("a", "b"):
        shutil.copyfile(STEERING, templates / f"{name}.toml")
    out = tmp_path / "out"
    write_run(out / "b", {"old.txt": "the previous run"})
    quick_check(monkeypatch)
    signal_at_commit(monkeypatch, signal.SIGINT, "after")
    code = main(["check", "--all", "--templates", str(templates), "--jobs", "1", "--out", str(out)])
    cap = capsys.readouterr()
    assert code == 130, cap.err
    assert interrupt_lines(cap.err) == [f"gearcheck: interrupted (SIGINT): {out / 'a'} was written: it is complete; "
                                        f"nothing else written, {out / 'b'} keeps its previous run"]
    complete_run(out / "a")
    assert sorted(p.name for p in (out / "b").iterdir()) == [RUN_MARKER, "old.txt"]


@pytest.mark.cad
def test_check_all_interrupted_at_the_last_commit_stands(tmp_path, capsys, monkeypatch, cli_handlers):
    templates = tmp_path / "templates"
    templates.mkdir()
    for name in ("a", "b"):
        shutil.copyfile(STEERING, templates / f"{name}.toml")
    out = tmp_path / "out"
    quick_check(monkeypatch)
    signal_at_commit(monkeypatch, signal.SIGTERM, "after", nth=2)
    code = main(["check", "--all", "--templates", str(templates), "--jobs", "1", "--out", str(out)])
    cap = capsys.readouterr()
    assert code == 0, cap.err
    assert "PASS a: " in cap.out and "PASS b: " in cap.out
    assert interrupt_lines(cap.err) == [f"gearcheck: interrupted (SIGTERM) after {out / 'a'} and {out / 'b'} were "
                                        "written: they are complete"]
    complete_run(out / "a")
    complete_run(out / "b")


STUDY = """
title = "interrupt at the commit"
template = "{template}"
samples = 16
seed = 11
exact = 0
check_worst = 0
rank_by = "analytical.wear_limit_tip_pct"

[[inputs]]
field = "chain.wear_elongation_pct"
distribution = "uniform"
low = 0.0
high = 3.0
unit = "%"
reason = "service life"

[[failures]]
name = "worn"
label = "wear limit below 1 %"
output = "analytical.wear_limit_tip_pct"
below = 1.0
"""


@pytest.mark.parametrize("when, code", [("after", 0), ("returned", 0), ("before", 130)])
def test_study_interrupted_at_its_commit(tmp_path, capsys, monkeypatch, cli_handlers, when, code):
    """Before: exit 130 whatever the folder held. Now after the swap the study stands (its figures
    printed, exit 0); before it, the previous run stays."""
    path = tmp_path / "s.toml"
    path.write_text(STUDY.format(template=TEMPLATES / "eod_track_drive.toml"))
    out = tmp_path / "study"
    write_run(out, {"old.txt": "the previous run"})
    signal_at_commit(monkeypatch, signal.SIGINT, when)
    got = main(["study", str(path), "--jobs", "1", "--out", str(out)])
    cap = capsys.readouterr()
    assert got == code, cap.err
    if code == 0:
        assert f"wrote {out}/" in cap.out
        assert interrupt_lines(cap.err) == [f"gearcheck: interrupted (SIGINT) after {out} was written: it is complete"]
        complete_run(out)
    else:
        assert cap.out == ""
        assert interrupt_lines(cap.err) == [f"gearcheck: interrupted (SIGINT): nothing written, {out} keeps its "
                                            "previous run"]
        assert sorted(p.name for p in out.iterdir()) == [RUN_MARKER, "old.txt"]
