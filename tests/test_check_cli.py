"""`gearcheck check` end to end on the track drive (the quickest sweep): files, exit codes,
determinism, and reproduction from the run's own params.toml."""

import json

import pytest

from gearcheck.cli import main

pytestmark = pytest.mark.cad


@pytest.fixture(scope="module")
def first_run(tmp_path_factory, templates_dir):
    out = tmp_path_factory.mktemp("check_a")
    code = main(["check", str(templates_dir / "eod_track_drive.toml"), "--out", str(out)])
    return code, out


def test_check_writes_report_files_and_passes(first_run):
    code, out = first_run
    assert code == 0
    for name in ("report.html", "summary.json", "sweep.csv", "manifest.json", "params.toml", "eod_track_drive.step"):
        assert (out / name).is_file(), name
    summary = json.loads((out / "summary.json").read_text())["track"]
    assert summary["verdict_pass"] == 1
    assert 0.5 <= summary["min_tip_plate_distance_mm"]
    confirmation = summary["exact_confirmation"]
    assert confirmation and all(abs(c["mesh_mm"] - c["brep_mm"]) <= c["bound_mm"] for c in confirmation.values())
    assert "<svg" in (out / "report.html").read_text()


def test_rerun_from_its_own_params_is_byte_identical(first_run, tmp_path):
    """The result folder reproduces itself: same summary.json and sweep.csv, byte for byte."""
    _, out = first_run
    assert main(["check", str(out / "params.toml"), "--out", str(tmp_path)]) == 0
    for name in ("summary.json", "sweep.csv"):
        assert (tmp_path / name).read_bytes() == (out / name).read_bytes(), name
    assert (tmp_path / "eod_track_drive.step").is_file()  # the result keeps its name


def test_failing_verdict_exits_1(tmp_path, templates_dir):
    """A tip gap below the paper's 0.5 mm window is valid input but fails the window verdict."""
    code = main(["check", str(templates_dir / "eod_track_drive.toml"), "--set", "track_plate.tip_gap_mm=0.3",
                 "--out", str(tmp_path)])
    assert code == 1
    summary = json.loads((tmp_path / "summary.json").read_text())["track"]
    assert summary["verdict_pass"] == 0
    assert summary["verdicts"]["seated_tip_gap_in_window"] == 0


def test_meshes_too_coarse_for_the_clearance_are_rejected(first_run, tmp_path, templates_dir, capsys):
    """After meshing, a mesh-error bound above 1/10 of the smallest clearance checked (track:
    tooth–sleeve 0.100 mm) is a one-line --tol error, exit 2 — and the folder keeps the previous
    complete run, untouched (the rejected run was never swapped in)."""
    import hashlib
    import shutil

    _, out = first_run
    target = tmp_path / "run"
    shutil.copytree(out, target)
    before = {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in target.iterdir()}
    code = main(["check", str(templates_dir / "eod_track_drive.toml"), "--tol", "0.02", "--out", str(target)])
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "--tol = 0.02: allowed ≤ 0.009999 mm" in err and "tooth–sleeve" in err
    assert {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in target.iterdir()} == before
    assert [p.name for p in tmp_path.iterdir() if ".staging-" in p.name] == []
    # the default run records the rule it met
    summary = json.loads((out / "summary.json").read_text())["track"]["mesh_resolution"]
    assert summary["rule_met"] == 1
    assert summary["largest_part_error_bound_mm"] <= summary["allowed_bound_mm"] == pytest.approx(0.1 * summary["smallest_clearance_mm"])
    assert summary["smallest_clearance_mm"] == pytest.approx(0.1, abs=1e-3)


def test_one_worker_and_every_core_write_the_same_files(first_run, tmp_path, templates_dir):
    """--jobs 1 runs the sweep in this process, the default on every core: byte-identical files."""
    _, out = first_run
    assert main(["check", str(templates_dir / "eod_track_drive.toml"), "--jobs", "1", "--out", str(tmp_path)]) == 0
    for name in ("summary.json", "sweep.csv"):
        assert (tmp_path / name).read_bytes() == (out / name).read_bytes(), name


def test_jobs_must_be_a_whole_number_of_at_least_one(capsys, templates_dir):
    with pytest.raises(SystemExit) as info:
        main(["check", str(templates_dir / "eod_track_drive.toml"), "--jobs", "0"])
    assert info.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--jobs = 0: allowed a whole number ≥ 1" in err
