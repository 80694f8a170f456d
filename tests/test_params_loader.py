"""The template loader: every bad file or override is one clear line (ParamError), exit code 2."""

import subprocess
import sys
from pathlib import Path

import pytest

from gearcheck.cli import main
from gearcheck.design import load_template
from gearcheck.mechanism import names as mechanism_names
from gearcheck.params import ParamError
from gearcheck.params.common import parse_override

ROOT = Path(__file__).resolve().parents[1]

TEMPLATE_FILES = {
    "differential": "zhurong_differential.toml",
    "track": "eod_track_drive.toml",
    "steering": "nose_wheel_steering.toml",
    "roller_chain": "roller_chain_12B_z21.toml",
    "assembly": "assembly_spur_pair.toml",
}


def test_every_mechanism_has_its_template(templates_dir):
    for mech, name in TEMPLATE_FILES.items():
        loaded = load_template(templates_dir / name)
        assert loaded.mechanism == mech
    assert set(TEMPLATE_FILES) == set(mechanism_names())


@pytest.mark.parametrize(
    "content, needle",
    [
        (b"", "empty file"),
        (b"mechanism = \"differential\"\n[operating\ncold_C = -65", "not valid TOML"),
        (b"\x00\xff\xfe garbage \x89PNG", "not UTF-8"),
        (b"mechanism = \"gearbox\"\n", "mechanism = 'gearbox'"),
        (b"title = \"no mechanism\"\n", "mechanism = <missing>"),
        (b"mechanism = \"track\"\n[sprocket]\nteeth = nan\n", "finite"),
        (b"mechanism = \"track\"\n[sprocket]\nteeth = inf\n", "finite"),
    ],
)
def test_malformed_files_are_one_line_errors(tmp_path, content, needle):
    path = tmp_path / "bad.toml"
    path.write_bytes(content)
    with pytest.raises(ParamError) as info:
        load_template(path)
    text = str(info.value)
    assert needle in text
    assert str(path) in text
    assert "\n" not in text


def test_missing_file_and_folder(tmp_path):
    with pytest.raises(ParamError, match="file not found"):
        load_template(tmp_path / "nope.toml")
    with pytest.raises(ParamError, match="is a folder"):
        load_template(tmp_path)


@pytest.mark.parametrize(
    "text, path, value",
    [
        ("operating.cold_C=-130", ("operating", "cold_C"), -130),
        ("shim.thickness_mm = 0.15", ("shim", "thickness_mm"), 0.15),
        ("a.b=true", ("a", "b"), True),
        ("a.b=steel", ("a", "b"), "steel"),
        ('a.b="x=y"', ("a", "b"), "x=y"),
    ],
)
def test_parse_override(text, path, value):
    assert parse_override(text) == (path, value)


@pytest.mark.parametrize("text", ["novalue", "=3", "a..b=3"])
def test_bad_override_syntax(text):
    with pytest.raises(ParamError):
        parse_override(text)


@pytest.mark.parametrize("name", TEMPLATE_FILES.values())
def test_unknown_key_and_section_rejected(templates_dir, name):
    with pytest.raises(ParamError, match="unknown key"):
        load_template(templates_dir / name, ["nonsense.key=1"])


@pytest.mark.parametrize("name", TEMPLATE_FILES.values())
def test_every_number_field_rejects_a_string(templates_dir, name):
    """Wrong types are rejected for every numeric field of every template (no silent coercion)."""
    loaded = load_template(templates_dir / name)
    for section, body in loaded.data.items():
        if not isinstance(body, dict):
            continue
        for key, value in body.items():
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                with pytest.raises(ParamError) as info:
                    load_template(templates_dir / name, [f'{section}.{key}="12 mm"'])
                assert f"{section}.{key}" in str(info.value)


def test_cli_bad_input_exit_2_one_line(templates_dir, capsys):
    code = main(["calc", str(templates_dir / "zhurong_differential.toml"), "--set", "operating.cold_C=-200"])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1
    assert "operating.cold_C = -200" in err and "-150" in err
    assert "Traceback" not in err


def test_cli_usage_error_exit_2(capsys):
    with pytest.raises(SystemExit) as info:
        main(["calc"])
    assert info.value.code == 2


def test_math_layer_imports_no_cad_kernel():
    """`gearcheck calc` and the analytical models must run without OpenCASCADE or FCL."""
    code = (
        "import sys, gearcheck.cli\n"
        "import gearcheck\n"
        "for t in ['zhurong_differential', 'eod_track_drive', 'nose_wheel_steering']:\n"
        "    gearcheck.load(f'templates/{t}.toml').calc().to_dict()\n"
        "bad = [m for m in ('cadquery', 'OCP', 'fcl', 'trimesh') if m in sys.modules]\n"
        "assert not bad, bad\n"
    )
    from conftest import ROOT

    subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT)


@pytest.mark.parametrize("name", TEMPLATE_FILES.values())
def test_resolved_parameters_round_trip_through_toml(tmp_path, templates_dir, name):
    """The params.toml written beside results reproduces the same validated parameters."""
    from gearcheck.params.common import to_toml

    loaded = load_template(templates_dir / name)
    copy = tmp_path / name  # another folder: a file the template names is recorded by its absolute path
    copy.write_text(to_toml(loaded.resolved_data))
    again = load_template(copy)
    assert again.params == loaded.params
    assert again.resolved_data == loaded.resolved_data


def test_optional_name_must_be_a_folder_name(tmp_path, templates_dir):
    text = (templates_dir / "eod_track_drive.toml").read_text()
    good = tmp_path / "good.toml"
    good.write_text('name = "drive-A_1"\n' + text)
    assert load_template(good).name == "drive-A_1"
    assert load_template(templates_dir / "eod_track_drive.toml").name == "eod_track_drive"
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "../escape"\n' + text)
    with pytest.raises(ParamError, match="name = '../escape'"):
        load_template(bad)


def test_a_renamed_key_still_loads_with_a_warning(tmp_path, caplog):
    """targets.continuous_angle_deg became targets.continuous_drive_deg (one name per concept):
    an old template loads, with a warning naming the new key; both names at once is an error."""
    import logging

    import gearcheck
    from gearcheck.params.common import ParamError

    text = (ROOT / "templates" / "nose_wheel_steering.toml").read_text()
    old = tmp_path / "old.toml"
    old.write_text(text.replace("continuous_drive_deg", "continuous_angle_deg"))
    with caplog.at_level(logging.WARNING, logger="gearcheck"):
        design = gearcheck.load(old)
    assert design.params.targets.continuous_drive_deg == 60.0
    assert "continuous_angle_deg is now called continuous_drive_deg" in caplog.text
    with pytest.raises(ParamError, match="continuous_angle_deg is the old name of continuous_drive_deg"):
        gearcheck.load(ROOT / "templates" / "nose_wheel_steering.toml",
                       overrides={"targets.continuous_angle_deg": 61.0})
