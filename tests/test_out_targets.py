"""Bad `--out` targets: an existing file, a path under a file, a folder no file can be made in
(chmod 0o500 for ordinary users; /proc and /sys, where even root cannot create files — this
suite runs as root, which ignores permission bits). `gearcheck build` exits 2 with one line
naming --out, and leaves no file (nor a temporary one) behind.
"""

from __future__ import annotations

import contextlib
import io
import os
from pathlib import Path

import pytest

from gearcheck.cli import main
from gearcheck.output import ensure_out_dir
from gearcheck.params import ParamError

IS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0


def _targets(tmp_path: Path) -> dict[str, tuple[Path, Path]]:
    """name → (--out target, folder that must be left as it was)."""
    existing = tmp_path / "existing.txt"
    existing.write_text("not a folder\n")
    targets = {
        "existing file": (existing, tmp_path),
        "path under a file": (existing / "sub", tmp_path),
    }
    if Path("/proc").is_dir():
        targets["/proc (no file can be made, even by root)"] = (Path("/proc"), Path("/proc"))
        targets["new folder in /proc"] = (Path("/proc/gearcheck-out"), Path("/proc"))
    if not IS_ROOT:
        locked = tmp_path / "locked"
        locked.mkdir()
        locked.chmod(0o500)
        targets["chmod 0o500 folder"] = (locked, locked)
    return targets


def _snapshot(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir()) if folder != Path("/proc") else []


@pytest.fixture
def targets(tmp_path):
    made = _targets(tmp_path)
    yield made
    for target, _ in made.values():
        if target.name == "locked":
            target.chmod(0o700)


def test_ensure_out_dir_rejects_each_bad_target(targets, tmp_path):
    # a folder no file can be made in is among the targets, whoever runs the suite
    assert any("chmod" in name or "/proc" in name for name in targets)
    for name, (target, parent) in targets.items():
        before = _snapshot(parent)
        with pytest.raises(ParamError) as info:
            ensure_out_dir(target)
        text = str(info.value)
        assert info.value.field == "--out" and str(target) in text and "\n" not in text, name
        assert _snapshot(parent) == before, name  # no folder, no probe file left
    assert (tmp_path / "existing.txt").read_text() == "not a folder\n"


def _run(argv):
    err, out = io.StringIO(), io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
        code = main(argv)
    return code, err.getvalue()


@pytest.mark.cad
def test_build_with_bad_out_exits_2_and_leaves_nothing(targets, templates_dir, tmp_path):
    template = templates_dir / "nose_wheel_steering.toml"
    for name, (target, parent) in targets.items():
        before = _snapshot(parent)
        code, err = _run(["build", str(template), "--out", str(target)])
        assert code == 2, name
        last = err.splitlines()[-1]
        assert last.startswith("gearcheck: error: --out = ") and str(target) in last, (name, err)
        assert "Traceback" not in err
        assert _snapshot(parent) == before, name
    assert (tmp_path / "existing.txt").read_text() == "not a folder\n"


@pytest.mark.cad
def test_build_with_bad_out_is_one_line(targets, templates_dir):
    target, _ = targets["existing file"]
    code, err = _run(["build", str(templates_dir / "nose_wheel_steering.toml"), "--out", str(target)])
    assert code == 2
    assert err.count("\n") == 1, err
