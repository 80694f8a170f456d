"""The CAD cache (gearcheck.cache) facing what it did not write: a cache folder that holds a user's
files is not used and nothing in it is touched; in gearcheck's own folder only what gearcheck
made is ever removed; an entry copied under another key, a link, a pipe in place of a file, or
an index of the wrong shape is an unreadable entry (a warning, the CAD built again), never a
wrong result, a hang or a traceback."""

from __future__ import annotations

import json
import logging
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

from gearcheck import cache

ROOT = Path(__file__).resolve().parents[1]
TEMPLATES = ROOT / "templates"
FILES = {"cad.pickle": b"solids" * 100, "model.step": b"ISO-10303-21;" * 10}
HOURS_AGO = time.time() - 2 * 3600


def key(label: str) -> str:
    return cache.key_of(label)


def tree(folder: Path) -> list[str]:
    """Every path under ``folder`` (links not followed), relative."""
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def user_folder(folder: Path) -> Path:
    """A home- or project-like folder: hidden folders over an hour old, a file, a folder named
    like an entry."""
    for name in (".git", ".ssh", ".config", "a" * 64):
        (folder / name).mkdir(parents=True)
        (folder / name / "keep").write_text("mine\n")
        os.utime(folder / name, (HOURS_AGO, HOURS_AGO))
    (folder / "notes.txt").write_text("mine\n")
    return folder


# --------------------------------------------------------------- the cache folder
def test_a_folder_holding_other_files_is_not_used_and_not_touched(tmp_path, caplog):
    folder = user_folder(tmp_path / "home")
    before = tree(folder)
    with caplog.at_level(logging.WARNING, logger="gearcheck"):
        assert cache.load(folder, key("k")) is None
        assert not cache.store(folder, key("k"), FILES)
    assert cache.evict(folder, max_bytes=0) == []
    cache.discard(folder, "a" * 64)
    assert tree(folder) == before  # no tag, no entry, nothing removed
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warnings) == 1, warnings  # once per run
    assert str(folder) in warnings[0] and "gearcheck did not write" in warnings[0]
    assert "cache not used" in warnings[0] and "GEARCHECK_CACHE" in warnings[0]


def test_build_with_the_cache_in_a_project_folder_keeps_its_files(tmp_path):
    """`GEARCHECK_CACHE=. gearcheck build` in a folder holding a .git two hours old: the run
    succeeds without the cache, says why on one line, and the .git is there after."""
    project = user_folder(tmp_path / "P")
    before = tree(project)
    env = {**os.environ, "GEARCHECK_CACHE": "."}
    out = subprocess.run([sys.executable, "-m", "gearcheck", "build", str(TEMPLATES / "eod_track_drive.toml"),
                          "--out", str(tmp_path / "O")], cwd=project, env=env, capture_output=True, text=True,
                         timeout=600, check=False)
    assert out.returncode == 0, out.stderr[-2000:]
    assert tree(project) == before
    lines = [line for line in out.stderr.splitlines() if "did not write" in line]
    assert len(lines) == 1 and "cache not used" in lines[0], out.stderr
    manifest = json.loads((tmp_path / "O" / "manifest.json").read_text())
    assert manifest["cad_cache"]["reused"] is False


def test_a_new_or_empty_folder_is_tagged_and_used(tmp_path):
    for folder in (tmp_path / "new" / "cache", tmp_path / "empty"):
        if folder.name == "empty":
            folder.mkdir()
        assert cache.store(folder, key("k"), FILES)
        tag = (folder / cache.TAG).read_text()
        assert tag.startswith("Signature: 8a477f597d28d172789f06886806bc55\n")  # the Cache Directory Tagging spec
        assert cache.load(folder, key("k")).files == FILES
        assert sorted(p.name for p in folder.iterdir()) == sorted([cache.TAG, key("k")])


def test_another_tools_cache_tag_is_not_gearchecks(tmp_path, caplog):
    (tmp_path / cache.TAG).write_text(cache.TAG_SIGNATURE + "\n# made by another tool\n")
    (tmp_path / "build").mkdir()
    with caplog.at_level(logging.WARNING, logger="gearcheck"):
        assert not cache.store(tmp_path, key("k"), FILES)
    assert "did not write" in caplog.text and sorted(p.name for p in tmp_path.iterdir()) == [cache.TAG, "build"]


def earlier_cache(folder: Path) -> Path:
    """A cache folder as an earlier gearcheck left it (format 1: no tag, no marks): an entry
    named by its key with its index, and a staging folder a killed run left."""
    import hashlib

    entry = folder / ("0123456789abcdef" * 4)
    entry.mkdir(parents=True)
    files = {}
    for name, data in FILES.items():
        (entry / name).write_bytes(data)
        files[name] = [len(data), hashlib.sha256(data).hexdigest()]
    (entry / "index.json").write_text(json.dumps({"format": 1, "created": "2026-01-01T00:00:00Z", "files": files}))
    staging = folder / ".0123456789abcdef-k1_lled9"
    staging.mkdir()
    (staging / "cad.pickle").write_bytes(b"half")
    return folder


def test_an_earlier_gearchecks_cache_folder_is_taken_over(tmp_path, caplog):
    """The default folder (~/.cache/gearcheck) as an earlier version wrote it: recognised as
    gearcheck's, its unreadable format-1 entries removed, tagged and used (not refused for good)."""
    folder = earlier_cache(tmp_path / "cache")
    with caplog.at_level(logging.WARNING, logger="gearcheck"):
        assert cache.store(folder, key("k"), FILES)
    assert "earlier gearcheck" in caplog.text
    assert sorted(p.name for p in folder.iterdir()) == sorted([cache.TAG, key("k")])


def test_an_earlier_cache_with_anything_else_in_it_is_refused_whole(tmp_path):
    folder = earlier_cache(tmp_path / "cache")
    (folder / ("0123456789abcdef" * 4) / "notes.txt").write_text("mine\n")  # not an entry's file
    before = tree(folder)
    assert not cache.store(folder, key("k"), FILES)
    assert tree(folder) == before


def test_only_what_gearcheck_made_is_evicted(tmp_path):
    """In gearcheck's own folder, eviction removes its entries and its old staging folders, and
    never a user's file or folder, whatever its name or age."""
    folder = tmp_path / "cache"
    for label in ("one", "two"):
        assert cache.store(folder, key(label), FILES)
    user_folder(folder)
    staging_like = folder / f"{cache.STAGING}{'b' * 16}-mine"  # gearcheck's naming, no mark
    staging_like.mkdir()
    no_index = folder / key("no index")  # an entry's name, no index
    no_index.mkdir()
    unmarked = folder / key("copied by hand")  # an entry's files, no mark
    shutil.copytree(folder / key("one"), unmarked)
    (unmarked / cache.MARK).unlink()
    stale = Path(tempfile.mkdtemp(prefix=f"{cache.STAGING}{key('three')[:16]}-", dir=folder))
    (stale / cache.MARK).write_bytes(cache.MARK_TEXT)
    (stale / "cad.pickle").write_bytes(b"half")
    for path in (staging_like, no_index, unmarked, stale):
        os.utime(path, (HOURS_AGO, HOURS_AGO))
    user_files = [name for name in tree(folder) if not name.startswith((key("one"), key("two"), stale.name))]
    removed = cache.evict(folder, max_bytes=0)
    assert sorted(removed) == sorted([key("one"), key("two")])
    assert tree(folder) == user_files  # the user's files, and the tag
    cache.discard(folder, unmarked.name)  # an entry's files without the mark: not gearcheck's to remove
    assert cache.load(folder, unmarked.name) is None and unmarked.exists()


# --------------------------------------------------------- an entry bound to its key
def test_an_entry_copied_under_another_key_is_refused(tmp_path, caplog):
    folder = tmp_path / "cache"
    assert cache.store(folder, key("coarse"), FILES)
    shutil.copytree(folder / key("coarse"), folder / key("fine"))
    with caplog.at_level(logging.WARNING, logger="gearcheck"):
        assert cache.load(folder, key("fine")) is None
    assert "another key" in caplog.text
    assert not (folder / key("fine")).exists()  # gearcheck's own entry under a name it cannot hold: removed
    assert cache.load(folder, key("coarse")).files == FILES
    assert cache.store(folder, key("fine"), {"cad.pickle": b"fine"})  # its own entry can be written now
    assert json.loads((folder / key("fine") / cache.INDEX).read_text())["key"] == key("fine")


def test_a_build_does_not_take_another_tolerances_meshes(tmp_path, monkeypatch, caplog):
    """The entry of the 0.01 mm meshes copied under the key of the 0.005 mm ones: the build at
    0.005 mm makes its own CAD, and its meshes are those of a cold build at 0.005 mm."""
    from gearcheck import pipeline
    from gearcheck.design import load_template

    monkeypatch.setenv("GEARCHECK_CACHE", str(tmp_path / "cache"))
    design = load_template(TEMPLATES / "nose_wheel_steering.toml")
    coarse = pipeline.build(design, tmp_path / "coarse", tol_mm=0.01)
    fine_key = pipeline.cad_key(design, design.impl.assembly(design.params), 0.005)
    shutil.copytree(tmp_path / "cache" / coarse.manifest["cad_cache"]["key"], tmp_path / "cache" / fine_key)
    with caplog.at_level(logging.WARNING, logger="gearcheck"):
        fine = pipeline.build(design, tmp_path / "fine", tol_mm=0.005)
    assert "another key" in caplog.text
    assert fine.manifest["cad_cache"] == {"key": fine_key, "reused": False, "made": None}
    monkeypatch.setenv("GEARCHECK_CACHE", "off")
    cold = pipeline.build(design, tmp_path / "cold", tol_mm=0.005)
    stls = sorted(p.name for p in cold.folder.glob("*.stl"))
    assert stls and all((fine.folder / n).read_bytes() == (cold.folder / n).read_bytes() for n in stls)


# ------------------------------------------------------- what is not a regular file
def load_in_child(folder: Path, entry_key: str) -> str:
    """``cache.load`` in a fresh interpreter, bounded in time: 'entry' or 'none'."""
    code = ("import pathlib, sys\nfrom gearcheck import cache\n"
            "print('entry' if cache.load(pathlib.Path(sys.argv[1]), sys.argv[2]) else 'none')")
    out = subprocess.run([sys.executable, "-c", code, str(folder), entry_key], capture_output=True, text=True,
                         timeout=60, check=False)
    assert out.returncode == 0, out.stderr[-2000:]
    return out.stdout.strip()


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes")
@pytest.mark.parametrize("name", [cache.INDEX, "cad.pickle", cache.MARK])
def test_a_pipe_in_place_of_a_file_does_not_block(tmp_path, name):
    folder = tmp_path / "cache"
    assert cache.store(folder, key("k"), FILES)
    (folder / key("k") / name).unlink()
    os.mkfifo(folder / key("k") / name)
    assert load_in_child(folder, key("k")) == "none"
    # without its mark the folder is not gearcheck's: left as it is; otherwise removed
    assert (folder / key("k")).exists() == (name == cache.MARK)


def test_links_are_not_followed_out_of_the_cache(tmp_path, caplog):
    folder, outside = tmp_path / "cache", tmp_path / "outside"
    assert cache.store(folder, key("k"), FILES)
    shutil.copytree(folder / key("k"), outside / "entry")
    (outside / "data").mkdir()
    (outside / "data" / "keep").write_text("mine\n")
    (outside / "cad.pickle").write_bytes(FILES["cad.pickle"])
    before = tree(outside)
    # a data file linked outside (with the right content): unreadable, removed, the target kept
    (folder / key("k") / "cad.pickle").unlink()
    (folder / key("k") / "cad.pickle").symlink_to(outside / "cad.pickle")
    (folder / key("k") / "more").symlink_to(outside / "data", target_is_directory=True)
    with caplog.at_level(logging.WARNING, logger="gearcheck"):
        assert cache.load(folder, key("k")) is None
    assert "not a regular file" in caplog.text and not os.path.lexists(folder / key("k"))
    # an entry that is a link to a whole entry elsewhere: not read, not removed
    (folder / key("k")).symlink_to(outside / "entry", target_is_directory=True)
    assert cache.load(folder, key("k")) is None
    cache.discard(folder, key("k"))
    assert cache.evict(folder, max_bytes=0) == []
    assert os.path.islink(folder / key("k")) and tree(outside) == before


# ------------------------------------------------------------- a malformed index
def digest(data: bytes) -> str:
    return cache._digest(data)


GOOD = [len(FILES["cad.pickle"]), digest(FILES["cad.pickle"])]
MALFORMED = {
    "files is a list": lambda i: {**i, "files": ["cad.pickle", "model.step"]},
    "files is a string": lambda i: {**i, "files": "cad.pickle"},
    "files is null": lambda i: {**i, "files": None},
    "files is empty": lambda i: {**i, "files": {}},
    "a file is a number": lambda i: {**i, "files": {"cad.pickle": 3}},
    "a file is one item": lambda i: {**i, "files": {"cad.pickle": [GOOD[0]]}},
    "a size is a string": lambda i: {**i, "files": {"cad.pickle": [str(GOOD[0]), GOOD[1]]}},
    "a size is true": lambda i: {**i, "files": {"cad.pickle": [True, GOOD[1]]}},
    "a size is negative": lambda i: {**i, "files": {"cad.pickle": [-1, GOOD[1]]}},
    "a digest is a number": lambda i: {**i, "files": {"cad.pickle": [GOOD[0], 7]}},
    "a name leads out": lambda i: {**i, "files": {"../../outside.bin": GOOD}},
    "an absolute name": lambda i: {**i, "files": {"/etc/hostname": GOOD}},
    "the index names itself": lambda i: {**i, "files": {cache.INDEX: GOOD}},
    "the index names the mark": lambda i: {**i, "files": {cache.MARK: GOOD}},
    "no key": lambda i: {k: v for k, v in i.items() if k != "key"},
    "key is a number": lambda i: {**i, "key": 1},
    "no created": lambda i: {k: v for k, v in i.items() if k != "created"},
    "created is a list": lambda i: {**i, "created": []},
    "format is true": lambda i: {**i, "format": True},
    "format is 1": lambda i: {**i, "format": 1},
    "an extra key": lambda i: {**i, "more": 1},
    "a list": lambda i: [i],
    "a string": lambda i: "index",
    "null": lambda i: None,
}


@pytest.mark.parametrize("case", sorted(MALFORMED))
def test_a_malformed_index_is_an_unreadable_entry(tmp_path, caplog, case):
    folder = tmp_path / "cache"
    (tmp_path / "outside.bin").write_bytes(FILES["cad.pickle"])
    assert cache.store(folder, key("k"), FILES)
    index_path = folder / key("k") / cache.INDEX
    index_path.write_text(json.dumps(MALFORMED[case](json.loads(index_path.read_text()))))
    with caplog.at_level(logging.WARNING, logger="gearcheck"):
        assert cache.load(folder, key("k")) is None
    assert "unreadable" in caplog.text and not (folder / key("k")).exists()
    assert (tmp_path / "outside.bin").exists()
    assert cache.store(folder, key("k"), FILES) and cache.load(folder, key("k")).files == FILES


@pytest.mark.parametrize("raw", [b"{", b"\xff\xfe{}", b"[" * 200_000 + b"]" * 200_000, b" " * (2 << 20)],
                         ids=["cut short", "not UTF-8", "nested deeply", "too large"])
def test_an_index_that_is_not_json_is_an_unreadable_entry(tmp_path, caplog, raw):
    folder = tmp_path / "cache"
    assert cache.store(folder, key("k"), FILES)
    (folder / key("k") / cache.INDEX).write_bytes(raw)
    with caplog.at_level(logging.WARNING, logger="gearcheck"):
        assert cache.load(folder, key("k")) is None
    assert "unreadable" in caplog.text and not (folder / key("k")).exists()


def test_a_malformed_index_in_a_build_is_a_warning_and_a_rebuild(tmp_path):
    """The CLI on an entry whose index lists its files: one warning line, the CAD built again,
    no traceback."""
    env = {**os.environ, "GEARCHECK_CACHE": str(tmp_path / "cache")}

    def build(out: str) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, "-m", "gearcheck", "build", str(TEMPLATES / "nose_wheel_steering.toml"),
                               "--out", str(tmp_path / out)], cwd=ROOT, env=env, capture_output=True, text=True,
                              timeout=600, check=False)

    assert build("a").returncode == 0
    (entry,) = (p for p in (tmp_path / "cache").iterdir() if p.name != cache.TAG)
    index = json.loads((entry / cache.INDEX).read_text())
    (entry / cache.INDEX).write_text(json.dumps({**index, "files": list(index["files"])}))
    out = build("b")
    assert out.returncode == 0 and "Traceback" not in out.stderr, out.stderr[-2000:]
    assert [line for line in out.stderr.splitlines() if "unreadable" in line], out.stderr
    assert json.loads((tmp_path / "b" / "manifest.json").read_text())["cad_cache"]["reused"] is False
