"""Bad input is one line naming the field, its value and what is allowed (exit code 2, no
traceback), also where the input is of the wrong type, not a text file, an unknown key inside a
list of tables, or a value so far off that a rule across fields would otherwise blame another
field."""

from __future__ import annotations

import os
import re
import shutil

import pytest

from gearcheck.cli import main
from gearcheck.design import load_template
from gearcheck.params import ParamError
from gearcheck.studies.spec import load_spec

TRACK = "eod_track_drive.toml"


def rejected(path, *overrides: str) -> ParamError:
    """The ParamError for this template and overrides; checks the one-line form."""
    with pytest.raises(ParamError) as info:
        load_template(path, list(overrides))
    text = str(info.value)
    assert "\n" not in text and text.startswith(f"{path}: "), text
    return info.value


def cli_error(capsys, *args: str) -> str:
    """The one line `gearcheck calc ARGS` writes to stderr, exiting 2."""
    code = main(["calc", *args])
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err


@pytest.mark.parametrize("value, shown", [('"abc"', "'abc'"), ("true", "True"), ("[0.01]", "[0.01]")])
def test_mesh_tolerance_of_the_wrong_type_says_it_wants_a_number(templates_dir, value, shown):
    exc = rejected(templates_dir / TRACK, f"mesh_tol_mm={value}")
    assert exc.field == "mesh_tol_mm"
    assert str(exc).endswith(f"mesh_tol_mm = {shown}: wrong type: input should be a number; allowed 0.0005 to 0.5 mm")
    assert "out of range" not in str(exc)


def test_mesh_tolerance_in_the_file(tmp_path, templates_dir, capsys):
    path = tmp_path / "track.toml"
    path.write_text(f'mesh_tol_mm = "abc"\n{(templates_dir / TRACK).read_text()}')
    err = cli_error(capsys, str(path))
    assert "mesh_tol_mm = 'abc': wrong type: input should be a number; allowed 0.0005 to 0.5 mm" in err
    assert "mesh_tol_mm = 0.9: out of range: allowed 0.0005 to 0.5 mm" in str(
        rejected(templates_dir / TRACK, "mesh_tol_mm=0.9"))
    assert "mesh_tol_mm = nan: must be a finite number (allowed 0.0005 to 0.5 mm)" in str(
        rejected(templates_dir / TRACK, "mesh_tol_mm=nan"))


@pytest.mark.skipif(not os.path.exists("/dev/urandom"), reason="no /dev/urandom")
@pytest.mark.parametrize("device", ["/dev/urandom", "/dev/zero", "/dev/null"])
def test_a_device_is_not_a_toml_text_file(capsys, device):
    """A device is refused unread: /dev/urandom and /dev/zero never end, /dev/null is not empty
    file but no file at all."""
    err = cli_error(capsys, device)
    assert f"{device}: not a TOML text file: a character device" in err
    assert "empty file" not in err


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes")
def test_a_named_pipe_is_refused_without_waiting_for_a_writer(tmp_path, capsys):
    fifo = tmp_path / "pipe.toml"
    os.mkfifo(fifo)
    err = cli_error(capsys, str(fifo))
    assert f"{fifo}: not a TOML text file: a named pipe" in err


@pytest.mark.parametrize("content, needle", [
    (bytes(range(128, 256)) * 4, "not a TOML text file: binary data, not UTF-8 text (byte 0)"),
    (b"mechanism = \"track\"\n\x00\x01\x02", "not a TOML text file: binary data (a NUL character at 20)"),
])
def test_binary_files_are_not_toml_text_files(tmp_path, content, needle):
    path = tmp_path / "blob.toml"
    path.write_bytes(content)
    assert needle in str(rejected(path))


def test_unknown_key_in_a_list_of_tables_names_the_allowed_keys(tmp_path, templates_dir):
    studies = templates_dir / "studies"
    shutil.copy(templates_dir / TRACK, tmp_path / TRACK)
    text = (studies / "track_wear.toml").read_text()
    path = tmp_path / "study.toml"
    path.write_text(text.replace("[[inputs]]\n", "[[inputs]]\ncolour = 1\n", 1))
    with pytest.raises(ParamError) as info:
        load_spec(path)
    text = str(info.value)
    assert info.value.field == "inputs.0.colour" and "\n" not in text
    assert "allowed keys here: )" not in text
    allowed = re.search(r"unknown key \(allowed keys here: (.+)\)$", text).group(1).split(", ")
    assert {"field", "distribution", "unit", "reason"} <= set(allowed), text


def test_a_key_where_none_is_allowed():
    from pydantic import ValidationError

    from gearcheck.params.common import Section, _errors

    class Empty(Section):
        pass

    class Model(Section):
        empty: Empty

    with pytest.raises(ValidationError) as info:
        Model.model_validate({"empty": {"x": 1}})
    exc = _errors(Model, info.value, {})
    assert str(exc) == "empty.x = 1: unknown key (no keys are allowed here)"


@pytest.mark.parametrize("pitch", ["5e-324", "1e-300", "0.001"])
def test_a_pitch_too_small_for_any_sleeve_names_the_pitch(templates_dir, capsys, pitch):
    """The sleeve diameter has no allowed value at such a pitch (it was named with 'allowed <
    0.000 mm'): the pitch is named, with the smallest pitch that leaves a tooth for the sleeve."""
    exc = rejected(templates_dir / TRACK, f"chain.pitch_mm={pitch}")
    assert exc.field == "chain.pitch_mm" and exc.value == float(pitch)
    low = float(re.search(r"allowed >([\d.]+) to 500 mm at z = 49, dR = 8 mm", exc.allowed).group(1))
    assert 16 < low < 16.2, exc.allowed
    with pytest.raises(ParamError) as inside:  # just inside the bound this rule holds: the next one speaks
        load_template(templates_dir / TRACK, [f"chain.pitch_mm={low + 0.001:.3f}"])
    assert "must leave a tooth" not in str(inside.value) and inside.value.field != "chain.pitch_mm"
    err = cli_error(capsys, str(templates_dir / TRACK), "--set", f"chain.pitch_mm={pitch}")
    assert "chain.pitch_mm = " in err and "sleeve_diameter_mm" not in err


def test_a_sleeve_too_large_for_the_pitch_is_still_the_sleeve(templates_dir):
    exc = rejected(templates_dir / TRACK, "chain.sleeve_diameter_mm=16")
    assert exc.field == "chain.sleeve_diameter_mm" and "allowed < 14.882 mm" in exc.allowed
