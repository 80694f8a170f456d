"""The exact model over temperature: cycle-minimum play per side at any temperature and shim,
where on the flanks the least play is decided, the range checks and the onset of binding.

Numpy only (no meshes): the exact-flank contact of :func:`gearcheck.geometry.bevel_play.big_gear_contacts`
(analytic spherical involutes, vectorised over many poses at once) on the thermal state of
:mod:`.thermal` at each temperature, at the same drive angles as the mesh sweep (:data:`ANGLES_PER_CYCLE`
over the play period, :func:`gearcheck.geometry.bevel_mesh.play_period`). At each pose the four
big/small pairs are grouped by congruence (the other output shaft's meshes are the same meshes,
checked on the poses), so only the distinct ones are solved.

Temperatures: ``thermal_state(params, cold_C=T)`` is the state at T from the warm (built) state,
for T below or above warm_C alike; at warm_C it is the built assembly itself.

The least play over a range. Every displacement of the thermal chain is linear in T, each contact
turn is nearly linear in the displacement, and the play is a minimum (plus side) minus a maximum
(minus side) of such turns: a concave, piecewise nearly linear function of T. Its least over a
range is then at one of the range's ends, and it crosses zero at most once on either side of its
top. The check evaluates it on a grid in steps of at most :data:`GRID_STEP_K` (the range ends and
the design points exactly) and does not rely on this; ``calc`` evaluates the key temperatures only
and does. A crossing (the onset of binding) is solved on the exact model itself (to :data:`ONSET_TOL_K`,
proven by a sign change of the exact play either side of it), not interpolated.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from gearcheck.geometry import bevel_play as bp
from gearcheck.geometry.bevel import BevelGearSpec
from gearcheck.geometry.bevel_contact import rigid_inverse
from gearcheck.geometry.bevel_mesh import congruent, drive_poses, play_period
from gearcheck.geometry.bevel_tca import tooth_coordinates
from gearcheck.mechanisms.differential.poses import GearSpecs, assembly_poses, gear_specs
from gearcheck.mechanisms.differential.thermal import BIG_GEARS, SMALL_GEARS, thermal_state
from gearcheck.sweep.certify import Refined, rate_bound, refine_least_many

# Drive angles over one period of the output shafts' play (the mesh sweep uses the same).
ANGLES_PER_CYCLE = 12
# Largest step of the temperature grid over the operating and storage ranges (K).
GRID_STEP_K = 5.0
# The onset of binding is solved to this (K), in at most this many steps.
ONSET_TOL_K = 0.02
ONSET_ITERATIONS = 30
# Plays closer to zero than this (arcmin) count as zero clearance (the exact model resolves ~1e-4′).
ZERO_PLAY_ARCMIN = 1e-6
DIRECTIONS = (1, -1)
# The states the mesh sweep measures: warm (the built state), the cold design point, the operating
# range's ends and the storage minimum (the coldest the gears get).
MESHED_STATES = ("warm", "cold", "operating_min", "operating_max", "storage_min")
# the meshed states whose play verdicts can fail a design: the mesh must resolve their plays
MESH_DECIDED_STATES = ("warm", "cold", "operating_min", "operating_max")
STATE_TEXT = {"warm": "warm", "cold": "cold design point", "operating_min": "operating min",
              "operating_max": "operating max", "storage_min": "storage min", "storage_max": "storage max"}


def shim_text(shim_mm: float) -> str:
    """A shim thickness as the reports print it: at least two decimals, three when it needs them
    (0.1 → '0.10', 0.056 → '0.056')."""
    text = f"{shim_mm:.3f}".rstrip("0")
    return text + "0" * max(0, 2 - len(text.split(".")[1]))


# --------------------------------------------------------------------------------------------
# Temperatures

def key_temperatures(params) -> dict[str, float]:
    """The template's named temperatures (°C)."""
    op = params.operating
    return {"warm": op.warm_C, "cold": op.cold_C, "operating_min": op.operating_min_C,
            "operating_max": op.operating_max_C, "storage_min": op.storage_min_C, "storage_max": op.storage_max_C}


def meshed_states(params) -> list[tuple[str, float]]:
    """(name, °C) of the states the mesh sweep measures, one per distinct temperature (the first
    name in :data:`MESHED_STATES` order wins: a cold design point at the operating minimum is
    "cold")."""
    keys = key_temperatures(params)
    out: list[tuple[str, float]] = []
    for name in MESHED_STATES:
        if all(not math.isclose(keys[name], t, abs_tol=1e-9) for _, t in out):
            out.append((name, float(keys[name])))
    return out


def temperature_grid(params) -> np.ndarray:
    """Sorted temperatures (°C) over the union of the operating and storage ranges and the design
    points, in equal steps of at most GRID_STEP_K, plus every named temperature exactly."""
    keys = key_temperatures(params)
    lo, hi = min(keys.values()), max(keys.values())
    n = max(1, math.ceil((hi - lo) / GRID_STEP_K - 1e-9))
    grid = np.linspace(lo, hi, n + 1)
    return _unique(np.concatenate([grid, list(keys.values())]))


def _unique(temps) -> np.ndarray:
    """Sorted, with values closer than 1e-9 K merged (a named temperature on the grid)."""
    out: list[float] = []
    for t in sorted(float(v) for v in temps):
        if not out or t - out[-1] > 1e-9:
            out.append(t)
    return np.array(out)


# --------------------------------------------------------------------------------------------
# The exact plays

def congruent_groups(placed: Mapping[str, bp.PlacedGear], big_spec: BevelGearSpec, small_spec: BevelGearSpec,
                     bigs: Sequence[str] = BIG_GEARS, smalls: Sequence[str] = SMALL_GEARS
                     ) -> tuple[list[tuple[str, str, list[tuple[str, str]]]], int]:
    """The big/small pairs at one pose grouped by congruence: one exact solve per distinct mesh. A
    pair congruent to one already listed (the other output shaft, by the assembly's symmetry)
    reuses that solve. Returns the groups (big, small, members) and how many pairs joined an
    earlier group."""
    groups: list[tuple[str, str, list[tuple[str, str]]]] = []
    relative: list[np.ndarray] = []  # each group's small frame → big frame
    reused = 0
    inverse = {big: rigid_inverse(placed[big].pose) for big in bigs}
    for big in bigs:
        for small in smalls:
            q = inverse[big] @ placed[small].pose
            for g, gq in zip(groups, relative, strict=True):
                same_scales = placed[g[0]].scale == placed[big].scale and placed[g[1]].scale == placed[small].scale
                if same_scales and congruent(gq, q, big_spec, small_spec, tol=1e-7):
                    g[2].append((big, small))
                    reused += 1
                    break
            else:
                groups.append((big, small, [(big, small)]))
                relative.append(q)
    return groups, reused


def placed_gears(specs: GearSpecs, poses: Mapping[str, np.ndarray], thermal) -> dict[str, bp.PlacedGear]:
    """The exact gears (pose about the apex, scale) in a thermal state."""
    return {n: bp.PlacedGear(specs.big if n in BIG_GEARS else specs.small,
                             thermal[n].cold_pose_about_origin(poses[n]), thermal[n].scale) for n in poses}


def cycle_angles(specs: GearSpecs, shim_mm: float,
                 angles_per_cycle: int = ANGLES_PER_CYCLE) -> tuple[np.ndarray, float]:
    """The drive angles the plays are taken at (over one play period) and that period (rad)."""
    built = assembly_poses(specs, shim_mm).as_dict()
    period = play_period(built, BIG_GEARS, SMALL_GEARS, specs.big, specs.small)
    return np.arange(angles_per_cycle) / angles_per_cycle * period, period


@dataclass(frozen=True)
class FlankSpot:
    """Where a contact point lies on one gear's tooth: cone distance from the apex (mm, unscaled
    design), its fraction of the face (0 toe … 1 heel) and the height (0 root cone … 1 tip cone,
    by polar angle)."""

    cone_mm: float
    along: float
    height: float


def flank_spot(gear: bp.PlacedGear, turn_rad: float, point) -> FlankSpot:
    """The contact point (world) in the coordinates of one gear's teeth (the big gear turned by
    ``turn_rad`` to its contact, the small gear as placed)."""
    return FlankSpot(*tooth_coordinates(gear, turn_rad, point))


@dataclass(frozen=True)
class ExactPlays:
    """Exact contact turns of each output shaft (big gear) at one shim over temperatures and drive
    angles: arrays (temperature, angle, big gear, small gear), radians, each small gear's mesh on
    its own; ``spots`` (temperature, plus/minus, big/small gear) where the least-play pose's two
    contacts lie, if asked for."""

    shim_mm: float
    temperatures_C: np.ndarray
    angles_rad: np.ndarray
    period_rad: float
    plus_rad: np.ndarray
    minus_rad: np.ndarray
    solves: int
    reused: int
    spots: list[list[list[FlankSpot]]] | None = field(default=None, compare=False)
    # (T,): the least play over the continuous cycle where refined (:func:`refined`: its bracket's lower end)
    lower_arcmin: np.ndarray | None = field(default=None, compare=False)

    @property
    def plus_arcmin(self) -> np.ndarray:
        """(T, angle, big): each way the big gear stops at the tighter of its two meshes."""
        return bp.arcmin(self.plus_rad.min(axis=3))

    @property
    def minus_arcmin(self) -> np.ndarray:
        return bp.arcmin(self.minus_rad.max(axis=3))

    @property
    def play_arcmin(self) -> np.ndarray:
        return self.plus_arcmin - self.minus_arcmin

    @property
    def sampled_least_arcmin(self) -> np.ndarray:
        """(T,): the least play per side at the cycle's drive angles, both output shafts."""
        return self.play_arcmin.min(axis=(1, 2))

    @property
    def least_arcmin(self) -> np.ndarray:
        """(T,): the least play per side over the cycle and both output shafts: over the continuous
        cycle where refined (:func:`refined`), else at its drive angles."""
        least = self.sampled_least_arcmin
        return least if self.lower_arcmin is None else np.fmin(least, self.lower_arcmin)

    @property
    def mean_arcmin(self) -> np.ndarray:
        """(T,): the play per side averaged over the cycle (both output shafts)."""
        return self.play_arcmin.mean(axis=(1, 2))


@dataclass(frozen=True)
class _Solved:
    """Per pose, big and small gear: each way's contact turn (rad) and the solve that gave it."""

    plus: np.ndarray
    minus: np.ndarray
    solved_by: np.ndarray
    bigs: list[bp.PlacedGear]
    smalls: list[bp.PlacedGear]
    contacts: dict[int, list]
    reused: int


def _solve(params, shim_mm: float, points: Sequence[tuple[float, float]], specs: GearSpecs) -> _Solved:
    """Every (°C, drive angle rad) of ``points`` solved in one vectorised batch, each distinct mesh
    once (congruent twins share it); RuntimeError where no contact lies within the model's reach."""
    built = assembly_poses(specs, shim_mm).as_dict()
    bigs: list[bp.PlacedGear] = []
    smalls: list[bp.PlacedGear] = []
    owners: list[list[tuple[int, int, int]]] = []
    thermals: dict[float, dict] = {}
    reused = 0
    for n, (temp, phi) in enumerate(points):
        if temp not in thermals:
            thermals[temp] = thermal_state(params, cold_C=float(temp), specs=specs, shim_mm=shim_mm)
        placed = placed_gears(specs, drive_poses(built, BIG_GEARS, SMALL_GEARS, specs.big, specs.small, float(phi)),
                              thermals[temp])
        groups, twins = congruent_groups(placed, specs.big, specs.small)
        reused += twins
        for big, small, members in groups:
            bigs.append(placed[big])
            smalls.append(placed[small])
            owners.append([(n, BIG_GEARS.index(b), SMALL_GEARS.index(s)) for b, s in members])
    contacts = dict(zip(DIRECTIONS, bp.big_gear_contacts_both(bigs, smalls), strict=True))
    shape = (len(points), len(BIG_GEARS), len(SMALL_GEARS))
    plus, minus, solved_by = np.empty(shape), np.empty(shape), np.empty(shape, dtype=int)
    for j, keys in enumerate(owners):
        for key in keys:
            plus[key] = contacts[1][j].angle_rad
            minus[key] = contacts[-1][j].angle_rad
            solved_by[key] = j
    return _Solved(plus, minus, solved_by, bigs, smalls, contacts, reused)


def exact_plays(params, shim_mm: float, temperatures_C, *, specs: GearSpecs | None = None,
                angles_per_cycle: int = ANGLES_PER_CYCLE, spots: bool = False,
                angles_rad: Sequence[float] | None = None) -> ExactPlays:
    """The exact plays at ``shim_mm`` (the big gears moved out by it) at each temperature (°C),
    over the cycle (or at the drive angles ``angles_rad`` only); ``spots``: also where the
    least-play pose's contacts lie."""
    specs = gear_specs(params) if specs is None else specs
    temps = np.atleast_1d(np.asarray(temperatures_C, dtype=float))
    angles, period = cycle_angles(specs, shim_mm, angles_per_cycle)
    if angles_rad is not None:
        angles = np.asarray(angles_rad, float)
    solved = _solve(params, shim_mm, [(float(t), float(phi)) for t in temps for phi in angles], specs)
    shape = (len(temps), len(angles), len(BIG_GEARS), len(SMALL_GEARS))
    plus, minus, solved_by = (a.reshape(shape) for a in (solved.plus, solved.minus, solved.solved_by))
    contacts, solve_big, solve_small, reused = solved.contacts, solved.bigs, solved.smalls, solved.reused
    out = ExactPlays(shim_mm, temps, angles, period, plus, minus, len(solve_big), reused)
    if not spots:
        return out
    where = []
    play = out.play_arcmin
    for i in range(len(temps)):
        k, b = (int(v) for v in np.unravel_index(np.argmin(play[i]), play[i].shape))
        per_way = []
        for d, s in ((1, int(np.argmin(plus[i, k, b]))), (-1, int(np.argmax(minus[i, k, b])))):
            j = solved_by[i, k, b, s]
            c = contacts[d][j]
            per_way.append([flank_spot(solve_big[j], c.angle_rad, c.point), flank_spot(solve_small[j], 0.0, c.point)])
        where.append(per_way)
    return ExactPlays(shim_mm, temps, angles, period, plus, minus, len(solve_big), reused, where)


def unsolved(shim_mm: float, temperature_C: float, angles_rad: np.ndarray, period_rad: float) -> ExactPlays:
    """A temperature the exact model could not solve (no contact within its reach): NaN plays."""
    shape = (1, len(angles_rad), len(BIG_GEARS), len(SMALL_GEARS))
    nan = FlankSpot(math.nan, math.nan, math.nan)
    return ExactPlays(shim_mm, np.array([temperature_C]), angles_rad, period_rad, np.full(shape, np.nan),
                      np.full(shape, np.nan), 0, 0, [[[nan, nan], [nan, nan]]])


def exact_plays_or_unsolved(params, shim_mm: float, temperatures_C, *, specs: GearSpecs | None = None,
                            angles_per_cycle: int = ANGLES_PER_CYCLE) -> ExactPlays:
    """:func:`exact_plays` with spots; a temperature the exact model cannot solve (no contact within
    its reach, e.g. a play of more than ±69′) gets NaN plays instead of stopping the others."""
    try:
        return exact_plays(params, shim_mm, temperatures_C, specs=specs, angles_per_cycle=angles_per_cycle, spots=True)
    except RuntimeError:
        specs = gear_specs(params) if specs is None else specs
        angles, period = cycle_angles(specs, shim_mm, angles_per_cycle)
        parts = []
        for t in np.atleast_1d(np.asarray(temperatures_C, dtype=float)):
            try:
                parts.append(exact_plays(params, shim_mm, [float(t)], specs=specs, angles_per_cycle=angles_per_cycle,
                                         spots=True))
            except RuntimeError:
                parts.append(unsolved(shim_mm, float(t), angles, period))
        return merge_plays(parts)


def least_play(params, shim_mm: float, temperature_C: float, *, specs: GearSpecs | None = None,
               angles_per_cycle: int = ANGLES_PER_CYCLE) -> float:
    """The exact least play per side (arcmin) at one temperature, at the cycle's drive angles (the
    calibration's reading of a measured least backlash; over the continuous cycle: :func:`refined`)."""
    return float(exact_plays(params, shim_mm, [temperature_C], specs=specs,
                             angles_per_cycle=angles_per_cycle).sampled_least_arcmin[0])


def onset(params, shim_mm: float, free_C: float, binding_C: float, *, free_play: float | None = None,
          binding_play: float | None = None, specs: GearSpecs | None = None,
          angles_per_cycle: int = ANGLES_PER_CYCLE) -> float:
    """The temperature (°C) between a free one and a binding one where the exact least play per
    side over the continuous cycle reaches zero (contact starts), to ±ONSET_TOL_K (:func:`_falsi`):
    solved on the plays at the cycle's drive angles (``free_play`` / ``binding_play``: at the ends,
    if known), then proven on the plays over the continuous cycle (:func:`refined`: a few hundredths
    of a kelvin away at most), solved on from there where the proof fails."""
    def sampled(temps: list[float]) -> np.ndarray:
        return exact_plays(params, shim_mm, temps, specs=specs, angles_per_cycle=angles_per_cycle).sampled_least_arcmin

    def continuous(temps: list[float]) -> np.ndarray:
        return refined(params, exact_plays(params, shim_mm, temps, specs=specs, angles_per_cycle=angles_per_cycle),
                       specs=specs).least_arcmin

    a, b = float(free_C), float(binding_C)
    way = 1.0 if b > a else -1.0  # from the free end toward the binding end
    try:
        t = _falsi(sampled, a, b, free_play, binding_play)
    except ValueError:  # the samples see no crossing: the continuous plays decide alone
        return _falsi(continuous, a, b, None, None)
    near, far = t - way * ONSET_TOL_K, t + way * ONSET_TOL_K
    f_near, f_far = (float(v) for v in continuous([near, far]))
    if f_near > 0.0 >= f_far:
        return t
    # the continuous root lies beyond the proof: solve on from the side that holds it
    return _falsi(continuous, a, near, None, f_near) if f_near <= 0.0 else _falsi(continuous, far, b, f_far, None)


def _falsi(plays, a: float, b: float, fa: float | None, fb: float | None) -> float:
    """Regula falsi on ``plays`` (temperatures → least plays) from a free ``a`` to a binding ``b``
    (their plays if known): a step (the play is piecewise nearly linear in T), then the plays at
    ONSET_TOL_K either side of it (one solve for both); a sign change there proves the root, else
    the bracket shrinks to the side that holds it and the step repeats."""
    free_C, binding_C = a, b
    fa = float(plays([a])[0]) if fa is None else fa
    fb = float(plays([b])[0]) if fb is None else fb
    if not (fa > 0.0 >= fb):
        raise ValueError(f"no onset between {free_C} °C ({fa:.4f}′) and {binding_C} °C ({fb:.4f}′)")
    way = 1.0 if b > a else -1.0  # from the free end toward the binding end
    for _ in range(ONSET_ITERATIONS):
        if abs(b - a) <= 2.0 * ONSET_TOL_K:
            return 0.5 * (a + b)
        t = a - fa * (b - a) / (fb - fa)
        t = min(max(t, min(a, b) + ONSET_TOL_K), max(a, b) - ONSET_TOL_K)
        near, far = t - way * ONSET_TOL_K, t + way * ONSET_TOL_K  # free side, binding side of t
        f_near, f_far = (float(v) for v in plays([near, far]))
        if f_near > 0.0 >= f_far:
            return t
        if f_near <= 0.0:  # the root lies on the free side of t
            b, fb = near, f_near
        else:  # f_far > 0: on the binding side
            a, fa = far, f_far
    raise RuntimeError(f"onset not found to {ONSET_TOL_K} K in {ONSET_ITERATIONS} steps ({a:.3f}…{b:.3f} °C)")


# --------------------------------------------------------------------------------------------
# The ranges

@dataclass(frozen=True)
class RangeCheck:
    """The exact least play per side over the template's temperatures at one shim: binding in the
    operating range fails, binding only in the storage range warns (with the temperature where
    contact starts and how deep the overlap gets at the storage minimum)."""

    shim_mm: float
    temperatures_C: np.ndarray
    least_arcmin: np.ndarray
    keys: dict[str, float]
    onsets_C: tuple[float, ...]  # where the least play crosses zero (contact starts), coldest first
    arc_radius_mm: float  # d1/2: plays as arcs on the big gear's outer pitch circle
    grid: bool  # the temperatures are the full grid (else the named ones only)
    plays: ExactPlays | None = field(default=None, compare=False)

    def least_between(self, lo: float, hi: float) -> tuple[float, float]:
        """The least play per side (arcmin) at the temperatures within [lo, hi], and where."""
        inside = ((self.temperatures_C >= lo - 1e-9) & (self.temperatures_C <= hi + 1e-9)
                  & np.isfinite(self.least_arcmin))
        if not inside.any():  # nothing the exact model could solve there
            return math.nan, math.nan
        i = int(np.flatnonzero(inside)[np.argmin(self.least_arcmin[inside])])
        return float(self.least_arcmin[i]), float(self.temperatures_C[i])

    @property
    def unsolved_C(self) -> list[float]:
        """Temperatures the exact model could not solve (no contact within its reach)."""
        return [float(t) for t, v in zip(self.temperatures_C, self.least_arcmin, strict=True) if not math.isfinite(v)]

    def at(self, name: str) -> float:
        """The least play per side at a named temperature."""
        i = int(np.argmin(np.abs(self.temperatures_C - self.keys[name])))
        return float(self.least_arcmin[i])

    @property
    def operating(self) -> tuple[float, float]:
        return self.least_between(self.keys["operating_min"], self.keys["operating_max"])

    @property
    def storage(self) -> tuple[float, float]:
        return self.least_between(self.keys["storage_min"], self.keys["storage_max"])

    @property
    def binds_operating(self) -> bool:
        return not self.operating[0] > 0.0  # binding, or not solved

    @property
    def binds_storage(self) -> bool:
        return not self.storage[0] > 0.0

    @property
    def level(self) -> str:
        return "fail" if self.binds_operating else "warn" if self.binds_storage else "pass"

    @property
    def cold_onset_C(self) -> float | None:
        """Cooling from warm, the temperature where contact starts (None: it does not within
        the temperatures checked)."""
        colder = [t for t in self.onsets_C if t < self.keys["warm"]]
        return max(colder) if colder else None

    @property
    def hot_onset_C(self) -> float | None:
        hotter = [t for t in self.onsets_C if t > self.keys["warm"]]
        return min(hotter) if hotter else None

    def depth_um(self, play_arcmin: float) -> float:
        """An overlap (negative play) as a depth in µm on d1/2 (0 when free)."""
        return max(0.0, -play_arcmin) / bp.ARCMIN_PER_RAD * self.arc_radius_mm * 1e3


def range_check(params, shim_mm: float, *, grid: bool = True, specs: GearSpecs | None = None,
                plays: ExactPlays | None = None, angles_per_cycle: int = ANGLES_PER_CYCLE,
                solved: Mapping[tuple[float, float], float] | None = None) -> RangeCheck:
    """The exact model over the operating and storage ranges at one shim: on the full grid
    (:func:`temperature_grid`), or at the named temperatures only (``grid=False``: concavity, see
    the module docstring), or on given ``plays``; each temperature's least play over the continuous
    cycle (:func:`refined`, unless the plays already are); every zero crossing between neighbouring
    temperatures solved on the exact model (those in ``solved`` already were: :func:`crossings`)."""
    specs = gear_specs(params) if specs is None else specs
    keys = key_temperatures(params)
    if plays is None:
        temps = temperature_grid(params) if grid else _unique(keys.values())
        plays = exact_plays(params, shim_mm, temps, specs=specs, angles_per_cycle=angles_per_cycle)
    if plays.lower_arcmin is None:  # each temperature's least over the continuous cycle
        plays = refined(params, plays, specs=specs)
    onsets = crossings(params, shim_mm, plays, specs=specs, angles_per_cycle=angles_per_cycle, solved=solved)
    return RangeCheck(shim_mm, plays.temperatures_C, plays.least_arcmin, keys, tuple(sorted(onsets.values())),
                      specs.big.outer_pitch_diameter_mm / 2.0, grid, plays)


def crossings(params, shim_mm: float, plays: ExactPlays, *, specs: GearSpecs | None = None,
              angles_per_cycle: int = ANGLES_PER_CYCLE, solved: Mapping[tuple[float, float], float] | None = None
              ) -> dict[tuple[float, float], float]:
    """Every zero crossing of the least play between neighbouring temperatures of ``plays``,
    solved on the exact model (:func:`onset`): (free °C, binding °C) → onset °C. ``solved``: the
    crossings already solved (by the tasks that computed those temperatures), taken as they are."""
    temps, least = plays.temperatures_C, plays.least_arcmin
    out: dict[tuple[float, float], float] = {}
    for i in range(len(temps) - 1):
        if not (np.isfinite(least[i]) and np.isfinite(least[i + 1])):
            continue
        if (least[i] > 0.0) != (least[i + 1] > 0.0):
            free, bind = (i, i + 1) if least[i] > 0.0 else (i + 1, i)
            key = (float(temps[free]), float(temps[bind]))
            known = None if solved is None else solved.get(key)
            # the ends solved again by onset itself (over the continuous cycle): the same root
            # whichever batch found the crossing
            out[key] = known if known is not None else onset(params, shim_mm, key[0], key[1], specs=specs,
                                                             angles_per_cycle=angles_per_cycle)
    return out


# --------------------------------------------------------------------------------------------
# The smallest clearance decided

def smallest_play(plays: Mapping[str, float]) -> tuple[str, float] | None:
    """Of the least plays per side the sweep decides on (name → arcmin, negative = overlap), the
    one nearest zero but not zero, by magnitude: (name, play); None if all are zero."""
    cands = [(abs(v), name, v) for name, v in plays.items() if abs(v) > ZERO_PLAY_ARCMIN]
    if not cands:
        return None
    _, name, v = min(cands)
    return name, v


def meshed_plays(params, shim_mm: float | None = None, *, specs: GearSpecs | None = None,
                 angles_per_cycle: int = ANGLES_PER_CYCLE) -> dict[str, float]:
    """The exact least play per side (arcmin) at each meshed state, at the template's shim."""
    shim = params.shim.thickness_mm if shim_mm is None else shim_mm
    states = meshed_states(params)
    plays = exact_plays(params, shim, [t for _, t in states], specs=specs, angles_per_cycle=angles_per_cycle)
    return {name: float(v) for (name, _), v in zip(states, plays.least_arcmin, strict=True)}


def merge_plays(parts: Sequence[ExactPlays]) -> ExactPlays:
    """Exact plays of one shim solved in chunks of temperatures, joined in temperature order."""
    parts = sorted(parts, key=lambda p: float(p.temperatures_C[0]))
    spots = None if any(p.spots is None for p in parts) else [s for p in parts for s in (p.spots or [])]
    lower = (None if any(p.lower_arcmin is None for p in parts)
             else np.concatenate([np.asarray(p.lower_arcmin) for p in parts]))
    return ExactPlays(parts[0].shim_mm, np.concatenate([p.temperatures_C for p in parts]), parts[0].angles_rad,
                      parts[0].period_rad, np.concatenate([p.plus_rad for p in parts]),
                      np.concatenate([p.minus_rad for p in parts]), sum(p.solves for p in parts),
                      sum(p.reused for p in parts), spots, lower)


# A least play is refined between the drive angles to a bracket below this (arcmin; printed: 0.001′).
REFINE_PRECISION_ARCMIN = 5e-4


def plays_at(params, shim_mm: float, points: Sequence[tuple[float, float]], *,
             specs: GearSpecs | None = None) -> np.ndarray:
    """The exact play per side at each (temperature °C, drive angle rad) of ``points``, the tighter
    output shaft's (arcmin), all solved in one vectorised batch (NaN for all where the model finds
    no contact within its reach)."""
    if not points:
        return np.full(0, np.nan)
    try:
        solved = _solve(params, shim_mm, points, gear_specs(params) if specs is None else specs)
    except RuntimeError:  # no contact within the model's reach somewhere
        return np.full(len(points), np.nan)
    return (bp.arcmin(solved.plus.min(axis=2)) - bp.arcmin(solved.minus.max(axis=2))).min(axis=1)


def refine_cycles(params, shim_mm: float, temperatures_C: Sequence[float], angles_rad, per_angle_arcmin,
                  period_rad: float, *, specs: GearSpecs | None = None) -> list[Refined]:
    """The least play at each temperature (and one shim) over the continuous cycle, from its plays
    at ``angles_rad`` (``per_angle_arcmin[i]``: the tighter output shaft's at each angle): refined
    between them on the exact model until each bracket is below :data:`REFINE_PRECISION_ARCMIN`
    (:func:`gearcheck.sweep.certify.refine_least_many`; each round's new points, every temperature's,
    solved in one batch by :func:`plays_at`)."""
    specs = gear_specs(params) if specs is None else specs
    temps = [float(t) for t in temperatures_C]

    def evaluate(asked: list[tuple[int, float]]) -> np.ndarray:
        return plays_at(params, shim_mm, [(temps[k], x) for k, x in asked], specs=specs)

    curves = [(angles_rad, per_angle_arcmin[i]) for i in range(len(temps))]
    return refine_least_many(curves, evaluate, period_rad, REFINE_PRECISION_ARCMIN)


def refined(params, plays: ExactPlays, *, specs: GearSpecs | None = None) -> ExactPlays:
    """``plays`` with the least play over the continuous cycle (``lower_arcmin``, :func:`refine_cycles`)
    wherever it can hold a range's least: the rate bound before refining (:func:`gearcheck.sweep.certify.rate_bound`)
    below its range's least sample plus the precision, or ≤ 0 with free samples (NaN elsewhere: the
    samples stand, their continuous least above the range's)."""
    per_angle = plays.play_arcmin.min(axis=2)  # (T, angle): the tighter output shaft
    temps = plays.temperatures_C
    sampled = per_angle.min(axis=1)
    solved = [i for i in range(len(temps)) if np.all(np.isfinite(per_angle[i]))]
    bound = {i: rate_bound(plays.angles_rad, per_angle[i], plays.period_rad) for i in solved}
    op = params.operating
    chosen = {i for i in solved if bound[i] <= 0.0 < sampled[i]}
    ranges = ((op.operating_min_C, op.operating_max_C), (op.storage_min_C, op.storage_max_C))
    for lo, hi in ranges:
        inside = [i for i in solved if lo - 1e-9 <= temps[i] <= hi + 1e-9]
        if inside:
            least = min(float(sampled[i]) for i in inside)
            chosen |= {i for i in inside if bound[i] < least + REFINE_PRECISION_ARCMIN}
    chosen |= {i for i in solved if not any(lo - 1e-9 <= temps[i] <= hi + 1e-9 for lo, hi in ranges)}
    order = sorted(chosen)
    lower = np.full(len(temps), np.nan)
    found = refine_cycles(params, plays.shim_mm, [temps[i] for i in order], plays.angles_rad, per_angle[order],
                          plays.period_rad, specs=specs)
    for i, r in zip(order, found, strict=True):
        lower[i] = r.lower
    return dataclasses.replace(plays, lower_arcmin=lower)
def clearance(specs: GearSpecs, shim_mm: float, plays: Mapping[str, float], temperatures: Mapping[str, float]):
    """The smallest non-zero least play per side the mesh sweep decides a failing verdict on
    (:func:`smallest_play` over the states of :data:`MESH_DECIDED_STATES`) as the arc it spans on
    the big gear's outer pitch circle (mm): the radius the check converts its mesh bound with, so
    the mesh-resolution rule reads bound ≤ play/10 in the verdicts' own terms. None when every
    play is zero. The storage minimum is meshed too, but storage binding only warns and its
    verdict rests on the exact model over the whole range (an overlap of a few µm there would
    otherwise ask for sub-µm meshes and take the evidence for the operating range off the mesh)."""
    from gearcheck.results import Clearance

    found = smallest_play({k: v for k, v in plays.items() if k in MESH_DECIDED_STATES})
    if found is None:
        return None
    name, play = found
    d1_half = specs.big.outer_pitch_diameter_mm / 2.0
    what = "overlap" if play < 0 else "play"
    return Clearance(abs(play) / bp.ARCMIN_PER_RAD * d1_half,
                     f"least {what} per side at shim {shim_text(shim_mm)} mm, {STATE_TEXT.get(name, name)} "
                     f"{temperatures[name]:g} °C (exact flanks, {play:.3f}′ on d1/2)")
