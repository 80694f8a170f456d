"""The CAD cache (gearcheck.cache): a design's solids, meshes and STEP file kept by what they are
made from. A re-check from the cache is the same run (every figure and file but the manifest's
note of where the CAD came from); a key changes with the geometry and not with what only the
sweep reads; an entry that does not read back is built again; a cache that cannot be written
never fails a run; the oldest-used entries go beyond the size limit."""

from __future__ import annotations

import json
import logging
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

from gearcheck import cache

ROOT = Path(__file__).resolve().parents[1]
TEMPLATES = ROOT / "templates"
SAME_BYTES = ("summary.json", "sweep.csv", "params.toml", ".step", ".stl", ".glb", ".png")


def test_root_from_the_environment(tmp_path):
    assert cache.root({"GEARCHECK_CACHE": "off"}) is None
    assert cache.root({"GEARCHECK_CACHE": "OFF "}) is None
    assert cache.root({"GEARCHECK_CACHE": str(tmp_path)}) == tmp_path
    assert cache.root({"XDG_CACHE_HOME": str(tmp_path)}) == tmp_path / "gearcheck"
    assert cache.root({}) == Path.home() / ".cache" / "gearcheck"


def _key(label: str) -> str:
    """A cache key (64 hex digits) for a test's label."""
    return cache.key_of(label)


def test_store_load_and_tampering(tmp_path, caplog):
    files = {"a.bin": b"x" * 1000, "b.bin": b"y"}
    k1 = _key("k1")
    assert cache.store(tmp_path, k1, files)
    assert not cache.store(tmp_path, k1, {"a.bin": b"other"})  # published already: kept as it is
    entry = cache.load(tmp_path, k1)
    assert entry is not None and entry.files == files and entry.key == k1
    assert cache.load(tmp_path, _key("missing")) is None
    (tmp_path / k1 / "a.bin").write_bytes(b"x" * 999)  # cut short
    with caplog.at_level(logging.WARNING, logger="gearcheck"):
        assert cache.load(tmp_path, k1) is None
    assert "unreadable" in caplog.text and not (tmp_path / k1).exists()
    assert cache.store(tmp_path, k1, files) and cache.load(tmp_path, k1).files == files
    (tmp_path / k1 / "a.bin").write_bytes(b"z" * 1000)  # edited, the same size: its SHA-256 tells
    assert cache.load(tmp_path, k1) is None and not (tmp_path / k1).exists()
    assert cache.store(tmp_path, k1, files)
    (tmp_path / k1 / "b.bin").unlink()  # a file gone: the entry goes too, to be written again
    assert cache.load(tmp_path, k1) is None and not (tmp_path / k1).exists()
    assert cache.store(tmp_path, k1, files)
    with pytest.raises(ValueError, match="not a CAD cache key"):
        cache.load(tmp_path, "../k1")


def test_eviction_keeps_the_most_recently_used(tmp_path):
    old, mid, new = (_key(label) for label in ("old", "mid", "new"))
    for i, key in enumerate((old, mid, new)):
        cache.store(tmp_path, key, {"f": bytes(1000)})
        os.utime(tmp_path / key / cache.INDEX, (1000.0 + i, 1000.0 + i))
    assert cache.load(tmp_path, old) is not None  # used now: the newest
    stale = Path(tempfile.mkdtemp(prefix=f"{cache.STAGING}{'d' * 16}-", dir=tmp_path))
    (stale / cache.MARK).write_bytes(cache.MARK_TEXT)
    os.utime(stale, (time.time() - 2 * cache.STALE_S,) * 2)
    fresh = Path(tempfile.mkdtemp(prefix=f"{cache.STAGING}{'c' * 16}-", dir=tmp_path))
    (fresh / cache.MARK).write_bytes(cache.MARK_TEXT)
    removed = cache.evict(tmp_path, max_bytes=2600)
    assert removed == [mid]  # new and old (about 1.3 kB each with the index and the mark) fit
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([cache.TAG, fresh.name, new, old])


def test_key_follows_the_geometry_not_the_sweep_settings(monkeypatch):
    from gearcheck.design import load_template
    from gearcheck.pipeline import cad_key

    def key(*overrides: str, tol: float = 0.01) -> str:
        design = load_template(TEMPLATES / "zhurong_differential.toml", list(overrides))
        return cad_key(design, design.impl.assembly(design.params), tol)

    base = key()
    assert key() == base
    assert key("operating.cold_C=-70", "operating.storage_min_C=-120") == base  # the sweep's temperatures
    assert key("shim.thickness_mm=0.15") != base  # the gears sit elsewhere
    assert key(tol=0.005) != base
    assert cache.key_of("a") != cache.key_of("b")
    monkeypatch.setattr(cache, "code_digest", lambda _cls: "the mechanism's code, edited")
    assert key() != base


def test_a_plugins_own_code_is_in_the_key(tmp_path, monkeypatch):
    """A mechanism from outside gearcheck keys its CAD by its own package's source: an edit of its
    CAD hook is a new key."""
    from gearcheck.mechanisms.steering.mechanism import Steering

    package = tmp_path / "myplugin"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "cad.py").write_text("WIDTH = 1.0\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    import myplugin  # noqa: F401

    class Plugin:
        pass

    Plugin.__module__ = "myplugin.mechanism"
    before = cache.code_digest(Plugin)
    assert before == cache.code_digest(Plugin) and before != cache.code_digest(Steering)
    assert cache.code_digest(Steering) == cache.source_digest()
    (package / "cad.py").write_text("WIDTH = 2.0\n")
    cache._tree_digest.cache_clear()  # a new process reads the edited file
    assert cache.code_digest(Plugin) != before


def _files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in folder.iterdir() if p.name.endswith(SAME_BYTES)}


def test_recheck_from_the_cache_is_the_same_run(tmp_path):
    """`check --all` twice on one cache (CLI, templates side by side in spawned workers): the
    second run takes every design's CAD from the cache and gives the same summary.json,
    sweep.csv, STEP, STL, glb and pictures, byte for byte; only the manifest's note differs. The
    exact B-rep confirmation works on solids read back from the cache (OCCT's binary B-rep with
    their triangulations), and confirms the same distances."""
    env = {**os.environ, "GEARCHECK_CACHE": str(tmp_path / "cache"), "SOURCE_DATE_EPOCH": "1700000000"}
    for label in ("cold", "warm"):
        out = subprocess.run([sys.executable, "-m", "gearcheck", "check", "--all", "--jobs", "2", "--out",
                              str(tmp_path / label)], cwd=ROOT, env=env, capture_output=True, text=True,
                             timeout=600, check=False)
        assert out.returncode in (0, 1), out.stderr[-2000:]
    assert sorted(p.name for p in (tmp_path / "cache").iterdir() if p.name != cache.TAG) == sorted(
        p.name for p in (tmp_path / "cache").iterdir() if cache.KEY.fullmatch(p.name))
    templates = len(list((ROOT / "templates").glob("*.toml")))
    assert len(list((tmp_path / "cache").iterdir())) == templates + 1  # an entry per template, and the tag
    for folder in sorted(f for f in (tmp_path / "cold").iterdir() if f.is_dir()):
        again = tmp_path / "warm" / folder.name
        cold, warm = _files(folder), _files(again)
        assert sorted(cold) == sorted(warm) and len(cold) >= 7
        assert [n for n in cold if cold[n] != warm[n]] == [], folder.name
        m1, m2 = (json.loads((f / "manifest.json").read_text()) for f in (folder, again))
        assert m1["cad_cache"]["reused"] is False and m2["cad_cache"]["reused"] is True
        assert m1["cad_cache"]["key"] == m2["cad_cache"]["key"]
        assert m1["parts"] == m2["parts"] and m1["step"] == m2["step"]
        assert "from the CAD cache" in (again / "report.html").read_text()


@pytest.fixture
def steering(monkeypatch, tmp_path):
    """The steering template with a cache of its own, and a count of the solids built."""
    from gearcheck.design import load_template

    monkeypatch.setenv("GEARCHECK_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    design = load_template(TEMPLATES / "nose_wheel_steering.toml")
    built = []
    original = type(design.impl).parts

    def counting(self, assembly):
        built.append(1)
        return original(self, assembly)

    monkeypatch.setattr(type(design.impl), "parts", counting)
    return design, built


def test_an_entry_that_does_not_read_back_is_built_again(steering, tmp_path, caplog):
    from gearcheck import pipeline

    design, built = steering
    first = pipeline.build(design, tmp_path / "a")
    (entry,) = (p for p in (tmp_path / "cache").iterdir() if p.name != cache.TAG)
    data = (entry / "cad.pickle").read_bytes()
    (entry / "cad.pickle").write_bytes(data[: len(data) // 2])
    with caplog.at_level(logging.WARNING, logger="gearcheck"):
        second = pipeline.build(design, tmp_path / "b")
    assert "unreadable" in caplog.text and len(built) == 2
    third = pipeline.build(design, tmp_path / "c")  # the entry written again, and read
    assert len(built) == 2 and third.manifest["cad_cache"]["reused"]
    assert _files(first.folder) == _files(second.folder) == _files(third.folder)


def test_a_cache_that_cannot_be_written_does_not_fail_the_run(steering, tmp_path, monkeypatch, caplog):
    from gearcheck import pipeline

    design, built = steering
    blocker = tmp_path / "not_a_folder"
    blocker.write_text("")
    monkeypatch.setenv("GEARCHECK_CACHE", str(blocker / "cache"))
    with caplog.at_level(logging.WARNING, logger="gearcheck"):
        run = pipeline.build(design, tmp_path / "a")
    assert "not written" in caplog.text and not run.manifest["cad_cache"]["reused"]
    assert (run.folder / "nose_wheel_steering.step").exists()


def test_no_cache_flag_and_off(tmp_path):
    env = {**os.environ, "GEARCHECK_CACHE": str(tmp_path / "cache")}
    out = subprocess.run([sys.executable, "-m", "gearcheck", "build", str(TEMPLATES / "nose_wheel_steering.toml"),
                          "--no-cache", "--out", str(tmp_path / "a")], cwd=ROOT, env=env, capture_output=True,
                         text=True, timeout=300, check=False)
    assert out.returncode == 0, out.stderr[-2000:]
    assert not (tmp_path / "cache").exists()
    manifest = json.loads((tmp_path / "a" / "manifest.json").read_text())
    assert manifest["cad_cache"] == {"key": None, "reused": False, "made": None}
