"""The mechanism interface: what a mechanism implements once, and the registry that finds them.

A mechanism is one package with one class deriving from :class:`Mechanism`. Each hook does one
job, and data flows one way through them::

    Params ──analyse──▶ figures (calc)
       └──assembly──▶ Assembly (part specs, poses, motions: numpy)
                         └──parts──▶ solids (the only hook that touches gearcheck.cad)
                         └──plan(assembly, meshed bodies)──▶ SweepPlan (picklable tasks + reduce)
                                         └──reduce──▶ SweepOutcome ──verdicts──▶ [Verdict]
                                                                    └──report──▶ Report

:mod:`gearcheck.pipeline` runs them (build → mesh → sweep → resolution rule → exact
confirmation → files); the CLI, the Python API, the benchmarks and the tests call the pipeline.

Registration: the entry-point group ``gearcheck.mechanisms`` (``name = "package.module:Class"``
in a package's metadata; gearcheck's own three are declared in its pyproject.toml), or
:func:`register` at run time. Nothing else lists the mechanisms.
"""

from __future__ import annotations

import logging
from abc import ABC, abstractmethod
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from importlib.metadata import entry_points
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

if TYPE_CHECKING:  # type names only: importing a mechanism costs neither CadQuery nor FCL
    from pydantic import BaseModel

    from gearcheck.cad.placement import Part
    from gearcheck.figures import Figure
    from gearcheck.drafting import Draft, NewInput
    from gearcheck.results import Clearance, Report, SweepOutcome, Verdict
    from gearcheck.sweep.bodies import Body, MeshData
    from gearcheck.sweep.motion import Motion
    from gearcheck.sweep_budget import SweepCost

log = logging.getLogger("gearcheck")

ENTRY_POINT_GROUP = "gearcheck.mechanisms"


@dataclass(frozen=True)
class PartSpec:
    """One part of an assembly as data: which solid it is (``solid``: a key of
    :attr:`Assembly.solids`; copies share one key, so the solid is built and meshed once), its
    pose as built (4×4, frame → world), material, display colour, motion and the named
    sub-solids (features) the CAD hook builds with it for exact confirmations."""

    name: str
    solid: str
    material: str
    pose: np.ndarray
    color: tuple[float, float, float] = (0.7, 0.7, 0.75)
    motion: Motion | None = None
    features: tuple[str, ...] = ()


@dataclass(frozen=True)
class Assembly:
    """A mechanism's parts as data (numpy only): the part specs in build order, the geometry
    spec of each distinct solid (what the CAD hook builds from), and the mechanism's own layout
    (the numbers its sweep plan works from, derived from the parameters once, here)."""

    mechanism: str
    parts: tuple[PartSpec, ...]
    solids: Mapping[str, Any]
    layout: Any = None

    def __post_init__(self) -> None:
        names = [p.name for p in self.parts]
        if len(set(names)) != len(names):
            raise ValueError(f"part names must be unique: {names}")
        missing = sorted({p.solid for p in self.parts} - set(self.solids))
        if missing:
            raise ValueError(f"parts refer to solids with no spec: {missing}")

    def part(self, name: str) -> PartSpec:
        for p in self.parts:
            if p.name == name:
                return p
        raise KeyError(name)

    @property
    def names(self) -> list[str]:
        return [p.name for p in self.parts]


Task = tuple[Callable[..., Any], tuple]


@dataclass
class SweepPlan:
    """A sweep as data: the meshes every worker builds its scene from, the tasks (each a
    module-level function ``fn(scene, *args)`` and its picklable arguments: no CadQuery), the
    progress units of each task, and the reduce step that turns the task results (in task
    order) into a :class:`~gearcheck.results.SweepOutcome` in this process. ``order``, if given,
    is the order to run the tasks in (a permutation of their indices; results still come back in
    task order): tasks that use the same meshes next to each other, so that a worker taking a run
    of them builds only those meshes' BVHs. ``first``, if given, is work of the calling process's
    own, done while the workers start (e.g. the BVHs the reduce step will query). ``cost``, if
    given, is the sweep's predicted cost (:class:`gearcheck.sweep_budget.SweepCost`): the pipeline
    states it before the sweep and refuses a sweep over the budget."""

    meshes: list[MeshData]
    tasks: list[Task]
    reduce: Callable[[list], SweepOutcome]
    weights: list[int] | None = None
    unit: str = "pose"
    options: dict = field(default_factory=dict)
    order: list[int] | None = None
    first: Callable[[], Any] | None = None
    cost: SweepCost | None = None

    def __post_init__(self) -> None:
        if self.order is not None and sorted(self.order) != list(range(len(self.tasks))):
            raise ValueError("SweepPlan.order must be a permutation of the task indices")

    @property
    def total(self) -> int:
        return sum(self.weights) if self.weights is not None else len(self.tasks)


class Mechanism(ABC):
    """One mechanism, implemented once. Subclasses set the class attributes and the hooks."""

    #: registry name and the ``mechanism`` key of its templates
    name: ClassVar[str]
    #: the JSON section of calc --json and summary.json
    section: ClassVar[str]
    #: one line for --help and the docs
    title: ClassVar[str]
    #: the pydantic model of its template (every section but ``mechanism`` and ``name``)
    Params: ClassVar[type[BaseModel]]
    #: meshing tolerance when --tol is not given (fine enough for the template's clearances)
    mesh_tol_mm: ClassVar[float]
    #: the shipped template's file name (in templates/), if it has one
    template: ClassVar[str | None] = None
    #: calc figures documented as NaN when the model has no value
    nan_figures: ClassVar[frozenset[str]] = frozenset()
    #: verdicts that test gearcheck itself (mesh sweep vs an independent exact model): a random
    #: design may fail a design verdict, never one of these
    consistency_verdicts: ClassVar[tuple[str, ...]] = ("mesh_agrees_with_exact",)
    #: first seed of its random sets in `make fuzz` (disjoint streams: a set is reproducible alone)
    fuzz_seed_base: ClassVar[int] = 0
    #: the numbers ``gearcheck new`` takes for a design of this mechanism (:mod:`gearcheck.drafting`);
    #: empty: it offers no ``new``
    new_inputs: ClassVar[tuple[NewInput, ...]] = ()

    # -- numpy only ---------------------------------------------------------------------------
    @abstractmethod
    def analyse(self, params: Any) -> list[Figure]:
        """The analytical model: the figures ``calc`` prints (numpy only)."""

    @abstractmethod
    def assembly(self, params: Any) -> Assembly:
        """The parts as data: specs, poses as built, motions (numpy only)."""

    def smallest_clearance(self, params: Any) -> Clearance | None:
        """Before meshing: the smallest non-zero clearance (mm, its magnitude; a negative
        clearance — an overlap — counts by its depth) between two meshed parts that the sweep
        will decide a verdict on, from the exact model (numpy only). The mesh tolerance follows
        from it (the pair's mesh-error bound ≤ 1/10 of it, :mod:`gearcheck.resolution`). None:
        nothing to resolve (zero-backlash contact decided within a contact tolerance)."""
        return None

    def display_frames(self, params: Any, assembly: Assembly) -> tuple[list[Any], str]:
        """Key frames of the mechanism's motion for the report's 3D view and the GLB's animation
        (:class:`gearcheck.scene.PoseView` each: the moving parts' poses), and what they step
        through ("towing swing angle, °"); none by default (numpy only)."""
        return [], ""

    def tca(self, params: Any) -> Any:
        """Tooth contact analysis (numpy only): how the mechanism's gears run — transmission error
        and contact curves as arrays, in a mechanism's own objects. Optional: a mechanism without
        one raises :class:`NotImplementedError`."""
        raise NotImplementedError(f"{self.name}: no tooth contact analysis")

    # -- the CAD hook -------------------------------------------------------------------------
    @abstractmethod
    def parts(self, assembly: Assembly) -> list[Part]:
        """Solids for the part specs, in the order of ``assembly.parts``: calls
        :mod:`gearcheck.cad` with the specs (cad/ never imports a mechanism)."""

    # -- the sweep ----------------------------------------------------------------------------
    @abstractmethod
    def plan(self, params: Any, assembly: Assembly, bodies: Mapping[str, Body],
             options: Mapping[str, Any] | None = None) -> SweepPlan:
        """The sweep for the meshed bodies (keyed by part name, posed as ``assembly`` built
        them); ``options`` override sampling densities (tests, fuzz, studies)."""

    @abstractmethod
    def verdicts(self, params: Any, outcome: SweepOutcome) -> list[Verdict]:
        """Pass / warn / fail claims from the sweep's outcome (names unique)."""

    @abstractmethod
    def report(self, params: Any, outcome: SweepOutcome, verdicts: Sequence[Verdict]) -> Report:
        """Rows for sweep.csv, comparison rows, plots and notes for report.html."""

    # -- studies ------------------------------------------------------------------------------
    def study_row(self, params: Any, level: str) -> dict[str, float]:
        """One variant's figures for a study (numpy only, no CAD, no mesh): at level
        "analytical" the analytical model (default: every numeric ``calc`` figure), at level
        "exact" the exact model (default: none), at level "contact" the tooth contact analysis
        (default: none; run only for a study naming one of its figures). Keys are plain names;
        the study prefixes the level."""
        if level == "analytical":
            return {f.key: float(f.value) for f in self.analyse(params)
                    if isinstance(f.value, (int, float)) and not isinstance(f.value, bool)}
        return {}

    def study_batch(self, params: Any, columns: Mapping[str, np.ndarray]) -> dict[str, np.ndarray] | None:
        """The analytical level vectorised over many variants (optional): ``params`` the
        template's, ``columns`` the sampled fields (``section.key`` → one value per variant, all
        of them validated). Returns the same keys as ``study_row(..., "analytical")`` as arrays,
        or None to be evaluated variant by variant."""
        return None

    # -- a design from a few numbers -----------------------------------------------------------
    def new(self, inputs: Mapping[str, Any], overrides: Mapping[str, Any]) -> Draft:
        """A complete template from ``inputs`` (the numbers of :attr:`new_inputs` given, as the user
        gave them) and ``overrides`` ({"section.key": value}: inputs to the derivation where it uses
        them; :func:`gearcheck.drafting.draft` writes each into the template as given). Every dependent
        value derived by the mechanism's design method, each with a note saying how (numpy only).
        Raises :class:`gearcheck.params.common.ParamError` when the numbers admit no design."""
        raise NotImplementedError(f"{self.name}: no `new`")

    # -- fuzzing ------------------------------------------------------------------------------
    def sample(self, data: dict, draw: Any) -> None:
        """Redraw the knobs of a template body in place (``draw``: a
        :class:`gearcheck.mechanisms.sampling.Draw`). Default: no sampler."""
        raise NotImplementedError(f"{self.name}: no fuzz sampler")

    def fuzz_options(self, params: Any) -> dict:
        """Sweep options for a fuzzed design (cheaper sampling where a mechanism needs it)."""
        return {}


# ------------------------------------------------------------------------------------------
# A hook that raised


class HookError(Exception):
    """A mechanism's hook raised something other than a :class:`ParamError`: the mechanism, the
    hook and the error in one line (the command line: exit 3, the traceback under ``-v``; the
    original exception is the ``__cause__``)."""

    def __init__(self, mechanism: str, hook: str, error: BaseException):
        self.mechanism, self.hook, self.error = mechanism, hook, error
        text = " ".join(str(error).split()) or "(no message)"
        super().__init__(f"the {mechanism} mechanism's {hook} hook failed: {type(error).__name__}: {text}")


@contextmanager
def calling(mechanism: Mechanism | str, hook: str) -> Iterator[None]:
    """Run a mechanism's hook: bad input (:class:`ParamError`) and gearcheck's own errors pass
    through, anything else becomes a :class:`HookError` naming the mechanism and the hook."""
    from gearcheck.params import ParamError

    try:
        yield
    except (ParamError, HookError):
        raise
    except Exception as exc:
        if type(exc).__module__.startswith("gearcheck.") and type(exc).__name__ in _OWN_ERRORS:
            raise
        name = mechanism if isinstance(mechanism, str) else mechanism.name
        raise HookError(name, hook, exc) from exc


# gearcheck's own errors that pass through a hook unchanged (they say what happened already)
_OWN_ERRORS = frozenset({"WorkerError", "OutputError", "TooManyTriangles", "RunIncomplete"})


# ------------------------------------------------------------------------------------------
# Registry

_registered: dict[str, Mechanism] = {}
_entry_points: dict[str, Any] | None = None


def _discovered() -> dict[str, Any]:
    global _entry_points  # noqa: PLW0603 - read the installed metadata once per process
    if _entry_points is None:
        _entry_points = {ep.name: ep for ep in entry_points(group=ENTRY_POINT_GROUP)}
    return _entry_points


def register(mechanism: Mechanism | type[Mechanism]) -> Mechanism:
    """Add a mechanism at run time (a test's, a notebook's); returns the instance."""
    instance = mechanism() if isinstance(mechanism, type) else mechanism
    if not isinstance(instance, Mechanism):
        raise TypeError(f"{instance!r} is not a gearcheck Mechanism")
    _registered[instance.name] = instance
    return instance


def unregister(name: str) -> None:
    _registered.pop(name, None)


def names() -> list[str]:
    """Every known mechanism: installed entry points first (sorted), then run-time ones."""
    found = sorted(_discovered())
    return found + sorted(n for n in _registered if n not in found)


def get(name: str) -> Mechanism:
    """The mechanism called ``name`` (imports its package on first use). KeyError if unknown."""
    if name in _registered:
        return _registered[name]
    ep = _discovered().get(name)
    if ep is None:
        raise KeyError(name)
    cls = ep.load()
    instance = register(cls)
    if instance.name != name:
        raise ValueError(f"entry point {name!r} loads a mechanism named {instance.name!r}")
    return instance


def all_mechanisms() -> list[Mechanism]:
    return [get(n) for n in names()]
