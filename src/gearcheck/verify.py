"""Verify a staged run before it is swapped in (numpy only): every file the manifest lists is
there with the size and sha256 it records, and nothing else is; the STEP ends with its ISO
10303-21 trailer; every STL re-reads as a closed (watertight) surface with the triangle count the
manifest records. A run that fails here never replaces the previous one.

Closed surfaces are counted on integers: the STL's corners become vertex numbers by a sort of
their coordinates' bit patterns (equal numbers exactly for equal coordinates), each edge one
integer key, and a sorted array of keys shows at once whether every edge occurs twice.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np

from gearcheck.output import RUN_MARKER

STEP_TRAILER = b"END-ISO-10303-21;"
MANIFEST = "manifest.json"


class RunIncomplete(Exception):
    """A staged run does not match its manifest (a write that was cut short, a missing file);
    ``file`` names the file at fault (or "" for the run as a whole)."""

    def __init__(self, message: str, file: str = ""):
        super().__init__(message)
        self.file = file


def file_record(path: Path) -> dict:
    data = Path(path).read_bytes()
    return {"bytes": len(data), "sha256": hashlib.sha256(data).hexdigest()}


def listing(folder: Path) -> dict[str, dict]:
    """``{file name: {bytes, sha256}}`` for every file of a run folder but the manifest."""
    return {p.name: file_record(p) for p in sorted(Path(folder).iterdir())
            if p.is_file() and p.name not in (MANIFEST, RUN_MARKER)}


def read_stl(path: Path) -> np.ndarray:
    """Binary STL → (triangles, 3, 3) float32 vertices; RunIncomplete if the file is cut short."""
    data = Path(path).read_bytes()
    if len(data) < 84:
        raise RunIncomplete(f"{len(data)} bytes, shorter than an STL header", path.name)
    count = int(np.frombuffer(data, "<u4", 1, 80)[0])
    if len(data) != 84 + 50 * count:
        raise RunIncomplete(f"{len(data)} bytes for {count} triangles (expected {84 + 50 * count})", path.name)
    record = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    return np.frombuffer(data, record, count, 84)["v"]


def occurs_twice(keys: np.ndarray) -> bool:
    """Whether every value of ``keys`` (integer edge keys) occurs exactly twice (vacuously true
    of none): sorted, the values pair up (k[0] = k[1], k[2] = k[3], …) and no pair's value
    repeats in the next pair."""
    if len(keys) % 2:
        return False
    k = np.sort(keys)
    return bool(np.all(k[0::2] == k[1::2]) and np.all(k[1:-1:2] != k[2::2]))


def vertex_index(points: np.ndarray) -> np.ndarray:
    """For (n, 3) float points, an index per point such that two points get the same index
    exactly when their coordinates are equal (−0.0 equals 0.0; NaN equals nothing, not even
    itself): a sort of the coordinates' bit patterns instead of a sort of rows of floats."""
    zero = np.zeros((), points.dtype)
    bits = (points + zero).view(np.uint32 if points.dtype == np.float32 else np.uint64)  # -0.0 + 0.0 = +0.0
    order = np.lexsort((bits[:, 2], bits[:, 1], bits[:, 0]))
    ranked = bits[order]
    new = np.empty(len(points), bool)
    new[:1] = True
    new[1:] = np.any(ranked[1:] != ranked[:-1], axis=1)
    nan = np.isnan(points).any(axis=1)[order]
    new |= nan  # NaN != NaN: every point with a NaN is a point of its own
    index = np.empty(len(points), np.int64)
    index[order] = np.cumsum(new) - 1
    return index


def stl_is_watertight(triangles: np.ndarray) -> bool:
    """Every undirected edge (vertices matched exactly) is shared by exactly two triangles."""
    if len(triangles) == 0:
        return False
    faces = vertex_index(np.ascontiguousarray(triangles).reshape(-1, 3)).reshape(-1, 3)
    n = np.int64(len(faces) * 3)
    tails = np.concatenate([faces[:, 0], faces[:, 1], faces[:, 2]])
    heads = np.concatenate([faces[:, 1], faces[:, 2], faces[:, 0]])
    return occurs_twice(np.minimum(tails, heads) * n + np.maximum(tails, heads))


def verify_run(folder: Path) -> dict:
    """Check a staged run against its manifest; returns the manifest. RunIncomplete otherwise."""
    folder = Path(folder)
    try:
        manifest = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise RunIncomplete(f"unreadable ({exc})", MANIFEST) from None
    listed = manifest.get("files", {})
    present = listing(folder)
    if set(listed) != set(present):
        missing, extra = sorted(set(listed) - set(present)), sorted(set(present) - set(listed))
        raise RunIncomplete(f"files differ from the manifest: missing {missing}, not listed {extra}")
    for name, record in listed.items():
        if present[name] != record:
            raise RunIncomplete(f"{present[name]['bytes']} bytes, sha256 {present[name]['sha256'][:12]}…, "
                                f"but the manifest records {record['bytes']} bytes, {record['sha256'][:12]}…", name)
    step = manifest.get("step", {}).get("file")
    if step:
        with open(folder / step, "rb") as fh:
            fh.seek(max(0, fh.seek(0, 2) - 256))
            if STEP_TRAILER not in fh.read():
                raise RunIncomplete(f"no {STEP_TRAILER.decode()} trailer: the file was cut short", step)
    for part in manifest.get("parts", []):
        name = part["stl"]["file"]
        triangles = read_stl(folder / name)
        if len(triangles) != part["triangles"]:
            raise RunIncomplete(f"{len(triangles)} triangles, the manifest records {part['triangles']}", name)
        if not stl_is_watertight(triangles):
            raise RunIncomplete("the mesh read back is not closed (watertight)", name)
    return manifest
