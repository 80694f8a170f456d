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


def test_the_default_mesh_resolves_the_smallest_clearance_between_two_parts(first_run):
    """Before meshing, the exact 2-D model names the least clearance (tooth–sleeve, 0.100 mm); the
    mesh tolerance follows from it so the PAIR bound (sprocket + link) is ≤ 1/10 of it."""
    _, out = first_run
    summary = json.loads((out / "summary.json").read_text())["track"]["mesh_resolution"]
    assert summary["rule_met"] == 1
    assert summary["smallest_clearance_mm"] == pytest.approx(0.1, abs=1e-3)
    assert summary["allowed_bound_mm"] == pytest.approx(0.1 * summary["smallest_clearance_mm"])
    assert summary["pair_error_bound_mm"] <= summary["allowed_bound_mm"]
    assert summary["pair_error_bound_mm"] >= 2 * summary["largest_part_error_bound_mm"] - 1e-12
    assert summary["tol_mm"] <= summary["smallest_clearance_mm"] / 20
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["chordal_tolerance_mm"] == summary["tol_mm"]
    assert manifest["mesh_tolerance"]["refined"] and not manifest["mesh_tolerance"]["explicit"]
    assert manifest["mesh_tolerance"]["requested_tol_mm"] == 0.008  # the mechanism's default, refined
    summary_all = json.loads((out / "summary.json").read_text())["track"]
    assert summary_all["verdict_levels"]["no_interference"] == "pass"
    assert summary_all["verdict_evidence"]["no_interference"].startswith("mesh sweep")


def test_a_tolerance_too_coarse_for_the_clearance_is_used_and_the_exact_evidence_decides(tmp_path, templates_dir):
    """A user's --tol that cannot resolve the least clearance is not refused (no exit 2): the
    mesh is made as asked, the rule is recorded as not met, and the interference verdict rests on
    the exact model, with the B-rep at the worst poses."""
    code = main(["check", str(templates_dir / "eod_track_drive.toml"), "--tol", "0.02", "--out", str(tmp_path)])
    assert code == 0
    s = json.loads((tmp_path / "summary.json").read_text())["track"]
    rule = s["mesh_resolution"]
    assert rule["rule_met"] == 0 and rule["tol_mm"] == 0.02
    assert json.loads((tmp_path / "manifest.json").read_text())["mesh_tolerance"]["explicit"]
    assert rule["pair_error_bound_mm"] > rule["allowed_bound_mm"]
    assert s["verdict_evidence"]["no_interference"].startswith("exact model")
    assert s["verdict_evidence"]["exact_confirmation"].startswith("exact B-rep: the meshes cannot resolve")
    assert "the verdicts on it rest on the exact model" in (tmp_path / "report.html").read_text()


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


def test_check_all_side_by_side_writes_what_each_check_alone_writes(template_check, tmp_path, capsys):
    """`check --all` on two processes runs the templates side by side (the finest mesh in this
    process, the others in a worker, whose own sweeps then run in it): every run's summary.json and
    sweep.csv are byte for byte those of the template checked alone on two processes, and the
    terminal lists the verdicts in template order."""
    from gearcheck.design import find_templates

    _, paths = find_templates(None)
    assert main(["check", "--all", "--jobs", "2", "--out", str(tmp_path)]) in (0, 1)
    out = capsys.readouterr().out
    names = [p.stem for p in paths]
    assert [out.index(f" {n}: ") for n in names] == sorted(out.index(f" {n}: ") for n in names)
    for name in names:
        alone = template_check(name).folder
        for file in ("summary.json", "sweep.csv"):
            assert (tmp_path / name / file).read_bytes() == (alone / file).read_bytes(), (name, file)
