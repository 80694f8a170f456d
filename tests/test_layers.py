"""The layers, read from the source (AST): data flows one way, and each heavy dependency has one
home. ruff's banned-api rule says the same for the linter; this test says it for pytest."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "gearcheck"


def imports(path: Path) -> set[str]:
    """Every module a file imports (absolute names; relative ones resolved in the package)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = ".".join(("gearcheck", *path.relative_to(SRC).with_suffix("").parts[:-1]))
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.rsplit(".", node.level - 1)[0] if node.level > 1 else package
                out.add(f"{base}.{node.module}" if node.module else base)
            else:
                out.add(node.module or "")
    return out


def files(under: str = "") -> list[Path]:
    return sorted((SRC / under).rglob("*.py"))


def _under(module: str, *roots: str) -> bool:
    return any(module == r or module.startswith(r + ".") for r in roots)


@pytest.mark.parametrize("path", files(), ids=lambda p: str(p.relative_to(SRC)))
def test_each_heavy_dependency_has_one_home(path):
    rel = path.relative_to(SRC).parts
    found = imports(path)
    if rel[0] != "cad":
        assert not [m for m in found if _under(m, "cadquery", "OCP")], "CadQuery/OCP only under cad/"
    if rel[0] != "sweep":
        assert not [m for m in found if _under(m, "fcl")], "python-fcl only under sweep/"


@pytest.mark.parametrize("path", files("cad"), ids=lambda p: str(p.relative_to(SRC)))
def test_cad_never_imports_a_mechanism_or_the_sweep(path):
    bad = [m for m in imports(path) if _under(m, "gearcheck.mechanisms", "gearcheck.sweep", "gearcheck.cli")]
    assert not bad


@pytest.mark.parametrize("path", files("sweep"), ids=lambda p: str(p.relative_to(SRC)))
def test_sweep_never_imports_params_mechanisms_or_the_cli(path):
    bad = [m for m in imports(path) if _under(m, "gearcheck.params", "gearcheck.mechanisms", "gearcheck.cli",
                                               "gearcheck.cad")]
    assert not bad


@pytest.mark.parametrize("path", files(), ids=lambda p: str(p.relative_to(SRC)))
def test_only_the_cli_prints(path):
    if path.name == "cli.py":
        return
    tree = ast.parse(path.read_text(encoding="utf-8"))
    calls = [n for n in ast.walk(tree) if isinstance(n, ast.Call) and getattr(n.func, "id", None) == "print"]
    assert not calls, f"print() at lines {[c.lineno for c in calls]}: log through logging.getLogger('gearcheck')"


def test_no_source_module_is_a_monolith():
    long = {str(p.relative_to(SRC)): n for p in files() if (n := len(p.read_text().splitlines())) > 620}
    assert not long


def test_import_gearcheck_loads_neither_cadquery_nor_fcl():
    code = ("import sys, gearcheck\n"
            "d = gearcheck.load('templates/eod_track_drive.toml', overrides={'track_plate.tip_gap_mm': 0.8})\n"
            "d.calc().to_dict()\n"
            "bad = [m for m in ('cadquery', 'OCP', 'fcl', 'trimesh', 'matplotlib') if m in sys.modules]\n"
            "assert not bad, bad\n")
    subprocess.run([sys.executable, "-c", code], check=True, cwd=SRC.parents[1])
