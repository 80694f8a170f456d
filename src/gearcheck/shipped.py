"""The templates and studies shipped in the package: the lines ``gearcheck templates`` lists,
and their copy into a folder of the user's (``--copy DIR``) with the STEP files they name and
the JSON Schemas they point at."""

from __future__ import annotations

import shutil
from pathlib import Path


def listing() -> list[str]:
    """A line per shipped template (file, mechanism, title) and per shipped study, each group
    closed by a line saying how to use it."""
    from gearcheck.design import load_template, packaged_templates
    from gearcheck.studies.spec import load_spec, packaged_studies

    shipped = sorted(packaged_templates().glob("*.toml"))
    lines = []
    for path in shipped:
        design = load_template(path)
        lines.append(f"{path.name:32s} {design.mechanism:13s} {design.impl.title}")
    lines.append(f"({len(shipped)} templates in {packaged_templates()}; copy them with --copy DIR; "
                 "their JSON Schemas: gearcheck schema MECHANISM)")
    studies = sorted(packaged_studies().glob("*.toml"))
    for path in studies:
        spec = load_spec(path)
        lines.append(f"{path.stem:32s} {'study':13s} {spec.title} (template {spec.template})")
    lines.append(f"({len(studies)} studies; run one with `gearcheck study NAME`)")
    return lines


def copy_to(target: Path) -> str:
    """Copy the shipped templates into ``target`` (made if missing), the STEP files they name
    beside them and their schemas into ``target/schema``; a file there that differs from the
    shipped one is never overwritten (OutputError, nothing copied). The line that says so."""
    from gearcheck.design import packaged_templates
    from gearcheck.output import OutputError, ensure_out_dir
    from gearcheck.schema import SCHEMA_FOLDER

    shipped = sorted(packaged_templates().glob("*.toml"))
    schemas = sorted((packaged_templates() / SCHEMA_FOLDER).glob("*.json"))
    folder = ensure_out_dir(target, "--copy")
    files = sorted(packaged_templates().glob("*.step"))  # the CAD an assembly template names, beside it
    copies = [(p, folder / p.name) for p in [*shipped, *files]] + [(p, folder / SCHEMA_FOLDER / p.name)
                                                                   for p in schemas]
    for path, dest in copies:
        if dest.exists() and dest.read_bytes() != path.read_bytes():
            raise OutputError(dest, "exists and differs from the shipped file (not overwritten)")
    for path, dest in copies:
        dest.parent.mkdir(exist_ok=True)
        shutil.copyfile(path, dest)
    return (f"copied {len(shipped)} templates to {folder}/ (the STEP files they name beside them, their schemas to "
            f"{folder / SCHEMA_FOLDER}/)")
