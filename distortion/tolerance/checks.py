"""Checks of a tolerance spec and of the arguments of a run that the spec reader
(:mod:`raytrace.tolerance.spec`) does not make: duplicate items, overlapping elements (named by
their items), limits that look like another unit, and the whole numbers of the API. Every
refusal is one line naming the file, the item and the fix.

"Looks like another unit" (:func:`unit_hint`) — the thresholds are where a value stops being a
plausible tolerance of its kind and becomes a plausible number in the neighbouring unit:

* lengths in mm (decenters TEDX/TEDY/TSDX/TSDY, thicknesses TTHI, runout TIRX/TIRY): ≥ 1 mm,
  which is 1000 µm (the bundled examples hold 0.01–0.05 mm);
* tilts in degrees (TETX/TETY/TSTX/TSTY): ≥ 1°, which would be 1 arcmin = 0.0167° typed in the
  wrong unit (the bundled examples hold 0.01–0.02°, i.e. 0.6–1.2 arcmin);
* index changes TIND: ≥ 0.05 (the bundled examples hold 0.0005);
* curvature changes TCUR, 1/mm: ≥ 0.01 /mm, a change of curvature of a 100 mm radius (the
  bundled example holds 2e-5 /mm for a plane surface).

Above these the value is still taken (a warning, :class:`distortion.errors.UnitWarning`) when the
lens traces; a sensitivity run whose item makes the lens untraceable is refused with the hint.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from raytrace.tolerance import ToleranceSpec, ToleranceSpecError
from raytrace.units import is_whole

from ..errors import UnitWarning

_LENGTH = ("TEDX", "TEDY", "TSDX", "TSDY", "TTHI", "TIRX", "TIRY")
_TILT = ("TETX", "TETY", "TSTX", "TSTY")
_KIND = {
    "TEDX": "a decenter", "TEDY": "a decenter", "TSDX": "a decenter", "TSDY": "a decenter",
    "TTHI": "a thickness change", "TIRX": "a runout", "TIRY": "a runout",
    "TETX": "a tilt", "TETY": "a tilt", "TSTX": "a tilt", "TSTY": "a tilt",
}  # fmt: skip
LENGTH_LARGE_MM = 1.0
TILT_LARGE_DEG = 1.0
TIND_LARGE = 0.05
TCUR_LARGE = 0.01
#: a pivot farther than this from the element (mm) is named in the hint
PIVOT_LARGE_MM = 1000.0
#: a yield limit below this many µm looks like millimetres (no production lens holds its
#: distortion to a micrometre; 0.5 typed for 0.5 mm would be 500 µm)
SMALL_LIMIT_UM = 1.0


class ToleranceInputError(ToleranceSpecError, ValueError):
    """A bad argument of a tolerance run (a whole number that is not one, a yield limit ≤ 0,
    ...): a :class:`ToleranceSpecError` (one line; the command line's exit status 2) and a
    :class:`ValueError`."""


def where_of(spec: ToleranceSpec, k: int) -> str:
    """``file: tolerances[N]`` (as the spec reader wrote it) of item ``k`` (0-based)."""
    it = spec.items[k]
    return it.where or f"{spec.path or 'tolerance spec'}: tolerances[{k + 1}]"


def split_where(where: str) -> tuple[str, str]:
    """(file, thing) of a ``where`` such as ``spec.toml: tolerances[3]``."""
    if ": " in where:
        a, b = where.rsplit(": ", 1)
        return a, b
    return "", where


def unit_hint(spec: ToleranceSpec, k: int) -> str:
    """A clause (``"20 mm is large for ..."``) when item ``k``'s limits look like another unit
    (module docstring), else ``""``."""
    it = spec.items[k]
    v = max(abs(it.min), abs(it.max))
    t = it.type
    if t in _LENGTH and v >= LENGTH_LARGE_MM:
        return (
            f"{v:g} mm is large for {_KIND[t]} and looks like micrometres typed as mm (the "
            f"unit is mm: {v:g} µm is {v / 1000:g} mm)"
        )
    if t in _TILT and v >= TILT_LARGE_DEG:
        return (
            f"{v:g}° is large for {_KIND[t]} and may be arcminutes or arcseconds (the unit is "
            f"degrees: {v:g} arcmin is {v / 60:.4g}°, {v:g} arcsec is {v / 3600:.3g}°)"
        )
    if t == "TIND" and v >= TIND_LARGE:
        return (
            f"an index change of {v:g} is far beyond a glass's index tolerance: TIND is the "
            "change of nd itself (e.g. 0.0005), not in units of 1e-4"
        )
    if t == "TCUR" and v >= TCUR_LARGE:
        return (
            f"TCUR is a change of curvature in 1/mm ({v:g}/mm is the curvature of a "
            f"{1 / v:.3g} mm radius); for a change of radius in mm use TRAD"
        )
    if t in ("TETX", "TETY") and abs(it.pivot) >= PIVOT_LARGE_MM:
        return f"the pivot {it.pivot:g} mm is far from the element (the unit is mm)"
    return ""


def warn_units(spec: ToleranceSpec, skip=()) -> None:
    """One :class:`UnitWarning` per item (not in ``skip``) whose limits look like another unit."""
    for k in range(spec.n_items):
        if k in skip:
            continue
        h = unit_hint(spec, k)
        if h:
            warnings.warn(
                UnitWarning(f"{where_of(spec, k)}: {spec.items[k].name}: {h}"), stacklevel=1
            )


def check_spec(spec: ToleranceSpec) -> None:
    """Refuse (ToleranceSpecError, one line) what the spec reader lets through: duplicate items
    (the same quantity drawn twice: its variance doubles), and elements that overlap without
    nesting (named by their items, which :mod:`raytrace.tolerance.model` does not)."""
    seen: dict[tuple, int] = {}
    for k, it in enumerate(spec.items):
        key = (it.type, it.surface, it.last, it.adjust, it.term,
               it.pivot if it.type in ("TETX", "TETY") else 0.0)  # fmt: skip
        if key in seen:
            j = seen[key]
            f, a = split_where(where_of(spec, j))
            _, b = split_where(where_of(spec, k))
            raise ToleranceSpecError(
                f"{f + ': ' if f else ''}{a} and {b} are the same tolerance ({it.name}): drawn "
                "twice, its variance would double; remove one, or merge them into one item "
                "with the limits you mean"
            )
        seen[key] = k
    groups: dict[tuple[int, int], int] = {}
    for k, it in enumerate(spec.items):
        if it.is_element:
            groups.setdefault((it.surface, it.last), k)
    keys = list(groups)
    for i, a in enumerate(keys):
        for b in keys[i + 1 :]:
            inter = not (a[1] < b[0] or b[1] < a[0])
            nested = (a[0] <= b[0] and b[1] <= a[1]) or (b[0] <= a[0] and a[1] <= b[1])
            if inter and not nested:
                f, wa = split_where(where_of(spec, groups[a]))
                _, wb = split_where(where_of(spec, groups[b]))
                raise ToleranceSpecError(
                    f"{f + ': ' if f else ''}{wa} (element {a[0]}-{a[1]}) and {wb} (element "
                    f"{b[0]}-{b[1]}) overlap without one containing the other; make the "
                    "elements disjoint or nested"
                )


def whole(value, name: str, minimum: int) -> int:
    """``value`` as an int when it is a whole number (an int or numpy integer, not a bool)
    ≥ ``minimum``; else :class:`ToleranceInputError` naming ``name``."""
    if not is_whole(value):
        raise ToleranceInputError(
            f"{name} must be a whole number ≥ {minimum} (an int), got {value!r}"
        )
    if int(value) < minimum:
        raise ToleranceInputError(f"{name} must be a whole number ≥ {minimum}, got {int(value)}")
    return int(value)


def check_yield_limit(
    limit_um, field_deg, where: str = "limit", *, warn: bool = True
) -> tuple[float, float]:
    """A yield limit (µm) and field (degrees): :class:`ToleranceInputError` unless both are
    finite, the limit > 0 and the field ≥ 0; a :class:`UnitWarning` (``warn``) when the limit
    is below 1 µm (it looks like millimetres)."""
    try:
        lim, deg = float(limit_um), float(field_deg)
    except (TypeError, ValueError):
        raise ToleranceInputError(
            f"{where} ({limit_um!r}, {field_deg!r}): give numbers, a limit in µm and a field in "
            "degrees"
        ) from None
    if not (math.isfinite(lim) and lim > 0.0):
        raise ToleranceInputError(
            f"{where} {limit_um!r} µm: the limit must be a positive number of µm"
        )
    if not (math.isfinite(deg) and deg >= 0.0):
        raise ToleranceInputError(f"{where} field {field_deg!r}: give an angle ≥ 0 in degrees")
    if warn and lim < SMALL_LIMIT_UM:
        warnings.warn(
            UnitWarning(
                f"yield limit {lim:g} µm at {deg:g}°: far below a micrometre; it looks like "
                f"millimetres (the limit is in µm: {lim:g} mm is {lim * 1000:g} µm)"
            ),
            stacklevel=3,
        )
    return lim, deg


def check_percentiles(levels, name: str = "percentiles") -> tuple[float, ...]:
    """The envelope levels ``levels`` (%) as a tuple of floats: :class:`ToleranceInputError`
    naming ``name`` unless they are one or more finite numbers from 0 to 100 (checked before a
    run, not by numpy after it)."""
    example = "e.g. (2.5, 50, 97.5)"
    try:
        vals = tuple(float(v) for v in np.asarray(levels, dtype=float).ravel())
    except (TypeError, ValueError):
        raise ToleranceInputError(
            f"{name} {levels!r}: give levels in % from 0 to 100, {example}"
        ) from None
    if not vals:
        raise ToleranceInputError(
            f"{name} (): give at least one level in % from 0 to 100, {example}"
        )
    bad = [v for v in vals if not (math.isfinite(v) and 0.0 <= v <= 100.0)]
    if bad:
        raise ToleranceInputError(
            f"{name} {vals!r}: {bad[0]:g} is not a level in % from 0 to 100; give levels "
            f"from 0 to 100, {example}"
        )
    return vals
