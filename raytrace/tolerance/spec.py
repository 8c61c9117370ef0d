"""Tolerance specs: what may vary in a manufactured lens, by how much, with which distribution,
and which compensator is adjusted after assembly (docs/tolerance.md is the format's manual).

A spec is read from TOML (:func:`read_tolerance_spec`) or from the ``TOL`` lines of a Zemax
``.zmx`` file (:func:`raytrace.tolerance.zemax_tol.read_zmx_tolerances`); both give the same
:class:`ToleranceSpec`. Every item carries the meaning OpticStudio gives its tolerance operand
(OpticStudio manual, "Tolerancing", operand descriptions), so that a designer's tolerance table
carries over:

=======  ==================================================  ================================
type     what varies                                         unit of min / max
=======  ==================================================  ================================
TRAD     radius of ``surface``                               mm
TCUR     curvature of ``surface``                            1/mm
TFRN     power of ``surface`` in fringes at ``test_wavelength`` (Δsag at the semi-diameter =
         N λ/2)                                              fringes
TTHI     thickness after ``surface``; ``adjust`` (optional) takes the opposite change, so the
         surfaces after it do not move                       mm
TCON     conic constant of ``surface``                       —
TASP     even-asphere coefficient ``term`` (4, 6, 8, ...) of ``surface``       mm^(1−term)
TEDX/Y   decenter of the element ``surfaces = [first, last]``; the surfaces after it return
                                                             mm
TETX/Y   tilt of the element about x / y, about its front vertex, or about the point ``pivot``
         mm behind it on the axis; the surfaces after it return              degrees
TSDX/Y   decenter of one ``surface`` (the next surfaces return)              mm
TSTX/Y   tilt of one ``surface`` about its vertex (the next surfaces return) degrees
TIRX/Y   tilt of ``surface`` as total indicator runout over its clear diameter 2·sd: the
         surface turns by atan(TIR / 2 sd) about y (TIRX, runout along x) or x (TIRY)   mm
TIRR     irregularity in fringes at ``test_wavelength``: half spherical (ρ⁴), half astigmatism
         (ρ_y²) over the semi-diameter, Δsag = N λ/2 in all                  fringes
TIND     Δnd of the glass after ``surface``: n(λ) shifts by Δnd at every wavelength       —
TABB     ΔVd of that glass: n(λ) − nd scales by Vd/(Vd + ΔVd)                          —
=======  ==================================================  ================================

Distributions (per item, default the spec's ``distribution``): ``"normal"`` — mean at the middle
of [min, max], truncated at the limits, which lie ``sigma`` standard deviations away (default 2:
OpticStudio's default Monte Carlo statistics); ``"uniform"`` on [min, max]; ``"endpoints"`` —
min or max with probability ½ each.

Compensators (:data:`COMPENSATORS`; Pestrecov 1958 §V: where the image plane is changes the
distortion, so the choice is part of the spec): ``"paraxial-refocus"`` — the image plane at the
paraxial image of each instance (its centred part: decenters and tilts change the focus only in
second order); ``"best-focus"`` — the plane of least RMS spot radius of the axial object point's
rays; ``"fixed-sensor"`` — nothing is adjusted: the image plane is the surface after the last
thickness, which moves with the thickness changes (as in OpticStudio with no compensator).

Every error in a spec is a :class:`ToleranceSpecError`, one line naming the file (and line or
item) and the fix.
"""

from __future__ import annotations

import difflib
import math
import re
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from ..errors import OrthoscopeError
from ..files.text import read_capped

#: the item types and the kind of target they take
SURFACE_TYPES = ("TRAD", "TCUR", "TFRN", "TTHI", "TCON", "TASP", "TSDX", "TSDY", "TSTX", "TSTY",
                 "TIRX", "TIRY", "TIRR", "TIND", "TABB")  # fmt: skip
ELEMENT_TYPES = ("TEDX", "TEDY", "TETX", "TETY")
ITEM_TYPES = SURFACE_TYPES + ELEMENT_TYPES
#: unit of each item's min / max (for listings and JSON)
UNITS = {
    "TRAD": "mm", "TCUR": "1/mm", "TFRN": "fringes", "TTHI": "mm", "TCON": "", "TASP": "",
    "TSDX": "mm", "TSDY": "mm", "TSTX": "deg", "TSTY": "deg", "TIRX": "mm", "TIRY": "mm",
    "TIRR": "fringes", "TIND": "", "TABB": "", "TEDX": "mm", "TEDY": "mm", "TETX": "deg",
    "TETY": "deg",
}  # fmt: skip
DISTRIBUTIONS = ("normal", "uniform", "endpoints")
COMPENSATORS = ("paraxial-refocus", "best-focus", "fixed-sensor")
#: OpticStudio's default test wavelength for fringes (He-Ne), nm
DEFAULT_TEST_WAVELENGTH = 632.8
DEFAULT_SIGMA = 2.0

TOP_KEYS = ("name", "notes", "lens", "test_wavelength", "distribution", "sigma", "tolerances",
            "compensator", "outputs", "monte_carlo")  # fmt: skip
ITEM_KEYS = ("type", "surface", "surfaces", "adjust", "min", "max", "limit", "distribution",
             "sigma", "term", "pivot", "label")  # fmt: skip
COMPENSATOR_KEYS = ("type", "rings")
MC_KEYS = ("samples", "seed", "chunk")
#: the ``[outputs]`` keys (read by :mod:`distortion.tolerance`): the object plane s' of
#: Fraser & Shortis's g_ss' (mm, a length such as "2m", "inf", or an image scale "10x")
OUTPUT_KEYS = ("g_object_distance",)


class ToleranceSpecError(OrthoscopeError):
    """A tolerance spec is invalid: one line ``WHERE: WHAT; FIX``."""


@dataclass(frozen=True)
class ToleranceItem:
    """One toleranced quantity (module docstring for the types and units).

    Attributes
    ----------
    type : str
        One of :data:`ITEM_TYPES`.
    surface : int
        1-based surface (the first surface of an element for TEDX..TETY).
    last : int
        Last surface of an element (= ``surface`` for surface items).
    min, max : float
        The limits, in the item's unit (:data:`UNITS`); the nominal value is 0 change.
    distribution : str
        ``"normal"``, ``"uniform"`` or ``"endpoints"``.
    sigma : float
        For ``"normal"``: the limits are ``sigma`` standard deviations from the mean.
    adjust : int
        TTHI: 1-based surface whose thickness takes the opposite change (0: none).
    term : int
        TASP: the power of r (4, 6, 8, ...).
    pivot : float
        TETX/TETY: the tilt's centre, mm behind the element's front vertex on its axis.
    label : str
        Name shown in tables (default ``TYPE s`` or ``TYPE a-b``).
    where : str
        Where the item was written (``spec.toml, tolerances[3]``, ``lens.zmx:112``).
    """

    type: str
    surface: int
    last: int
    min: float
    max: float
    distribution: str = "normal"
    sigma: float = DEFAULT_SIGMA
    adjust: int = 0
    term: int = 0
    pivot: float = 0.0
    label: str = ""
    where: str = field(default="", compare=False)

    @property
    def is_element(self) -> bool:
        return self.type in ELEMENT_TYPES

    @property
    def unit(self) -> str:
        return UNITS[self.type]

    @property
    def name(self) -> str:
        """The item's label, or ``TYPE s`` / ``TYPE a-b``."""
        if self.label:
            return self.label
        if self.is_element:
            return f"{self.type} {self.surface}-{self.last}"
        if self.type == "TASP":
            return f"TASP {self.surface} A{self.term}"
        if self.type == "TTHI" and self.adjust:
            return f"TTHI {self.surface} (adj {self.adjust})"
        return f"{self.type} {self.surface}"

    @property
    def mean(self) -> float:
        """Mean of the item's distribution (the middle of [min, max])."""
        return 0.5 * (self.min + self.max)

    @property
    def std(self) -> float:
        """Standard deviation of the item's distribution (the truncated normal's, not σ)."""
        h = 0.5 * (self.max - self.min)
        if self.distribution == "uniform":
            return h / math.sqrt(3.0)
        if self.distribution == "endpoints":
            return h
        a = self.sigma
        phi = math.exp(-0.5 * a * a) / math.sqrt(2.0 * math.pi)
        mass = math.erf(a / math.sqrt(2.0))
        return (h / a) * math.sqrt(1.0 - 2.0 * a * phi / mass)


@dataclass(frozen=True)
class Compensator:
    """The adjustment made after assembly (module docstring): ``type`` one of
    :data:`COMPENSATORS`; ``rings`` the pupil rings of the best-focus bundle."""

    type: str = "paraxial-refocus"
    rings: int = 6


@dataclass(frozen=True)
class ToleranceSpec:
    """A tolerance spec (module docstring).

    Attributes
    ----------
    items : tuple of ToleranceItem
        In the order written: the order of the random draws of each instance.
    compensator : Compensator
    test_wavelength : float
        nm, for fringes (TFRN, TIRR).
    name, notes : str
    lens : str
        The lens the spec is for (bundled name or path), ``""`` when not stated.
    outputs : dict
        The ``[outputs]`` table as written (keys :data:`OUTPUT_KEYS`, read and checked against
        the lens by :mod:`distortion.tolerance`).
    monte_carlo : dict
        ``samples``, ``seed``, ``chunk`` defaults of a Monte Carlo run.
    path : str or None
        The file read.
    """

    items: tuple[ToleranceItem, ...]
    compensator: Compensator = Compensator()
    test_wavelength: float = DEFAULT_TEST_WAVELENGTH
    name: str = ""
    notes: str = ""
    lens: str = ""
    outputs: dict = field(default_factory=dict, compare=False)
    monte_carlo: dict = field(default_factory=dict, compare=False)
    path: str | None = field(default=None, compare=False)

    def __post_init__(self) -> None:
        if not self.items:
            raise ToleranceSpecError(
                f"{self.path or 'tolerance spec'}: no tolerances; give at least one item "
                '(e.g. { type = "TEDY", surfaces = [1, 2], limit = 0.02 })'
            )

    @property
    def n_items(self) -> int:
        return len(self.items)

    def names(self) -> list[str]:
        """Item labels, in order."""
        return [it.name for it in self.items]

    def with_compensator(self, type_: str) -> ToleranceSpec:
        """A copy with another compensator (one of :data:`COMPENSATORS`)."""
        _choice(type_, COMPENSATORS, "compensator", "the compensator")
        return replace(self, compensator=replace(self.compensator, type=type_))

    def __repr__(self) -> str:
        return (
            f"ToleranceSpec({self.name or self.path or 'unnamed'}: {len(self.items)} items, "
            f"compensator {self.compensator.type})"
        )


# ------------------------------------------------------------------------------ helpers
def _is_num(v) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def _is_int(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _near(word: str, choices) -> str:
    m = difflib.get_close_matches(str(word), list(choices), n=1, cutoff=0.6)
    return f"; did you mean {m[0]!r}?" if m else f"; use one of {', '.join(choices)}"


def _choice(v, choices, where: str, what: str) -> str:
    if not isinstance(v, str) or v not in choices:
        raise ToleranceSpecError(f"{where}: {what} {v!r} is not known{_near(str(v), choices)}")
    return v


def _keys(d: dict, allowed, where: str) -> None:
    for k in d:
        if k not in allowed:
            raise ToleranceSpecError(f"{where}: unknown key {k!r}{_near(k, allowed)}")


def make_item(
    type_: str,
    *,
    where: str,
    surface: int | None = None,
    surfaces: tuple[int, int] | None = None,
    lo: float,
    hi: float,
    distribution: str = "normal",
    sigma: float = DEFAULT_SIGMA,
    adjust: int = 0,
    term: int = 0,
    pivot: float = 0.0,
    label: str = "",
) -> ToleranceItem:
    """A checked :class:`ToleranceItem` (the one constructor the TOML and .zmx readers use);
    raises :class:`ToleranceSpecError` naming ``where``."""
    t = _choice(type_, ITEM_TYPES, where, "tolerance type")
    if t in ELEMENT_TYPES:
        if surfaces is None:
            if surface is None:
                raise ToleranceSpecError(
                    f"{where}: {t} moves an element: give surfaces = [first, last]"
                )
            surfaces = (surface, surface)
        a, b = surfaces
    else:
        if surfaces is not None:
            if surfaces[0] != surfaces[1]:
                raise ToleranceSpecError(
                    f"{where}: {t} applies to one surface: give surface = N, not a range"
                )
            surface = surfaces[0]
        if surface is None:
            raise ToleranceSpecError(f"{where}: {t} needs surface = N (1-based)")
        a = b = surface
    for s in (a, b):
        if not _is_int(s) or s < 1:
            raise ToleranceSpecError(f"{where}: surfaces are whole numbers from 1, got {s!r}")
    if b < a:
        raise ToleranceSpecError(f"{where}: surfaces = [{a}, {b}]: the last is before the first")
    if not (_is_num(lo) and _is_num(hi)):
        raise ToleranceSpecError(f"{where}: min and max must be finite numbers, got {lo!r}, {hi!r}")
    if not lo <= hi:
        raise ToleranceSpecError(f"{where}: min {lo:g} is above max {hi:g}; swap them")
    if lo == hi:
        raise ToleranceSpecError(
            f"{where}: min and max are both {lo:g}: nothing varies; widen the limits or remove "
            "the item"
        )
    d = _choice(distribution, DISTRIBUTIONS, where, "distribution")
    if not (_is_num(sigma) and sigma > 0.0):
        raise ToleranceSpecError(f"{where}: sigma must be a positive number, got {sigma!r}")
    if t == "TTHI":
        if not _is_int(adjust) or adjust < 0:
            raise ToleranceSpecError(
                f"{where}: adjust must be a surface number or 0, got {adjust!r}"
            )
        if adjust == a:
            adjust = 0
    elif adjust:
        raise ToleranceSpecError(f"{where}: only TTHI takes an adjust surface")
    if t == "TASP":
        if not _is_int(term) or term < 4 or term % 2:
            raise ToleranceSpecError(
                f"{where}: TASP needs term = 4, 6, 8, ... (the power of r of the coefficient), "
                f"got {term!r}"
            )
    elif term:
        raise ToleranceSpecError(f"{where}: only TASP takes a term")
    if t in ("TETX", "TETY"):
        if not _is_num(pivot):
            raise ToleranceSpecError(f"{where}: pivot must be a number of mm, got {pivot!r}")
    elif pivot:
        raise ToleranceSpecError(f"{where}: only TETX / TETY take a pivot")
    if not isinstance(label, str):
        raise ToleranceSpecError(f"{where}: label must be a string, got {label!r}")
    return ToleranceItem(t, int(a), int(b), float(lo), float(hi), d, float(sigma), int(adjust),
                         int(term), float(pivot), label, where)  # fmt: skip


def _item_from_table(d: Any, where: str, dist: str, sigma: float) -> ToleranceItem:
    if not isinstance(d, dict):
        raise ToleranceSpecError(f"{where}: an item is a table {{ type = ..., ... }}, got {d!r}")
    _keys(d, ITEM_KEYS, where)
    if "type" not in d:
        raise ToleranceSpecError(f"{where}: give the item's type (one of {', '.join(ITEM_TYPES)})")
    t = d["type"]
    if isinstance(t, str):
        t = t.upper()
    if "limit" in d:
        if "min" in d or "max" in d:
            raise ToleranceSpecError(f"{where}: give limit = L (±L) or min and max, not both")
        lim = d["limit"]
        if not (_is_num(lim) and lim > 0.0):
            raise ToleranceSpecError(f"{where}: limit must be a positive number, got {lim!r}")
        lo, hi = -float(lim), float(lim)
    else:
        if "min" not in d or "max" not in d:
            raise ToleranceSpecError(f"{where}: give limit = L (±L), or both min and max")
        lo, hi = d["min"], d["max"]
    surfaces = None
    if "surfaces" in d:
        s = d["surfaces"]
        if not (isinstance(s, list) and len(s) == 2):
            raise ToleranceSpecError(f"{where}: surfaces must be [first, last], got {s!r}")
        surfaces = (s[0], s[1])
    adj = d.get("adjust", 0)
    if t == "TTHI" and adj and not isinstance(adj, bool) and adj == d.get("surface"):
        # make_item reads adjust == surface as "no adjust" (as .zmx TTHI lines may write it); a
        # spec that writes it asks for something it would not get
        raise ToleranceSpecError(
            f"{where}: adjust = {adj} is the TTHI's own surface; adjust must name another surface "
            "(the thickness that takes the opposite change), or leave adjust out"
        )
    return make_item(
        t,
        where=where,
        surface=d.get("surface"),
        surfaces=surfaces,
        lo=lo,
        hi=hi,
        distribution=d.get("distribution", dist),
        sigma=d.get("sigma", sigma),
        adjust=d.get("adjust", 0),
        term=d.get("term", 0),
        pivot=d.get("pivot", 0.0),
        label=d.get("label", ""),
    )


def _compensator(v: Any, where: str) -> Compensator:
    if isinstance(v, str):
        return Compensator(_choice(v, COMPENSATORS, where, "compensator"))
    if not isinstance(v, dict):
        raise ToleranceSpecError(
            f"{where}: compensator must be a name ({', '.join(COMPENSATORS)}) or a table"
        )
    _keys(v, COMPENSATOR_KEYS, where)
    t = _choice(v.get("type", "paraxial-refocus"), COMPENSATORS, where, "compensator")
    rings = v.get("rings", 6)
    if not (_is_int(rings) and 1 <= rings <= 64):
        raise ToleranceSpecError(f"{where}: rings must be a whole number 1..64, got {rings!r}")
    return Compensator(t, rings)


def _monte_carlo(v: Any, where: str) -> dict:
    if not isinstance(v, dict):
        raise ToleranceSpecError(f"{where}: [monte_carlo] must be a table")
    _keys(v, MC_KEYS, where)
    for k in MC_KEYS:
        if k in v and not (_is_int(v[k]) and v[k] >= (0 if k == "seed" else 1)):
            raise ToleranceSpecError(
                f"{where}: {k} must be a whole number ≥ {0 if k == 'seed' else 1}"
            )
    return dict(v)


def spec_from_dict(d: dict, *, path: str | None = None) -> ToleranceSpec:
    """A :class:`ToleranceSpec` from the parsed TOML table ``d`` (the format of
    :func:`read_tolerance_spec`); ``path`` names it in messages."""
    where = path or "tolerance spec"
    _keys(d, TOP_KEYS, f"{where}: top level")
    for k in ("name", "notes", "lens"):
        if k in d and not isinstance(d[k], str):
            raise ToleranceSpecError(f"{where}: {k} must be a string, got {d[k]!r}")
    wl = d.get("test_wavelength", DEFAULT_TEST_WAVELENGTH)
    if not (_is_num(wl) and 100.0 <= wl <= 20000.0):
        raise ToleranceSpecError(
            f"{where}: test_wavelength must be in nm (100..20000), got {wl!r}; write 632.8 for "
            "He-Ne"
        )
    dist = _choice(d.get("distribution", "normal"), DISTRIBUTIONS, where, "distribution")
    sigma = d.get("sigma", DEFAULT_SIGMA)
    if not (_is_num(sigma) and sigma > 0.0):
        raise ToleranceSpecError(f"{where}: sigma must be a positive number, got {sigma!r}")
    raw = d.get("tolerances")
    if not isinstance(raw, list) or not raw:
        raise ToleranceSpecError(
            f"{where}: give tolerances = [ {{ type = ..., ... }}, ... ] (a non-empty list)"
        )
    items = tuple(
        _item_from_table(it, f"{where}: tolerances[{i}]", dist, sigma)
        for i, it in enumerate(raw, start=1)
    )
    comp = _compensator(d.get("compensator", "paraxial-refocus"), f"{where}: compensator")
    outputs = d.get("outputs", {})
    if not isinstance(outputs, dict):
        raise ToleranceSpecError(f"{where}: [outputs] must be a table")
    _keys(outputs, OUTPUT_KEYS, f"{where}: [outputs]")
    mc = _monte_carlo(d.get("monte_carlo", {}), f"{where}: [monte_carlo]")
    return ToleranceSpec(items, comp, float(wl), d.get("name", ""), d.get("notes", ""),
                         d.get("lens", ""), dict(outputs), mc, path)  # fmt: skip


def bundled_spec_dir() -> Path:
    """The folder of the bundled example specs (``lenses/tolerances/``)."""
    from ..files.library import library_dir

    return library_dir() / "tolerances"


def resolve_spec_path(path: str | Path) -> Path:
    """``path`` as given when it exists, has a folder or a suffix other than ``.toml``; else (a
    bare NAME or NAME.toml) the bundled example of that name (``lenses/tolerances/NAME.toml``)
    when there is one (:func:`raytrace.files.library.bundled_or_given`); else ``path``."""
    from ..files.library import bundled_or_given

    return bundled_or_given(path, "tolerances")


def read_tolerance_spec(path: str | Path) -> ToleranceSpec:
    """Read a TOML tolerance spec (docs/tolerance.md; examples in ``lenses/tolerances/``)::

        name = "production tolerances"
        lens = "topogon-like-pestrecov"
        test_wavelength = 632.8          # nm, for fringes
        distribution = "normal"          # default of every item (truncated at ±sigma σ)
        compensator = "paraxial-refocus"
        tolerances = [
          { type = "TFRN", surface = 1, limit = 2 },              # ±2 fringes
          { type = "TTHI", surface = 1, adjust = 2, limit = 0.02 },
          { type = "TEDY", surfaces = [1, 2], limit = 0.01 },
          { type = "TETX", surfaces = [1, 2], limit = 0.02, pivot = 0.0 },
          { type = "TIND", surface = 1, min = -0.0005, max = 0.0005, distribution = "uniform" },
        ]
        [outputs]                        # optional: g_object_distance = "10x" (g_ss' per lens)
        [monte_carlo]
        samples = 1000
        seed = 1

    A ``.zmx`` path reads the file's TOL lines instead
    (:func:`raytrace.tolerance.zemax_tol.read_zmx_tolerances`). A bare name that is not a file
    (no folder; with or without ``.toml``) is a bundled example, one per bundled lens and named
    like it (``read_tolerance_spec("topogon-like-pestrecov")``).

    Parameters
    ----------
    path : str or Path
        A TOML tolerance spec (UTF-8), a Zemax ``.zmx`` file, or the name of a bundled example.

    Returns
    -------
    ToleranceSpec

    Raises
    ------
    ToleranceSpecError
        One line, for anything wrong (a missing or unreadable file, text that is not UTF-8 or
        not TOML, a spec that does not parse).
    """
    p = resolve_spec_path(path)
    if p.suffix.lower() == ".zmx":
        from .zemax_tol import read_zmx_tolerances

        return read_zmx_tolerances(p)
    try:
        raw = read_capped(p)
    except FileNotFoundError:
        raise ToleranceSpecError(f"{p}: no such tolerance spec; check the path") from None
    except IsADirectoryError:
        raise ToleranceSpecError(f"{p}: is a folder; give a tolerance spec file (.toml)") from None
    except OSError as e:
        raise ToleranceSpecError(f"{p}: cannot read it: {e.strerror or e}") from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise ToleranceSpecError(f"{p}: not UTF-8 text; save the spec as UTF-8") from None
    try:
        d = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        msg = re.sub(r"\s+", " ", str(e)).strip()
        raise ToleranceSpecError(f"{p}: not valid TOML: {msg}; fix the syntax there") from None
    except RecursionError:
        raise ToleranceSpecError(f"{p}: nested too deeply to be a tolerance spec") from None
    return spec_from_dict(d, path=str(p))


def check_against_lens(spec: ToleranceSpec, lens) -> None:
    """Raise :class:`ToleranceSpecError` (one line, naming the item) when an item cannot apply
    to ``lens``: a surface that does not exist, a TRAD on a plane, fringes or runout on a surface
    without a semi-diameter, an index tolerance on air, an element that contains the stop's
    neighbour but not whole elements, ... The lens must be centred."""
    n = lens.n_surfaces
    j = lens.first_placed() if hasattr(lens, "first_placed") else None
    if j is not None or lens.has_mirrors or any(s.coordinate_break for s in lens.surfaces):
        raise ToleranceSpecError(
            f"{lens.name}: tolerancing needs a centred lens without mirrors or coordinate breaks "
            "(the perturbations are applied to the centred design); use lens.nominal()"
        )
    q = next((i for i, s in enumerate(lens.surfaces, start=1) if s.qtype is not None), None)
    if q is not None:
        raise ToleranceSpecError(
            f"{lens.name}: surface {q} is a Q-type (Forbes) asphere: tolerancing does not model "
            "Q-type surfaces (the perturbation model and the instance kernels hold spheres, "
            "conics and even aspheres)"
        )
    for it in spec.items:
        w = it.where or it.name
        for s in (it.surface, it.last, it.adjust):
            if s > n:
                raise ToleranceSpecError(
                    f"{w}: surface {s} does not exist ({lens.name} has {n} surfaces)"
                )
        srf = lens.surfaces[it.surface - 1]
        if it.type == "TRAD" and srf.curvature == 0.0:
            raise ToleranceSpecError(
                f"{w}: surface {it.surface} is plane: a radius tolerance is undefined; use TFRN "
                "(fringes) or TCUR (curvature)"
            )
        if it.type in ("TFRN", "TIRX", "TIRY", "TIRR") and not math.isfinite(srf.semi_diameter):
            raise ToleranceSpecError(
                f"{w}: {it.type} is measured over the clear aperture, but surface {it.surface} has "
                "no semi-diameter; give it one (sd) in the lens"
            )
        if it.type in ("TIND", "TABB"):
            m = srf.material
            if m.is_air:
                raise ToleranceSpecError(
                    f"{w}: the medium after surface {it.surface} is air; {it.type} applies to "
                    "the glass after a surface (the front surface of the element)"
                )
            if it.type == "TABB" and m.kind == "index":
                raise ToleranceSpecError(
                    f"{w}: surface {it.surface} is followed by a fixed index without dispersion; "
                    "an Abbe tolerance needs a glass (model or catalog)"
                )
        if it.type == "TTHI" and it.surface == n and it.adjust:
            raise ToleranceSpecError(f"{w}: the last thickness has no surface after it to adjust")
        if it.type == "TRAD":
            r = srf.radius
            if r + it.min == 0.0 or r + it.max == 0.0 or (r + it.min) * (r + it.max) < 0.0:
                raise ToleranceSpecError(
                    f"{w}: the radius {r:g} mm changes sign within [{it.min:g}, {it.max:g}] mm; "
                    "use TCUR or TFRN for a nearly flat surface"
                )
