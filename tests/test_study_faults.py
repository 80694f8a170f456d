"""`gearcheck study` on bad input and under stress: whole-number inputs reach the template as
ints, a study whose every variant is rejected is an error, the flags are held to the study
file's own limits, outputs are checked before any variant is drawn, free text is printable,
messages say what is allowed, a Dask run is quiet (no logs without -v, no dashboard) and ends
in one line when terminated, an absent scheduler is named, and a study's folder holds only its
run's files."""

import os
import re
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path

import numpy as np
import pytest

import gearcheck
from gearcheck.params import ParamError
from gearcheck.studies import core, spec

ROOT = Path(__file__).resolve().parents[1]
TEMPLATE = ROOT / "templates" / "eod_track_drive.toml"

STUDY = """
title = "{title}"
template = "{template}"
samples = {samples}
seed = 11
exact = 0
check_worst = 0
rank_by = "{rank_by}"

[[inputs]]
field = "chain.wear_elongation_pct"
distribution = "uniform"
low = 0.0
high = 3.0
unit = "%"
reason = "service life"

[[inputs]]
field = "sprocket.seating_radius_mm"
distribution = "{dist}"
{shape}
unit = "mm"
reason = "grinding tolerance of the groove radius"

[[failures]]
name = "seat_large"
label = "seating radius above 4.15 mm"
output = "{output}"
above = 4.15
"""


def write(tmp_path: Path, *, title="faults", samples=16, dist="normal", shape="sd = 0.05",
          rank_by="analytical.wear_limit_tip_pct", output="analytical.seating_radius_mm", name="s.toml") -> Path:
    path = tmp_path / name
    path.write_text(STUDY.format(title=title, template=TEMPLATE, samples=samples, dist=dist, shape=shape,
                                 rank_by=rank_by, output=output))
    return path


def cli(*args: str, env: dict | None = None, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "gearcheck", *args], capture_output=True, text=True, check=False,
                          timeout=timeout, env={**os.environ, **(env or {})})


# A piped study's progress on stderr: a line when a stage starts, per tenth of it, when it ends.
PROGRESS = re.compile(r"^(study: .* …|  study: .*: \d+/\d+ .* \(\d+ %\)|study: .*: done in [\d.]+ s)$")


def messages(err: str) -> list[str]:
    """stderr without the progress lines."""
    return [line for line in err.strip().splitlines() if not PROGRESS.match(line)]


def one_line(err: str) -> str:
    lines = messages(err)
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


# -- whole-number inputs, all variants rejected -------------------------------------------------

TEETH = """
title = "tooth count"
template = "{template}"
samples = 8
seed = 1
exact = 0
check_worst = 0
rank_by = "analytical.wear_limit_tip_pct"

[[inputs]]
field = "sprocket.teeth"
distribution = "uniform"
low = 47
high = 51
integer = true
unit = "1"
reason = "the tooth count chosen"
"""


def test_integer_inputs_reach_the_template_as_ints(tmp_path):
    """Before: every variant rejected ("sprocket.teeth = 48.0: wrong type ... integer"), exit 0.
    Now: each draw is a whole tooth count, and each is valid (an even count is a warning of the
    track's verdicts, not bad input), never rejected for its type."""
    path = tmp_path / "teeth.toml"
    path.write_text(TEETH.format(template=TEMPLATE))
    res = gearcheck.study(path, jobs=1)
    teeth = np.asarray(res.table.column("in.sprocket.teeth").to_numpy())
    assert np.array_equal(teeth, np.rint(teeth)) and set(teeth) <= {47, 48, 49, 50, 51}
    assert len(set(teeth)) > 1 and res.summary["valid"] == len(teeth)
    assert not res.summary["rejections"]


def test_study_with_every_variant_rejected_is_one_line_and_exit_2(tmp_path):
    """Before: exit 0, "0 valid variants of 16", the files written (or an error blaming a
    failure's output). Now: one line naming the first rejection, exit 2, nothing written."""
    path = write(tmp_path, dist="uniform", shape="low = 5.0\nhigh = 5.1")  # outside ISO 606's 4.040–4.178 mm
    out = tmp_path / "out"
    r = cli("study", str(path), "--jobs", "1", "--out", str(out))
    line = one_line(r.stderr)
    assert r.returncode == 2, r.stderr
    assert "every one of the 16 variants was rejected" in line and "sprocket.seating_radius_mm = 5.0" in line
    assert "allowed 4.040 to 4.178 mm" in line and "failures[" not in line
    assert not out.exists() and r.stdout == ""


# -- flags against the study file's limits ------------------------------------------------------

def _range(name: str) -> str:
    lo, hi = (m for m in spec.StudySpec.model_fields[name].metadata)
    return f"allowed {lo.ge} to {hi.le}"


@pytest.mark.parametrize("flag, value, allowed", [
    ("--samples", "1000000000", _range("samples")),
    ("--samples", "1", _range("samples")),
    ("--samples", "1e3", "allowed a whole number 2 to"),
    ("--check-worst", "1000", _range("check_worst")),
    ("--check-worst", "-3", _range("check_worst")),
    ("--exact", "-5", _range("exact")),
    ("--exact", str(spec.MAX_EXACT + 1), _range("exact")),
    ("--seed", "-1", _range("seed")),
    ("--scheduler", "garbage", "allowed local-cluster, or tcp://HOST:PORT or tls://HOST:PORT"),
    ("--scheduler", "udp://127.0.0.1:8786", "allowed local-cluster, or tcp://HOST:PORT"),
    ("--scheduler", "tcp://127.0.0.1:70000", "allowed local-cluster, or tcp://HOST:PORT"),
])
def test_flags_are_held_to_the_study_files_limits(tmp_path, flag, value, allowed):
    """Before: a 40 GiB allocation's traceback, --check-worst 1000 run, negative counts taken,
    ValueError tracebacks (exit 1). Now: one line naming the flag, its value and the range the
    study file's own field allows; exit 2; nothing written."""
    out = tmp_path / "out"
    r = cli("study", str(write(tmp_path)), flag, value, "--jobs", "1", "--out", str(out), timeout=60)
    line = one_line(r.stderr)
    assert r.returncode == 2 and line.startswith(f"gearcheck: error: {flag} = "), r.stderr
    assert value in line and allowed in line
    assert not out.exists()


def test_flag_limits_are_the_spec_models():
    assert _range("check_worst") == f"allowed 0 to {spec.MAX_CHECKS}"
    assert spec.flag_value("exact", "-1") == -1  # every variant, as --help says
    assert spec.flag_value("samples", 2) == 2 and spec.flag_value("seed", "0") == 0
    for name, bad in [("samples", True), ("seed", 2**63), ("check_worst", spec.MAX_CHECKS + 1)]:
        with pytest.raises(ParamError, match=spec.FLAGS[name]):
            spec.flag_value(name, bad)


def test_api_overrides_are_checked_too(tmp_path):
    with pytest.raises(ParamError, match=r"--exact = -5: allowed -1 to"):
        gearcheck.study(write(tmp_path), jobs=1, exact=-5)
    with pytest.raises(ParamError, match=r"--scheduler = 'udp://h:1'"):
        gearcheck.study(write(tmp_path), jobs=1, scheduler="udp://h:1")


# -- outputs checked before any variant is drawn ------------------------------------------------

@pytest.mark.parametrize("field, kwargs", [
    ("rank_by", {"rank_by": "analytical.no_such_figure"}),
    ("failures[seat_large].output", {"output": "exact.no_such_figure"}),
])
def test_outputs_are_checked_before_any_variant_is_drawn(tmp_path, monkeypatch, field, kwargs):
    """Before: the variants were drawn and evaluated, then the error came (or, with every
    variant rejected, blamed the output). Now: before drawing, one line with the allowed names."""
    def no_draw(*_a, **_k):
        raise AssertionError("variants drawn before the study's outputs were checked")

    monkeypatch.setattr(core, "draw", no_draw)
    with pytest.raises(ParamError) as err:
        gearcheck.study(write(tmp_path, **kwargs), jobs=1)
    text = str(err.value)
    assert f"{field} = '{next(iter(kwargs.values()))}'" in text
    assert "allowed one of the study's figures: " in text and "analytical.seating_radius_mm" in text
    assert "\n" not in text


def test_failure_on_an_exact_figure_with_exact_0_reports_it_not_evaluated(tmp_path):
    """Before: `--exact 0` ran the study, then failed on the failures' exact outputs (exit 2).
    Now: the study runs; a failure counted on a level that did not run says so."""
    r = cli("study", "track_wear", "--samples", "4", "--exact", "0", "--check-worst", "0", "--jobs", "1",
            "--out", str(tmp_path / "out"))
    assert r.returncode == 0, r.stderr
    assert "P(link_jumps): not evaluated (exact.link_jumps on 0 variants)" in r.stdout


# -- free text and messages ---------------------------------------------------------------------

@pytest.mark.parametrize("text", ["\\u001b[31mred", "bell\\u0007", "two\\nlines", "\\u202eevil"])
def test_control_characters_in_free_text_are_refused(tmp_path, text):
    """Before: an escape sequence or a bell in the title reached the terminal and report.html
    raw. Now: one line naming the field."""
    with pytest.raises(ParamError, match=r"^.*: title = .*: allowed printable text") as err:
        spec.load_spec(write(tmp_path, title=text))
    assert "\x1b" not in str(err.value) and "\x07" not in str(err.value)
    path = write(tmp_path)
    path.write_text(path.read_text().replace('label = "seating', f'label = "{text} seating'))
    with pytest.raises(ParamError, match=r"failures\[seat_large\]\.label = .*: allowed printable text"):
        spec.load_spec(path)


@pytest.mark.parametrize("shape, dist, expected", [
    ("sd = -0.0067", "normal", "inputs[sprocket.seating_radius_mm].sd = -0.0067: out of range: allowed ≥ 0"),
    ("", "normal", "inputs[sprocket.seating_radius_mm].sd = <missing>: required for a normal distribution"),
    ("low = 4.0", "uniform", "inputs[sprocket.seating_radius_mm].high = <missing>: required for a uniform"),
])
def test_input_messages_say_what_is_allowed(tmp_path, shape, dist, expected):
    """Before: "sd = -0.0067: out of range: " with nothing after it; "sd = 'missing'"."""
    with pytest.raises(ParamError) as err:
        spec.load_spec(write(tmp_path, dist=dist, shape=shape))
    assert expected in str(err.value)


@pytest.mark.parametrize("limits, expected", [
    ("", "failures[seat_large].below/above = <missing>: required: one limit, below"),
    ("above = 4.15\nbelow = 4.0", "failures[seat_large].above = 4.15: allowed only one of below or above"),
])
def test_failure_messages_say_what_is_allowed(tmp_path, limits, expected):
    path = write(tmp_path)
    path.write_text(path.read_text().replace("above = 4.15", limits))
    with pytest.raises(ParamError) as err:
        spec.load_spec(path)
    assert expected in str(err.value)


# -- Dask: quiet, no dashboard, one line when terminated, an absent scheduler named -------------

def test_local_cluster_is_silent_without_v_and_speaks_with_it(tmp_path):
    """Before: 33 lines of distributed's INFO logs on stderr without -v. Now: none; with -v
    they show."""
    path = write(tmp_path, samples=8)
    quiet = cli("study", str(path), "--scheduler", "local-cluster", "--jobs", "1", "--out", str(tmp_path / "a"))
    assert quiet.returncode == 0 and messages(quiet.stderr) == [], quiet.stderr  # its own progress lines only
    assert "variant (100 %)" in quiet.stderr
    loud = cli("-v", "study", str(path), "--scheduler", "local-cluster", "--jobs", "1", "--out", str(tmp_path / "b"))
    assert loud.returncode == 0 and "Scheduler at" in loud.stderr and "Traceback" not in loud.stderr


def test_local_cluster_serves_no_dashboard():
    """Before: the scheduler's HTTP server on port 8787 with its routes (the dashboard's, health,
    metrics). Now: a random loopback port, nothing served, no dashboard."""
    import logging

    from gearcheck.executor import DaskExecutor

    with DaskExecutor("local-cluster", 1) as ex:
        server = ex._cluster.scheduler.http_server
        assert ex.client.submit(int, "7").result(timeout=60) == 7
        assert server.address == "127.0.0.1" and server.port != 8787
        with pytest.raises(urllib.error.HTTPError) as got:
            urllib.request.urlopen(f"http://127.0.0.1:{server.port}/health", timeout=10)
        assert got.value.code == 404
        assert logging.getLogger("distributed.scheduler").getEffectiveLevel() > logging.CRITICAL
    assert logging.getLogger("distributed.scheduler").getEffectiveLevel() <= logging.INFO  # restored


def _session(sid: int) -> list[int]:
    """Live (not zombie) processes of a session."""
    out = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            fields = stat.rsplit(")", 1)[1].split()
            if int(fields[3]) == sid and fields[0] != "Z":
                out.append(int(entry.name))
    return out


@pytest.mark.parametrize("group", [False, True], ids=["process", "process-group"])
def test_sigterm_to_a_local_cluster_study_is_one_line_and_leaves_no_process(tmp_path, group):
    """Before: distributed's logs and tracebacks (CommClosedError) around the interrupt, lines
    after it. Now: exactly one line, exit 143, nothing written, no process left."""
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "gearcheck", "study", "track_wear", "--samples", "64",
                             "--check-worst", "0", "--scheduler", "local-cluster", "--jobs", "2", "--out", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        deadline = time.monotonic() + 60
        while len(_session(proc.pid)) < 3 and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.1)  # this process and two workers: the cluster is up
        time.sleep(1.0)
        assert proc.poll() is None, proc.stderr.read()
        if group:
            os.killpg(proc.pid, signal.SIGTERM)
        else:
            proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 143, err
    assert messages(err) == ["gearcheck: interrupted (SIGTERM): nothing written"], err
    assert not out.exists()
    deadline = time.monotonic() + 10
    while _session(proc.pid) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert _session(proc.pid) == []


def test_absent_scheduler_is_named_with_the_wait(tmp_path):
    """Before: "<stdout>: cannot write: Timed out trying to connect ..." after 20 s. Now: the
    flag, its value, and that no scheduler answered in the time allowed."""
    with socket.socket() as s:  # a port nothing listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    address = f"tcp://127.0.0.1:{port}"
    t0 = time.monotonic()
    r = cli("study", str(write(tmp_path)), "--scheduler", address, "--out", str(tmp_path / "out"),
            env={core.SCHEDULER_TIMEOUT_ENV: "1"}, timeout=60)
    assert r.returncode == 2, r.stderr
    assert one_line(r.stderr) == (f"gearcheck: error: --scheduler = '{address}': no Dask scheduler answered within "
                                  "1 s (start one with `dask scheduler`, or run on --scheduler local-cluster)")
    assert time.monotonic() - t0 < 30 and not (tmp_path / "out").exists()
    bad = cli("study", str(write(tmp_path)), "--scheduler", address, "--out", str(tmp_path / "out"),
              env={core.SCHEDULER_TIMEOUT_ENV: "soon"})
    assert bad.returncode == 2 and f"{core.SCHEDULER_TIMEOUT_ENV} = 'soon': allowed" in one_line(bad.stderr)


# -- the folder holds the run's files only ------------------------------------------------------

def test_checks_leave_no_lock_files_in_the_study_folder(tmp_path, monkeypatch):
    """Before: checks/.variant_NNNNN.lock beside each re-checked variant. Now: the study's folder
    holds its files and each check's folder, nothing else (a check is stood in for: its folder is
    a run folder, as pipeline.check writes one, without the CAD)."""
    from types import SimpleNamespace

    from gearcheck import pipeline
    from gearcheck.output import RunFolder

    def fake_check(design, folder, **_kw):
        with RunFolder(folder) as txn:
            (txn.staging / "summary.json").write_text("{}\n")
            txn.commit()
        return SimpleNamespace(result=SimpleNamespace(level="pass", passed=True, verdicts=[]))

    monkeypatch.setattr(pipeline, "check", fake_check)
    path = write(tmp_path, samples=8)
    path.write_text(path.read_text().replace("check_worst = 0", "check_worst = 2"))
    out = tmp_path / "study"
    res = gearcheck.study(path, jobs=1, out=out)
    assert [c["folder"] for c in res.summary["checks"]] == [f"checks/variant_{c['variant']:05d}"
                                                            for c in res.summary["checks"]] and res.summary["checks"]
    files = sorted(str(p.relative_to(out)) for p in out.rglob("*") if p.is_file())
    checks = [c["folder"] for c in res.summary["checks"]]
    assert files == sorted(["manifest.json", "report.html", "results.parquet", "summary.json", ".gearcheck-run",
                            *(f"{c}/summary.json" for c in checks), *(f"{c}/.gearcheck-run" for c in checks)])
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".study")) == [".study.lock"]


def test_probabilities_over_valid_and_over_all_drawn():
    """Before: a study with variants out of spec reported failures over the accepted ones only
    (21/44 where 20 of 64 were rejected), without saying so. Now both, and which one leads."""
    import numpy as np

    from gearcheck.studies.core import summarise
    from gearcheck.studies.spec import load_spec, packaged_studies

    spec = load_spec(packaged_studies() / "track_wear.toml")
    failure = spec.failures[0]
    n = 64
    valid = np.ones(n, bool)
    valid[:20] = False
    limit = failure.below if failure.below is not None else failure.above
    bad = limit - 1.0 if failure.below is not None else limit + 1.0
    good = limit + 1.0 if failure.below is not None else limit - 1.0
    v = np.full(n, good)
    v[20:41] = bad  # 21 of the 44 valid variants fail
    v[:20] = np.nan
    def passing(g) -> float:
        return g.below + 1.0 if g.below is not None else g.above - 1.0

    figures = {g.output: np.where(valid, passing(g), np.nan) for g in spec.failures}
    figures.setdefault(spec.rank_by, np.where(valid, 1.0, np.nan))
    figures[failure.output] = v
    inputs = {i.key: np.linspace(0.0, 1.0, n) for i in spec.inputs}
    ev = {"figures": figures, "valid": valid, "rejection": ["out of spec"] * n, "exact_rows": np.arange(n)}
    s = summarise(spec, "t.toml", inputs, ev, [], n, 0)
    f = s["failures"][failure.name]
    assert (f["failures"], f["variants"], f["over"]) == (21, 44, "valid variants")
    d = f["over_drawn"]
    assert (d["failures"], d["variants"], d["rejected"]) == (41, 64, 20)
    assert d["probability"] == pytest.approx(41 / 64)
