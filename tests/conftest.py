import os
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

# A progress line on a piped stderr (cli's line progress): a stage starting, a tenth of it, its end
PROGRESS_LINE = re.compile(r"^(building .* \.\.\.|\S.* …|  \S.*: \d+/\S+.* \(\d+ %\)|\S.*: done in [\d.]+ s)$")


def messages(err: str) -> list[str]:
    """stderr less its progress lines and -v's stage lines: what gearcheck said."""
    return [line for line in err.splitlines() if line.strip() and not PROGRESS_LINE.match(line)
            and not line.startswith("gearcheck: stage")]
TEMPLATES = ROOT / "templates"


@pytest.fixture(scope="session")
def templates_dir() -> Path:
    return TEMPLATES


@pytest.fixture(scope="session")
def build_bodies(tmp_path_factory):
    """Factory: build a template (with --set overrides) through the pipeline into a temp folder
    and return its :class:`gearcheck.pipeline.BuildRun` (design, assembly, parts, bodies,
    manifest); each distinct request is built once per session."""
    cache = {}

    def build(name: str, overrides: tuple[str, ...] = (), tol_mm: float = 0.01):
        key = (name, tuple(overrides), tol_mm)
        if key not in cache:
            from gearcheck import pipeline
            from gearcheck.design import load_template

            design = load_template(TEMPLATES / f"{name}.toml", list(overrides))
            cache[key] = pipeline.build(design, tmp_path_factory.mktemp(name), tol_mm=tol_mm)
        return cache[key]

    return build


@pytest.fixture(scope="session")
def template_check(tmp_path_factory):
    """Factory: ``gearcheck check`` of a template (with --set overrides) into a temp folder, on 2
    processes; returns the :class:`gearcheck.pipeline.CheckRun`. Each distinct request runs once
    per session, so every test module that reads a template's report shares one run."""
    cache = {}

    def check(name: str, overrides: tuple[str, ...] = ()):
        key = (name, tuple(overrides))
        if key not in cache:
            from gearcheck import pipeline
            from gearcheck.design import load_template

            design = load_template(TEMPLATES / f"{name}.toml", list(overrides))
            cache[key] = pipeline.check(design, tmp_path_factory.mktemp(f"check_{name}") / "run", jobs=2,
                                        overrides=list(overrides))
        return cache[key]

    return check


# The CAD cache is off for the suite (tests that monkeypatch the CAD must build it); the tests
# of the cache turn it on in folders of their own. Spawned workers and CLI subprocesses inherit it.
os.environ["GEARCHECK_CACHE"] = "off"
