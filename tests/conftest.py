from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
TEMPLATES = ROOT / "templates"


@pytest.fixture(scope="session")
def templates_dir() -> Path:
    return TEMPLATES


@pytest.fixture(scope="session")
def build_bodies(tmp_path_factory):
    """Factory: build a template (with --set overrides), export it to a temp folder and return
    (loaded template, parts, sweep bodies); each distinct request is built once per session."""
    cache = {}

    def build(name: str, overrides: tuple[str, ...] = (), tol_mm: float = 0.01):
        key = (name, tuple(overrides), tol_mm)
        if key not in cache:
            from gearcheck.cad.export import export_parts, sweep_bodies
            from gearcheck.mechanisms import load_template

            loaded = load_template(TEMPLATES / f"{name}.toml", list(overrides))
            parts = loaded.parts_module.build_parts(loaded.params)
            out = tmp_path_factory.mktemp(name)
            _, exported = export_parts(parts, out, name=name, mechanism=loaded.mechanism,
                                       params_data=loaded.resolved_data, tol_mm=tol_mm)
            cache[key] = (loaded, parts, sweep_bodies(exported))
        return cache[key]

    return build
