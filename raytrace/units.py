"""Values with units, validated where they enter (CLI and API alike): lengths, wavelengths, image
scales. One parser, one set of messages (docs/design.md, "Vocabulary" and "Errors and files").

A number may carry a unit suffix wherever a unit could be doubted: ``"1.5m"``, ``"250mm"``,
``"25cm"``, ``"2in"`` for lengths; ``"587.6nm"``, ``"0.5876um"`` (or ``µm``) for wavelengths;
``"12x"`` for an image scale. A bare number means the documented default unit of the place it is
given (mm for lengths, nm for wavelengths) — except where the default is ambiguous, where the
caller asks for a suffix (``require_unit=True``) and a bare number is refused with a message that
shows how to write it. A value that looks like the other unit (a wavelength of 0.5876 "nm") is
refused with a message saying so.
"""

from __future__ import annotations

import math
import re

from .errors import OrthoscopeError


class UnitError(OrthoscopeError, ValueError):
    """A value with a unit is malformed, out of range, or looks like the wrong unit."""


#: mm per unit
LENGTH_UNITS = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "um": 1e-3, "µm": 1e-3, "in": 25.4}
#: nm per unit
WAVELENGTH_UNITS = {"nm": 1.0, "um": 1000.0, "µm": 1000.0, "mm": 1e6}

#: the range of wavelengths the project accepts (nm): deep UV to far IR
WAVELENGTH_RANGE_NM = (100.0, 30000.0)

#: what an ``object_distance`` may be (raytrace.paraxial.resolve_object_distance), for the
#: messages that refuse one
OBJECT_DISTANCE_FORMS = (
    "mm (or a length with its unit: 1.5m, 250mm), 'inf' or an image scale such as '12x'"
)

_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_RE = re.compile(rf"^\s*({_NUM}|[-+]?inf(?:inity)?)\s*([a-zA-Zµ×]*)\s*$")


def is_whole(value) -> bool:
    """Whether ``value`` is a whole number as a count or an index must be: an int or a numpy
    integer, not a bool (nor a float that happens to be whole)."""
    import numbers

    return isinstance(value, numbers.Integral) and not isinstance(value, bool)


def _not_real(value) -> str | None:
    """What ``value`` is when ``float()`` would take it (or its imaginary part would be lost)
    though it is no real number: ``"a bool, not a number"`` (``True`` would read as 1) or ``"a
    complex number"``; None otherwise. Looks at Python and numpy scalars and 0-d arrays (their
    ``dtype``) without importing numpy."""
    kind = getattr(getattr(value, "dtype", None), "kind", None)
    if isinstance(value, bool) or kind == "b":
        return "a bool, not a number"
    if isinstance(value, complex) or kind == "c":  # numpy's complex128 is a complex
        return "a complex number"
    return None


def number_problem(value) -> str | None:
    """Why ``value`` is no real number (``"a bool, not a number"``, ``"a complex number"``,
    ``"not a number"``), or None when ``float()`` reads it as one (numbers, numpy scalars and
    0-d arrays, numeric strings): the test of :func:`real_number`, and of converters that check a
    sequence item by item."""
    why = _not_real(value)
    if why is None:
        try:
            float(value)
        except (TypeError, ValueError, OverflowError):
            return "not a number"
    return why


def _shown(value, limit: int = 60) -> str:
    """``repr(value)`` on one line (an array's repr spans lines), cut to ``limit`` characters."""
    text = " ".join(repr(value).split())
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _refusal(what: str, expected: str, value, why: str | None) -> str:
    """The one line of a value that is not the number a keyword takes."""
    return f"{what}: expected {expected}, got {_shown(value)}" + (f" ({why})" if why else "")


def real_number(
    value, what: str, expected: str = "a number", *, error: type[Exception] = UnitError
) -> float:
    """``value`` as a float where a real number enters: an int, a float, a numpy scalar or 0-d
    array, or a string that ``float()`` reads (``"10"``, ``"1e3"``). NaN and inf are returned
    as they are (the caller's range check names them).

    Parameters
    ----------
    value
        The value as given.
    what : str
        The keyword's name, for the message.
    expected : str
        What to give, for the message (``"a length in mm"``).
    error : type
        The exception class to raise: the caller's own (:class:`UnitError`, or e.g.
        :class:`raytrace.errors.TraceError` where a trace request is checked).

    Raises
    ------
    error
        A bool (``True`` is no length of 1 mm), a complex number, a sequence, or anything else
        that is not one real number: ``"{what}: expected {expected}, got 1j (a complex
        number)"``.
    """
    if number_problem(value) is None:
        return float(value)
    raise error(_refusal(what, expected, value, _not_real(value)))


def real_array(value, what: str, expected: str = "numbers", *, error: type[Exception] = UnitError):
    """``value`` as a float64 array of its own shape, as ``np.asarray(value, float)`` reads it
    (numbers, numeric strings such as ``"10"``; ``None`` becomes NaN for the caller's finiteness
    check), where the fields or angles of a call enter. Refused, as :func:`real_number` refuses
    a scalar: bools (also inside a list, where numpy would read ``[0, True]`` as ``[0, 1]``),
    complex numbers (numpy would drop the imaginary part), ragged lists and values that are no
    numbers.

    Parameters
    ----------
    value
        A number, a sequence or an array.
    what : str
        The keyword's name, for the message.
    expected : str
        What to give, for the message (``"field angles in degrees"``).
    error : type
        The exception class to raise (the caller's own).

    Returns
    -------
    ndarray
        float64, the shape of ``value``.
    """
    import numpy as np

    if isinstance(value, np.ndarray) and value.dtype.kind in "fiu":  # the common case, fast
        return value.astype(np.float64, copy=False)
    why = _not_real(value) or _any_not_real(value)
    if why is None:
        try:
            a = np.asarray(value)
            why = _not_real(a)
            if why is None and a.dtype.kind == "O":
                why = _any_not_real(a.ravel().tolist())
            if why is None:
                return a.astype(np.float64)
        except (TypeError, ValueError, OverflowError):
            pass
    raise error(_refusal(what, expected, value, why))


def _any_not_real(items) -> str | None:
    """:func:`_not_real` of the first item of a (nested) list or tuple that is no real number,
    or None."""
    if not isinstance(items, list | tuple):
        return None
    for x in items:
        why = _not_real(x) or _any_not_real(x)
        if why is not None:
            return why
    return None


def split_unit(text: str) -> tuple[float, str]:
    """``"1.5m"`` → (1.5, "m"); ``"12x"`` → (12.0, "x"); ``"inf"`` → (inf, ""). UnitError when the
    text is not a number with an optional unit word."""
    m = _RE.match(str(text))
    if not m:
        raise UnitError(f"{text!r} is not a number (with an optional unit such as mm, m, nm, um)")
    v = float(m.group(1))
    if math.isnan(v):
        raise UnitError(f"{text!r} is not a number")
    unit = m.group(2).replace("×", "x").replace("X", "x")
    return v, unit.lower() if unit not in ("µm",) else unit


def _split(text: str, what: str) -> tuple[float, str]:
    """:func:`split_unit`, its error naming ``what``."""
    try:
        return split_unit(text)
    except UnitError as e:
        raise UnitError(f"{what}: {e}") from None


def length_mm(
    value: float | str,
    what: str,
    *,
    require_unit: bool = False,
    allow_inf: bool = False,
    positive: bool = False,
) -> float:
    """A length in mm from a number (mm) or a string with a unit suffix (mm, cm, m, um, in).

    ``require_unit``: a bare number is refused (used where the default unit was once metres).
    ``allow_inf``: ``inf`` is accepted. ``positive``: the value must be > 0.
    """
    if isinstance(value, str):
        v, unit = _split(value, what)
        if not unit:
            if require_unit and not math.isinf(v):  # inf needs no unit
                t = value.strip()
                raise UnitError(
                    f"{what}: {value!r} needs a unit — write e.g. {t}m or {t}mm "
                    "(a bare number is ambiguous here)"
                )
            unit = "mm"
        if unit not in LENGTH_UNITS:
            raise UnitError(
                f"{what}: unknown length unit {unit!r} in {value!r}; use mm, cm, m, um or in"
            )
        v *= LENGTH_UNITS[unit]
    else:
        v = real_number(
            value,
            what,
            "a length in mm (a number, or a string with its unit such as 50.5mm or 0.05m)",
        )
    if math.isnan(v) or (math.isinf(v) and not allow_inf):
        raise UnitError(f"{what}: expected a finite length, got {value!r}")
    if positive and not v > 0:
        raise UnitError(f"{what}: expected a positive length, got {value!r}")
    return v


#: The largest distance of an image plane (mm, exclusive). 1e10 mm is 10,000 km: no image plane
#: of a lens lies near it (1e300 was traced to distortions of 1e296 mm). It is the threshold the
#: Zemax, CODE V and OSLO files use for an object at infinity (their object distance of 1e10 lens
#: units or more: ``raytrace/files``: zemax.py, codev.py, oslo.py), taken over for image planes.
PLANE_LIMIT_MM = 1e10


def plane_distance_mm(value: float | str, what: str) -> float:
    """The signed distance of an image plane in mm (``s_prime``, ``from_last_vertex``,
    ``defocus``) from a number (mm) or a string with a length unit (``"50.5mm"``, ``"5cm"``):
    :func:`length_mm`, then finite and below :data:`PLANE_LIMIT_MM` in magnitude.

    Parameters
    ----------
    value : float or str
        The distance as given.
    what : str
        The keyword's name, for the message.

    Returns
    -------
    float
        mm.

    Raises
    ------
    UnitError
        Not a length, not finite, or 1e10 mm or more away (where lens files put an object at
        infinity).
    """
    v = length_mm(value, what)
    if abs(v) >= PLANE_LIMIT_MM:
        raise UnitError(
            f"{what}={v:g} mm is not a plane position: 1e10 mm or more is where lens files put "
            "an object at infinity; give a distance within ±1e10 mm (mm, or a length with its "
            "unit: 50.5mm)"
        )
    return v


def wavelength_nm(value: float | str, what: str = "wavelength") -> float:
    """A wavelength in nm from a number (nm), a string with a unit (nm, um, µm) or a
    spectral-line letter (:data:`SPECTRAL_LINES`: ``"d"``, ``"F'"``).

    Refuses NaN, inf, zero and negative values, and values outside
    :data:`WAVELENGTH_RANGE_NM`; a bare number below 100 that is in range as µm looks like µm
    and the message says so (``0.5876`` → "write 0.5876um or 587.6nm"; one that looks like
    metres or millimetres says that). A value that carries its unit (``"0.55nm"``,
    ``"0.05um"``) is taken as meant: out of range, the message gives the range (a unit is never
    appended to it)."""
    bare = True
    if isinstance(value, str) and value.strip() in SPECTRAL_LINES:
        return SPECTRAL_LINES[value.strip()]
    if isinstance(value, str):
        v, unit = _split(value, what)
        bare = not unit
        unit = unit or "nm"
        if unit not in WAVELENGTH_UNITS:
            raise UnitError(f"{what}: unknown wavelength unit {unit!r} in {value!r}; use nm or um")
        v *= WAVELENGTH_UNITS[unit]
    else:
        v = real_number(value, what, "a number of nm")
    if not math.isfinite(v):
        raise UnitError(f"{what}: expected a finite wavelength in nm, got {value!r}")
    if v <= 0:
        raise UnitError(f"{what}: a wavelength must be positive, got {value!r}")
    lo, hi = WAVELENGTH_RANGE_NM
    for factor, name in ((1e9, "metres"), (1e6, "millimetres")):
        if bare and v < lo and v * 1000.0 < lo and lo <= v * factor <= hi:
            raise UnitError(
                f"{what} {value!r} nm looks like {name}: write {v * factor:g}nm (wavelengths "
                "are in nm)"
            )
    if bare and v < lo and lo <= v * 1000.0 <= hi:
        t = value.strip() if isinstance(value, str) else value
        raise UnitError(
            f"{what} {value!r} nm looks like micrometres: write {t}um or "
            f"{v * 1000:g}nm (wavelengths are in nm)"
        )
    if not lo <= v <= hi:
        raise UnitError(f"{what}: {v:g} nm is outside {lo:g}-{hi:g} nm")
    return v


def image_scale(value: float | str, what: str = "image scale") -> float:
    """An image scale N ("N×", Gaussian magnification −1/N) from ``12``, ``"12"`` or ``"12x"``."""
    if isinstance(value, str):
        v, unit = _split(value, what)
        if unit not in ("", "x"):
            raise UnitError(f"{what}: {value!r} is not an image scale such as 12x")
    else:
        v = real_number(value, what, "an image scale N such as 12 or '12x'")
    if not (math.isfinite(v) and v > 0):
        raise UnitError(
            f"{what}: N must be a positive finite number (12x: m0 = -1/12), got {value!r}"
        )
    return v


#: Fraunhofer / spectral-line letters as glass catalogs print them (Schott optical glass data
#: sheets, e.g. the N-BK7 sheet: nm, in air). Case matters: ``d`` (helium) is not ``D``
#: (sodium).
SPECTRAL_LINES = {
    "i": 365.0146,
    "h": 404.6561,
    "g": 435.8343,
    "F'": 479.9914,
    "F": 486.1327,
    "e": 546.074,
    "d": 587.5618,
    "D": 589.2938,
    "C'": 643.8469,
    "C": 656.2725,
    "r": 706.5188,
    "s": 852.11,
    "t": 1013.98,
}


def wavelengths_nm(values, what: str = "wavelengths") -> tuple[float, ...]:
    """Several wavelengths in nm: a comma-separated string (``"486.1327,587.5618,656.2725"``,
    ``"F,d,C"``, ``"0.55um,650nm"``) or a sequence of numbers / strings. Each value goes through
    :func:`wavelength_nm`; a spectral-line letter (:data:`SPECTRAL_LINES`) stands for its
    wavelength. An empty list is refused."""
    if isinstance(values, str):
        items = [v.strip() for v in values.split(",") if v.strip()]
    else:
        try:
            items = list(values)
        except TypeError:
            items = [values]
    if not items:
        raise UnitError(f"{what}: give at least one wavelength (nm)")
    return tuple(wavelength_nm(v, what) for v in items)
