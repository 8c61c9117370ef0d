"""Design specs: variables, pick-ups, operands with targets, glass and global-search settings.

A spec is usually read from a TOML file (:func:`read_spec`; the language is documented in
``docs/spec.md``, complete examples in ``lenses/specs/*.toml``). Every key is checked: an unknown
key or a value of the wrong type is an error that names where it is and, for a misspelt key, the
nearest valid one; all problems of a file are reported together, one line each.

See :mod:`raytrace.optimize.operands` for what each operand type computes.
"""

from __future__ import annotations

import difflib
import math
import numbers
import re
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..errors import OrthoscopeError, PrescriptionError
from ..files.text import read_capped
from ..lens import Lens
from ..units import is_whole

#: continuous variables (damped least squares) and the discrete ``glass`` substitution variable
CONTINUOUS_KINDS = (
    "curvature",
    "thickness",
    "index",
    "abbe",
    "conic",
    "A4",
    "A6",
    "A8",
    "A10",
)
VARIABLE_KINDS = CONTINUOUS_KINDS + ("glass",)
ASPHERIC_KINDS = ("A4", "A6", "A8", "A10")  # coefficients of r^4, r^6, r^8, r^10
PICKUP_KINDS = CONTINUOUS_KINDS + ("glass",)
INDEX_BOUNDS = (1.40, 2.05)  # glass-like bounds for index variables
ABBE_BOUNDS = (15.0, 100.0)  # glass-like bounds for Abbe-number variables

#: The operand types and the parameters each takes besides type / target / weight.
_OBJECT = ("object_distance", "object_s", "object_scale")
_CHIEF = ("field", "field_kind", "wavelength", *_OBJECT)
OPERAND_PARAMS: dict[str, tuple[str, ...]] = {
    "efl": ("wavelength", *_OBJECT),
    "m_e": ("wavelength", *_OBJECT),
    "HE0": ("wavelength", *_OBJECT),
    "HpE0p": ("wavelength", *_OBJECT),
    "distortion": (*_CHIEF, "plane"),
    "distortion_rel": (*_CHIEF, "plane"),
    "image_height": (*_CHIEF, "plane"),
    "distortion_slope": _CHIEF,
    "landing_angle": _CHIEF,
    "best_focus": ("field", "field_kind", "aperture", "wavelength", "drop_failed", *_OBJECT),
    "rms_spot": ("field", "field_kind", "aperture", "plane", "wavelength", "drop_failed", *_OBJECT),
    "ray_height": ("field", "field_kind", "pupil", "surface", "wavelength", *_OBJECT),
    "axial_color": ("wavelengths", *_OBJECT),
    "element_power": ("surface", "last", "wavelength"),
    "center_thickness": ("surface",),
    "edge_thickness": ("surface", "height"),
}
OPERAND_TYPES = tuple(OPERAND_PARAMS)
#: parameters an operand type cannot do without
OPERAND_REQUIRED: dict[str, tuple[str, ...]] = {
    "distortion": ("field",),
    "distortion_rel": ("field",),
    "image_height": ("field",),
    "distortion_slope": ("field",),
    "landing_angle": ("field",),
    "ray_height": ("surface",),
    "element_power": ("surface",),
    "center_thickness": ("surface",),
    "edge_thickness": ("surface", "height"),
}
#: every operand type may carry these instead of a target: it is then one-sided (a bound
#: operand, :attr:`Operand.bounded`), its residual the violation of ``min`` / ``max``
BOUND_KEYS = ("min", "max")
#: operands on the thickness after a ``surface``: they need a ``target`` or ``min`` / ``max``
THICKNESS_OPERANDS = ("center_thickness", "edge_thickness")
#: operands that name a lens ``surface`` (checked against the lens by ``check_spec``)
SURFACE_OPERANDS = (*THICKNESS_OPERANDS, "ray_height", "element_power")
#: optimization methods (:func:`raytrace.optimize.optimize`): damped least squares, or
#: minimax by sequential linear programming (:mod:`raytrace.optimize.minimax`)
METHODS = ("least_squares", "minimax")
PLANE_KEYS = ("s_prime", "from_last_vertex", "from_vertex", "defocus")

#: glass catalogs the substitution searches by default (``Misc``, crystals and plastics, only
#: when named)
DEFAULT_CATALOGS = ("Schott", "Ohara", "Hoya", "CDGM", "Hikari", "Sumita")
#: availability classes of catalog glasses, from the catalog's status (see
#: :func:`raytrace.optimize.glasses.availability`)
AVAILABILITY = ("current", "withdrawn", "legacy")


class SpecError(OrthoscopeError):
    """A design spec is invalid (unknown key or variable, wrong type, missing surface, ...)."""


@dataclass(frozen=True)
class GlassSettings:
    """Which real glasses a ``glass`` variable may take (the substitution pool).

    catalogs:
        vendor catalogs searched (names of :data:`raytrace.glass.CATALOGS`).
    availability:
        classes allowed (:data:`AVAILABILITY`): ``current`` (in the vendor's current catalog
        edition), ``withdrawn`` (only in the previous edition), ``legacy`` (only in the
        refractiveindex.info shelf of older glasses).
    nd, vd:
        closed windows (min, max) on the catalog's d-line index and Abbe number.
    glasses:
        an explicit list of glass names (a designer's preferred list): the pool is exactly
        these (looked up in ``catalogs``); the filters above still apply.
    neighbours:
        a substitution move replaces a glass by one of its ``neighbours`` nearest candidates
        on the glass map (glass-code distance, :func:`raytrace.glass.search_glass`).
    model_phase:
        first optimize each glass as a continuous nd/vd model glass inside the pool's window,
        then snap to the nearest real glasses (CODE V's glass fitting); otherwise substitute
        real glasses only.
    max_price:
        the cost class: the largest relative price the vendor prints
        (:attr:`raytrace.glass.CatalogGlass.price`: Schott N-BK7 = 1, CDGM H-K9L = 1). A finite
        value keeps only glasses with a printed price, i.e. of the Schott and CDGM catalogs.
    """

    catalogs: tuple[str, ...] = DEFAULT_CATALOGS
    availability: tuple[str, ...] = ("current",)
    nd: tuple[float, float] = (-math.inf, math.inf)
    vd: tuple[float, float] = (-math.inf, math.inf)
    glasses: tuple[str, ...] = ()
    neighbours: int = 6
    model_phase: bool = True
    max_price: float = math.inf

    def __post_init__(self) -> None:
        p = self.max_price  # the spec reader checks its [glass] keys; this guards the API
        if isinstance(p, bool) or not isinstance(p, numbers.Real) or not p > 0:
            raise SpecError(
                f"glass settings: max_price must be a positive number (a vendor's relative "
                f"price, N-BK7 = 1; inf: no limit), got {p!r}"
            )


@dataclass(frozen=True)
class SearchSettings:
    """Settings of the global search (:func:`raytrace.optimize.global_optimize`).

    starts:
        independent starts; start 0 is the spec's start lens, the others are perturbed copies.
    seed:
        root of the random streams (``numpy.random.SeedSequence(seed)``; start k uses child k).
    hops:
        basin hops per start: perturb the start's best design (and substitute one glass),
        re-optimize, keep it when the merit improves.
    perturbation, hop_perturbation:
        relative size of the start perturbation and of a hop's perturbation (a curvature moves by
        about ``p × (|c| + 0.1/|EFL|)``, a thickness by a factor ``exp(p N(0,1))``).
    time_budget_s:
        wall-clock budget in seconds (None: none); when spent the search stops and keeps the best.
    workers:
        worker processes (1: in this process).
    local_evaluations:
        merit evaluations per local damped-least-squares run (None: the spec's
        ``max_evaluations``); the best design is polished with ``max_evaluations`` at the end.
    """

    starts: int = 8
    seed: int = 0
    hops: int = 4
    perturbation: float = 0.1
    hop_perturbation: float = 0.05
    time_budget_s: float | None = None
    workers: int = 1
    local_evaluations: int | None = None


@dataclass(frozen=True)
class Variable:
    """A free parameter: ``kind`` of ``surface`` (1-based), within [lower, upper].

    ``kind = "glass"`` is the glass-substitution variable: the medium after ``surface`` is
    chosen among real catalog glasses (``glass``: this variable's pool settings, default the
    spec's); damped least squares holds it, the global search substitutes it.
    """

    kind: str
    surface: int
    lower: float = -math.inf
    upper: float = math.inf
    glass: GlassSettings | None = None


@dataclass(frozen=True)
class Pickup:
    """``kind`` of ``surface`` := factor × (``kind`` of ``source``) + offset, applied after the
    variables (e.g. ``R5 = −R4`` is curvature 5 = −1 × curvature 4). A ``glass`` pick-up copies
    the medium after ``source``."""

    kind: str
    surface: int
    source: int
    factor: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class Operand:
    """A target: ``type`` (see :mod:`.operands`), ``target``, ``weight`` and its parameters.

    An operand whose ``params`` hold ``min`` and/or ``max`` (in the operand's unit) is a
    *bound* operand (:attr:`bounded`): it has no target and contributes only when its value is
    outside [min, max]. Damped least squares squares its weighted violation with the other
    residuals; minimax (:mod:`.minimax`) makes it a constraint.
    """

    type: str
    target: float = 0.0
    weight: float = 1.0
    params: dict = field(default_factory=dict)

    @property
    def bounded(self) -> bool:
        """Whether the operand is one-sided (has ``min`` and/or ``max``), not a target."""
        return any(k in self.params for k in BOUND_KEYS)

    @property
    def limits(self) -> tuple[float, float]:
        """(min, max) of a bound operand (±inf where not given; (-inf, inf) for a target)."""
        return (
            float(self.params.get("min", -math.inf)),
            float(self.params.get("max", math.inf)),
        )

    def residual(self, value: float) -> float:
        """The weighted residual of ``value``: weight × (value − target), or for a bound
        operand weight × its violation (distance outside [min, max], 0 inside)."""
        if not self.bounded:
            return self.weight * (value - self.target)
        lo, hi = self.limits
        viol = (lo - value) if value < lo else ((value - hi) if value > hi else 0.0)
        return self.weight * viol

    def label(self) -> str:
        extra = ", ".join(f"{k}={v}" for k, v in self.params.items())
        return f"{self.type}({extra})" if extra else self.type


@dataclass(frozen=True)
class DesignSpec:
    """A reproducible design: start lens, variables, pick-ups, operands, solver settings, the
    glass pool and the global-search settings.

    ``method``: ``"least_squares"`` (damped least squares, the merit the sum of squared weighted
    residuals) or ``"minimax"`` (the merit the largest |weighted residual| of the target
    operands, the bound operands constraints; :mod:`.minimax`); ``penalty``: minimax's weight P
    of the constraint violations in its exact penalty max|r| + P × Σ violation.
    """

    start: str
    variables: tuple[Variable, ...]
    operands: tuple[Operand, ...]
    pickups: tuple[Pickup, ...] = ()
    name: str = ""
    max_evaluations: int = 2000
    tolerance: float = 1e-12
    merit_goal: float | None = None  # a run that ends above it is reported as failed
    path: str | None = None
    glass: GlassSettings = GlassSettings()
    search: SearchSettings = SearchSettings()
    method: str = "least_squares"
    penalty: float = 100.0

    def glass_settings(self, v: Variable) -> GlassSettings:
        """The pool settings of glass variable ``v`` (its own, else the spec's)."""
        return v.glass if v.glass is not None else self.glass


# ----------------------------------------------------------------------------- durations
_DURATION = re.compile(r"(\d+(?:\.\d*)?|\.\d+)\s*(h|m|min|s|sec)?", re.IGNORECASE)


def parse_duration(text: str | float | int) -> float:
    """A duration in seconds from ``"10m"``, ``"90s"``, ``"1h30m"``, ``"2.5h"`` or a number of
    seconds. Raises :class:`SpecError` for anything else or a duration that is not positive."""
    if isinstance(text, bool):
        raise SpecError(f"bad duration {text!r}: use e.g. 90s, 10m, 1h30m or seconds")
    if isinstance(text, (int, float)):
        v = float(text)
    else:
        t = str(text).strip().replace(" ", "")
        pos, v = 0, 0.0
        unit = {"h": 3600.0, "m": 60.0, "min": 60.0, "s": 1.0, "sec": 1.0, None: 1.0}
        while pos < len(t):
            m = _DURATION.match(t, pos)
            if not m or m.end() == pos:
                raise SpecError(f"bad duration {text!r}: use e.g. 90s, 10m, 1h30m or seconds")
            v += float(m.group(1)) * unit[m.group(2).lower() if m.group(2) else None]
            pos = m.end()
        if not t:
            raise SpecError("empty duration: use e.g. 90s, 10m, 1h30m or seconds")
    if not (math.isfinite(v) and v > 0):
        raise SpecError(f"bad duration {text!r}: it must be a positive time")
    return v


# ----------------------------------------------------------------------------- checking
class _Problems:
    """Collects one line per problem; raises them together."""

    def __init__(self, where: str) -> None:
        self.where = where
        self.lines: list[str] = []
        self.misspelt: list[tuple[str, str]] = []  # (where in the file, the key it meant)

    def add(self, msg: str) -> None:
        # a key reported as misspelt is not reported again as missing at the same place: the
        # fix of the first line is the fix of both
        if any(msg.startswith(f"{at}:") and f"'{key}'" in msg for at, key in self.misspelt):
            return
        self.lines.append(msg)

    def unknown_keys(self, d: dict, allowed, at: str) -> None:
        for k in d:
            if k not in allowed:
                self.add(f"{at}: unknown key {k!r}{suggest(k, allowed)}")
                near = difflib.get_close_matches(str(k), list(allowed), n=1, cutoff=0.6)
                if near and near[0] not in d:
                    self.misspelt.append((at, near[0]))

    def raise_if_any(self) -> None:
        if not self.lines:
            return
        if len(self.lines) == 1:
            raise SpecError(f"{self.where}: {self.lines[0]}")
        body = "\n".join(f"  {ln}" for ln in self.lines)
        raise SpecError(f"{self.where}: {len(self.lines)} problems:\n{body}")


def suggest(word: str, choices) -> str:
    """`` (did you mean 'x'?)`` for the nearest of ``choices``, or the list of choices."""
    choices = list(choices)
    near = difflib.get_close_matches(str(word), choices, n=1, cutoff=0.6)
    if near:
        return f" (did you mean {near[0]!r}?)"
    return f" (use one of: {', '.join(choices)})"


_is_int = is_whole  # numpy integers too, never a bool


def _is_num(v) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, bool)


def _num_or_inf(v) -> bool:
    return _is_num(v) or (isinstance(v, str) and v.strip().lower() in ("inf", "+inf", "-inf"))


def _as_float(v) -> float:
    return float(v) if not isinstance(v, str) else float(v.strip().lower())


def _same(v):
    return v


#: (test, words, conversion) of a setting's value, for :func:`_take`
_POSITIVE_INT = (lambda v: _is_int(v) and v >= 1, "a positive integer", _same)
_POSITIVE = (lambda v: _is_num(v) and v > 0, "a positive number", float)
_NON_NEGATIVE = (lambda v: _is_num(v) and v >= 0, "a non-negative number", float)
_BOOL = (lambda v: isinstance(v, bool), "true or false", _same)


def _int_at_least(lo: int) -> tuple:
    return (lambda v: _is_int(v) and v >= lo, f"an integer >= {lo}", _same)


def _take(d: dict, kinds: dict, kw: dict, probs: _Problems, at: str = "") -> None:
    """Each key of ``kinds`` that ``d`` holds into ``kw`` (converted) when its value passes the
    test, else the problem "``at``: 'key' must be <words>, got <value>" (no ``at``: top level)."""
    prefix = f"{at}: " if at else ""
    for k, (test, words, convert) in kinds.items():
        if k in d:
            if test(d[k]):
                kw[k] = convert(d[k])
            else:
                probs.add(f"{prefix}{k!r} must be {words}, got {d[k]!r}")


def _range(v) -> bool:
    return (
        isinstance(v, list)
        and len(v) == 2
        and all(_num_or_inf(x) for x in v)
        and _as_float(v[0]) <= _as_float(v[1])
    )


def operand_problems(
    type_: str, params: dict, target, weight, *, target_given: bool | None = None
) -> list[str]:
    """Problems of one operand (unknown type or keys, wrong types, a target mixed with bounds);
    empty when it is valid. ``target_given``: whether the spec wrote a ``target`` (None: read
    from the API, where a target other than 0 counts as given)."""
    out: list[str] = []
    if type_ not in OPERAND_PARAMS:
        return [f"unknown operand type {type_!r}{suggest(type_, OPERAND_TYPES)}"]
    allowed = OPERAND_PARAMS[type_] + BOUND_KEYS
    meant = set()  # keys a misspelling stood for: not reported again as missing
    for k in params:
        if k not in allowed:
            keys = ("type", "target", "weight", *allowed)
            out.append(f"unknown key {k!r} for operand {type_}" + suggest(k, keys))
            meant.update(difflib.get_close_matches(str(k), keys, n=1, cutoff=0.6))
    for k in OPERAND_REQUIRED.get(type_, ()):
        if k not in params and k not in meant:
            out.append(f"operand {type_} needs a {k!r}")
    if not _is_num(target):
        out.append(f"'target' must be a number, got {target!r}")
    if not (_is_num(weight) and math.isfinite(weight) and weight >= 0):
        out.append(f"'weight' must be a non-negative number, got {weight!r}")
    p = params
    if "field" in p and not (_is_num(p["field"]) and math.isfinite(p["field"])):
        out.append(f"'field' must be a number (degrees or mm), got {p['field']!r}")
    if "field_kind" in p and p["field_kind"] not in ("angle", "height"):
        out.append(f'\'field_kind\' must be "angle" or "height", got {p["field_kind"]!r}')
    if "surface" in p and not _is_int(p["surface"]):
        out.append(f"'surface' must be an integer (1-based), got {p['surface']!r}")
    if "last" in p and not (
        _is_int(p["last"]) and (not _is_int(p.get("surface")) or p["last"] >= p["surface"])
    ):
        out.append(
            f"'last' must be an integer surface number (1-based) not before 'surface', got "
            f"{p['last']!r}"
        )
    out += _bound_problems(type_, p, target, target_given)
    if "height" in p and not (_is_num(p["height"]) and p["height"] >= 0):
        out.append(f"'height' must be a non-negative number (mm), got {p['height']!r}")
    if "drop_failed" in p and not isinstance(p["drop_failed"], bool):
        out.append(f"'drop_failed' must be true or false, got {p['drop_failed']!r}")
    if "aperture" in p and not (_is_num(p["aperture"]) and 0 < p["aperture"] <= 1):
        out.append(
            f"'aperture' must be a fraction of the pupil radius in (0, 1], got {p['aperture']!r}"
        )
    if "pupil" in p:
        pp = p["pupil"]
        if not (
            (isinstance(pp, (list, tuple)) or type(pp).__name__ == "ndarray")  # API: an array
            and len(pp) == 2
            and all(_is_num(c) and math.isfinite(c) for c in pp)
            and math.hypot(*pp) <= 1.0 + 1e-12
        ):
            out.append(
                "'pupil' must be two numbers [px, py] inside the unit circle (fractions of the "
                f"entrance-pupil radius), got {pp!r}"
            )
    if "wavelength" in p and not (_is_num(p["wavelength"]) and p["wavelength"] > 0):
        out.append(f"'wavelength' must be a positive number (nm), got {p['wavelength']!r}")
    if "wavelengths" in p:
        w = p["wavelengths"]
        if not (isinstance(w, list) and len(w) == 2 and all(_is_num(x) and x > 0 for x in w)):
            out.append(f"'wavelengths' must be two positive numbers (nm), got {w!r}")
    given = [k for k in _OBJECT if k in p]
    if len(given) > 1:
        out.append(f"give the object one way, not {' and '.join(given)}")
    if "object_distance" in p:
        v = p["object_distance"]
        ok = (_is_num(v) and v > 0) or (
            isinstance(v, str) and re.fullmatch(r"\s*(inf|[0-9.]+\s*[xX×])\s*", v) is not None
        )
        if not ok:
            out.append(
                f"'object_distance' must be a positive number (mm from the first vertex), "
                f'"inf" or "Nx", got {v!r}'
            )
    if "object_s" in p and not (_is_num(p["object_s"]) and p["object_s"] != 0):
        out.append(f"'object_s' must be a non-zero number (mm from H), got {p['object_s']!r}")
    if "object_scale" in p and not (_is_num(p["object_scale"]) and p["object_scale"] > 0):
        out.append(f"'object_scale' must be a positive number, got {p['object_scale']!r}")
    if "plane" in p:
        out += plane_problems(p["plane"], allow_best=type_ == "rms_spot")
    return out


def _bound_problems(type_: str, p: dict, target, target_given: bool | None) -> list[str]:
    """Problems of an operand's ``min`` / ``max`` (numbers in the operand's unit, min ≤ max, no
    target beside them; a thickness operand needs a target or a bound)."""
    out: list[str] = []
    given = [k for k in BOUND_KEYS if k in p]
    for k in given:
        v = p[k]
        if not (_num_or_inf(v) and not math.isnan(_as_float(v))):
            out.append(f'{k!r} must be a number (in the operand\'s unit) or "inf", got {v!r}')
            return out
    if _as_float(p.get("min", 0.0)) == math.inf or _as_float(p.get("max", 0.0)) == -math.inf:
        out.append("'min' cannot be +inf nor 'max' -inf: leave the bound out instead")
    elif "min" in p and "max" in p and _as_float(p["min"]) > _as_float(p["max"]):
        out.append(f"'min' ({p['min']!r}) is above 'max' ({p['max']!r}): swap them")
    if target_given is None:
        target_given = _is_num(target) and target != 0
    if given and target_given:
        out.append(
            "give a 'target' (two-sided) or 'min' / 'max' (one-sided bound), not both: "
            "write the bound as its own operand"
        )
    if type_ in THICKNESS_OPERANDS and not given and target_given is False:
        out.append(f"operand {type_} needs a 'target' or 'min' and/or 'max'")
    return out


def plane_problems(plane, *, allow_best: bool = False) -> list[str]:
    """Problems of a spec ``plane`` value (see :func:`.operands.spec_plane`)."""
    names = ("gaussian", "file", "best") if allow_best else ("gaussian", "file")
    if isinstance(plane, str):
        if plane in names:
            return []
        return [
            f"plane {plane!r} is not one of {', '.join(map(repr, names))}{suggest(plane, names)}"
        ]
    if isinstance(plane, dict):
        if len(plane) != 1:
            return [
                f"plane {plane!r}: give exactly one of {', '.join(PLANE_KEYS[:1] + PLANE_KEYS[2:])}"
                " (mm)"
            ]
        ((k, v),) = plane.items()
        if k not in PLANE_KEYS:
            return [f"plane: unknown key {k!r}{suggest(k, PLANE_KEYS)}"]
        from .operands import spec_plane  # (operands imports this module)

        try:  # the value as ImagePlane reads it: mm, or a length with its unit ("50.5mm")
            spec_plane(plane)
        except SpecError as e:
            return [str(e)]
        return []
    return [
        f'plane {plane!r}: use "gaussian", "file" or a table {{ s_prime | from_last_vertex | '
        "defocus = mm }"
    ]


def _glass_settings(d: dict, base: GlassSettings, at: str, probs: _Problems) -> GlassSettings:
    """Glass pool settings from a table (the spec's ``[glass]`` or a glass variable's keys)."""
    from ..glass import CATALOGS

    kw: dict = {}
    if "catalogs" in d:
        c = d["catalogs"]
        if not (isinstance(c, list) and c and all(isinstance(x, str) for x in c)):
            probs.add(f"{at}: 'catalogs' must be a list of catalog names, got {c!r}")
        else:
            known = {x.lower(): x for x in CATALOGS}
            bad = [x for x in c if x.lower() not in known]
            for x in bad:
                probs.add(f"{at}: unknown glass catalog {x!r}{suggest(x, CATALOGS)}")
            if not bad:
                kw["catalogs"] = tuple(known[x.lower()] for x in c)
    if "availability" in d:
        a = d["availability"]
        if not (isinstance(a, list) and a and all(isinstance(x, str) for x in a)):
            probs.add(f"{at}: 'availability' must be a list of classes, got {a!r}")
        else:
            bad = [x for x in a if x not in AVAILABILITY]
            for x in bad:
                probs.add(f"{at}: unknown availability class {x!r}{suggest(x, AVAILABILITY)}")
            if not bad:
                kw["availability"] = tuple(a)
    for k in ("nd", "vd"):
        if k in d:
            if _range(d[k]):
                kw[k] = (_as_float(d[k][0]), _as_float(d[k][1]))
            else:
                probs.add(f"{at}: {k!r} must be a window [min, max], got {d[k]!r}")
    if "glasses" in d:
        g = d["glasses"]
        if not (isinstance(g, list) and g and all(isinstance(x, str) for x in g)):
            probs.add(f"{at}: 'glasses' must be a list of glass names, got {g!r}")
        else:
            kw["glasses"] = tuple(g)
    _take(
        d,
        {"neighbours": _POSITIVE_INT, "model_phase": _BOOL, "max_price": _POSITIVE},
        kw,
        probs,
        at,
    )
    return replace(base, **kw)


GLASS_KEYS = (
    "catalogs",
    "availability",
    "nd",
    "vd",
    "glasses",
    "neighbours",
    "model_phase",
    "max_price",
)
SEARCH_KEYS = (
    "starts",
    "seed",
    "hops",
    "perturbation",
    "hop_perturbation",
    "time",
    "workers",
    "local_evaluations",
)
TOP_KEYS = (
    "name",
    "start",
    "notes",
    "variables",
    "pickups",
    "operands",
    "max_evaluations",
    "tolerance",
    "merit_goal",
    "method",
    "penalty",
    "glass",
    "global",
)


def _search_settings(d: dict, at: str, probs: _Problems) -> SearchSettings:
    kw: dict = {}
    kinds = {
        "starts": _int_at_least(1),
        "seed": _int_at_least(0),
        "hops": _int_at_least(0),
        "workers": _int_at_least(1),
        "local_evaluations": _POSITIVE_INT,
        "perturbation": _NON_NEGATIVE,
        "hop_perturbation": _NON_NEGATIVE,
    }
    _take(d, kinds, kw, probs, at)
    if "time" in d:
        try:
            kw["time_budget_s"] = parse_duration(d["time"])
        except SpecError as e:
            probs.add(f"{at}: 'time': {e}")
    return SearchSettings(**kw)


def resolve_spec_path(path: str | Path) -> Path:
    """The file :func:`read_spec` reads for ``path``: ``path`` itself when it exists, has a
    folder or a suffix other than ``.toml``; else (a bare NAME or NAME.toml) the bundled
    ``lenses/specs/NAME.toml`` when there is one (:func:`raytrace.files.library.bundled_or_given`);
    else ``path``."""
    from ..files.library import bundled_or_given

    return bundled_or_given(path, "specs")


def read_spec(path: str | Path) -> DesignSpec:
    """Read a TOML design spec (the language: ``docs/spec.md``; examples: ``lenses/specs/``)::

        name = "my-design"
        start = "cooke-triplet-f4"        # bundled name or a path relative to the spec
        max_evaluations = 500
        merit_goal = 1e-6                 # optional: above it the run is a failure
        variables = [
          { kind = "curvature", surface = 1 },
          { kind = "thickness", surface = 2, min = 0.5, max = 12 },
          { kind = "glass", surface = 1, nd = [1.5, 1.7] },
        ]
        pickups = [ { kind = "curvature", surface = 6, source = 1, factor = -1 } ]
        operands = [
          { type = "efl", target = 50.0, weight = 10 },
          { type = "distortion", field = 20, target = 0.0, plane = "gaussian" },
        ]
        [glass]                            # the substitution pool of glass variables
        catalogs = ["Schott", "Ohara"]
        [global]                           # settings of the global search (optimize --global)
        starts = 16
        seed = 1
        time = "10m"

    Parameters
    ----------
    path : str or Path
        The spec file (UTF-8 TOML), or the name (with or without ``.toml``, no folder) of a
        bundled spec in ``lenses/specs/`` when no file of that name is here.

    Returns
    -------
    DesignSpec

    Raises
    ------
    SpecError
        Listing every problem (unknown keys with the nearest valid one, wrong types, missing
        keys), one line each; also a missing file, a folder, text that is not UTF-8 or not TOML.
    """
    p = resolve_spec_path(path)
    try:
        raw = read_capped(p)
        d = tomllib.loads(raw.decode("utf-8-sig"))  # a byte-order mark is no error
    except FileNotFoundError:
        raise SpecError(f"{p}: no such spec file") from None
    except IsADirectoryError:
        raise SpecError(f"{p}: is a folder, not a spec file") from None
    except OSError as e:
        raise SpecError(f"{p}: cannot read the spec: {e.strerror or e}") from None
    except UnicodeDecodeError:
        raise SpecError(f"{p}: not a UTF-8 text file") from None
    except tomllib.TOMLDecodeError as e:
        raise SpecError(f"{p}: {e}") from None
    except RecursionError:
        raise SpecError(f"{p}: nested too deeply to be a spec") from None
    probs = _Problems(str(p))
    probs.unknown_keys(d, TOP_KEYS, "top level")
    if "start" not in d or not isinstance(d["start"], str):
        probs.add("'start' (the start lens: bundled name or path) is required, as a string")
    for k in ("name", "notes"):
        if k in d and not isinstance(d[k], str):
            probs.add(f"{k!r} must be a string, got {d[k]!r}")
    top: dict = {}
    kinds = {
        "max_evaluations": _POSITIVE_INT,
        "tolerance": _POSITIVE,
        "merit_goal": _NON_NEGATIVE,
        "penalty": _POSITIVE,
    }
    _take(d, kinds, top, probs)
    if "method" in d:
        m = d["method"]
        if isinstance(m, str) and m in METHODS:
            top["method"] = m
        else:
            probs.add(
                f"'method' must be one of {', '.join(map(repr, METHODS))}, got {m!r}"
                + (suggest(m, METHODS) if isinstance(m, str) else "")
            )

    glass = GlassSettings()
    if "glass" in d:
        if isinstance(d["glass"], dict):
            probs.unknown_keys(d["glass"], GLASS_KEYS, "[glass]")
            glass = _glass_settings(d["glass"], glass, "[glass]", probs)
        else:
            probs.add("'glass' must be a table ([glass])")
    search = SearchSettings()
    if "global" in d:
        if isinstance(d["global"], dict):
            probs.unknown_keys(d["global"], SEARCH_KEYS, "[global]")
            search = _search_settings(d["global"], "[global]", probs)
        else:
            probs.add("'global' must be a table ([global])")

    variables = []
    for at, v in _tables(d, "variables", "{ kind = ..., surface = ... }", probs):
        kind = v.get("kind")
        if not isinstance(kind, str):
            probs.add(f"{at}: needs 'kind' (one of {', '.join(VARIABLE_KINDS)})")
            continue
        if kind not in VARIABLE_KINDS:
            probs.add(f"{at}: unknown variable kind {kind!r}{suggest(kind, VARIABLE_KINDS)}")
            continue
        allowed = ("kind", "surface") + (GLASS_KEYS if kind == "glass" else ("min", "max"))
        probs.unknown_keys(v, allowed, at)
        s = v.get("surface")
        if not _is_int(s):
            probs.add(f"{at}: 'surface' must be an integer (1-based), got {s!r}")
            continue
        lo, hi = v.get("min", -math.inf), v.get("max", math.inf)
        if not (_num_or_inf(lo) and _num_or_inf(hi)):
            probs.add(f"{at}: 'min' and 'max' must be numbers, got {lo!r}, {hi!r}")
            continue
        gs = None
        if kind == "glass":
            own = {k: v[k] for k in GLASS_KEYS if k in v}
            gs = _glass_settings(own, glass, at, probs) if own else None
        variables.append(Variable(kind, s, _as_float(lo), _as_float(hi), gs))

    pickups = []
    for at, v in _tables(d, "pickups", "{ kind, surface, source, factor, offset }", probs):
        probs.unknown_keys(v, ("kind", "surface", "source", "factor", "offset"), at)
        kind = v.get("kind")
        if not isinstance(kind, str) or kind not in PICKUP_KINDS:
            probs.add(f"{at}: unknown pick-up kind {kind!r}{suggest(str(kind), PICKUP_KINDS)}")
            continue
        if not (_is_int(v.get("surface")) and _is_int(v.get("source"))):
            probs.add(
                f"{at}: 'surface' and 'source' must be integers (1-based), got "
                f"{v.get('surface')!r}, {v.get('source')!r}"
            )
            continue
        f, o = v.get("factor", 1.0), v.get("offset", 0.0)
        if not (_is_num(f) and _is_num(o)):
            probs.add(f"{at}: 'factor' and 'offset' must be numbers, got {f!r}, {o!r}")
            continue
        if kind == "glass" and ("factor" in v or "offset" in v):
            probs.add(f"{at}: a glass pick-up copies the glass; it takes no factor or offset")
            continue
        pickups.append(Pickup(kind, v["surface"], v["source"], float(f), float(o)))

    operands = []
    for i, o in enumerate(_list(d, "operands", probs), 1):
        at = f"operands[{i}]"
        if not isinstance(o, dict) or not isinstance(o.get("type"), str):
            probs.add(f"{at}: needs 'type' (one of {', '.join(OPERAND_TYPES)})")
            continue
        t = o["type"]
        params = {k: v for k, v in o.items() if k not in ("type", "target", "weight")}
        target, weight = o.get("target", 0.0), o.get("weight", 1.0)
        bad = operand_problems(t, params, target, weight, target_given="target" in o)
        for b in bad:
            probs.add(f"{at} ({t}): {b}")
        if not bad:
            operands.append(Operand(t, float(target), float(weight), params))
    probs.raise_if_any()
    return DesignSpec(
        start=d["start"],
        variables=tuple(variables),
        operands=tuple(operands),
        pickups=tuple(pickups),
        name=str(d.get("name", p.stem)),
        path=str(p),
        glass=glass,
        search=search,
        **top,
    )


def _list(d: dict, key: str, probs: _Problems) -> list:
    v = d.get(key, [])
    if not isinstance(v, list):
        probs.add(f"{key!r} must be a list of tables, [ {{ ... }}, ... ]")
        return []
    return v


def _tables(d: dict, key: str, form: str, probs: _Problems):
    """(``key[i]``, entry) for each entry of the list ``d[key]`` that is a table; one that is not
    is a problem ("must be a table ``form``")."""
    for i, v in enumerate(_list(d, key, probs), 1):
        at = f"{key}[{i}]"
        if isinstance(v, dict):
            yield at, v
        else:
            probs.add(f"{at}: must be a table {form}")


def start_lens(spec: DesignSpec) -> Lens:
    """Load the spec's start lens (a path relative to the spec file, or a bundled name)."""
    from ..files.library import load_lens

    if spec.path is not None:
        cand = Path(spec.path).parent / spec.start
        if cand.is_file():
            return load_lens(str(cand))
    try:
        return load_lens(spec.start)
    except PrescriptionError as e:
        raise SpecError(f"start lens {spec.start!r}: {e}") from None


def evaluation_limit(spec: DesignSpec, max_evaluations: int | None) -> int:
    """The evaluation limit of a local run: ``max_evaluations`` (a whole number ≥ 1, checked
    here: SpecError naming it) or the spec's."""
    if max_evaluations is None:
        return spec.max_evaluations
    if not (_is_int(max_evaluations) and max_evaluations >= 1):
        raise SpecError(f"max_evaluations must be a whole number >= 1, got {max_evaluations!r}")
    return int(max_evaluations)
