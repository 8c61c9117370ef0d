"""The distortion curve as data: Pestrecov's characteristic distortion in one image plane (Eq. 9).

A curve holds, per field point, the abscissa of orthoscopy ``x`` (``tan α`` for an object at
infinity, the object height ``y`` in mm for finite conjugates), the ideal image size
``y0' = K0·x`` with ``K0`` = F0 (mm) or M0, and the linear distortion ``D0 = y' − y0'`` (mm). The
relative distortion ``Dr = D0 / y0'`` is kept as a fraction internally and printed in per cent as
in the paper. Curves come from a trace (:mod:`distortion.characteristic`) or from a table file
(:mod:`distortion.tablefile`).
"""

from __future__ import annotations

import math
from collections.abc import Collection
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from raytrace.errors import TraceError

if TYPE_CHECKING:
    from raytrace.lens import Lens
    from raytrace.paraxial import ParaxialResult

ANGLE = "angle"
HEIGHT = "height"
NOMINAL_ANGLE = "nominal-angle"
FIELD_KINDS = (ANGLE, HEIGHT, NOMINAL_ANGLE)


def require_choice(
    value: object, choices: Collection[str], what: str, error: type[Exception] = TraceError
) -> None:
    """Raise ``error`` with the one wording of a bad choice, ``unknown <what> <value!r>;
    expected one of <choices>``, unless ``value`` is one of ``choices`` (names, in order)."""
    if value not in choices:
        raise error(f"unknown {what} {value!r}; expected one of {', '.join(choices)}")


def check_field_angles(
    values: npt.ArrayLike, what: str, error: type[Exception] = TraceError, *, index: bool = True
) -> None:
    """Raise ``error`` naming the first of ``values`` (field angles in degrees) that is not
    strictly between −90° and 90°, ``<what>[i] = <value>: <the tracer's message>`` (without
    ``index``: ``<what> <value>: …``): the check the tracer applies to every field
    (:func:`raytrace.trace.chief.checked_aim_request`). ``values`` must be finite."""
    from raytrace.trace.chief import checked_aim_request

    a = np.atleast_1d(np.asarray(values, dtype=float)).ravel()
    try:
        checked_aim_request("angle", math.inf, a)
    except TraceError as e:
        i = int(np.argmax(~(np.abs(a) < 90.0)))
        raise error(f"{what}[{i}] = {a[i]:g}: {e}" if index else f"{what} {a[i]:g}: {e}") from None


def _require_finite(values: np.ndarray, name: str, unit: str, fields=None) -> None:
    """ValueError naming ``make_curve``'s input ``name`` and the index of its first value that
    is not finite (and that point's field, when ``fields`` are given)."""
    bad = np.nonzero(~np.isfinite(values))[0]
    if bad.size:
        i = int(bad[0])
        at = f" (field {fields[i]:g})" if fields is not None else ""
        unit = f" ({unit})" if unit else ""
        raise ValueError(
            f"make_curve: {name}[{i}] = {values[i]:g}{at} is not a finite number; {name} holds "
            f"one finite value{unit} per field point"
        )


def relative_distortion(
    D: npt.ArrayLike,
    reference: npt.ArrayLike,
    *,
    off_axis: npt.ArrayLike | None = None,
    valid: npt.ArrayLike | None = None,
) -> np.ndarray:
    """Relative distortion ``Dr = D / reference`` as a fraction (Pestrecov's ``D0 / y0'``).

    Parameters
    ----------
    D : array_like
        Linear distortion (mm).
    reference : array_like
        The height it is relative to (mm), e.g. the ideal image size y0'.
    off_axis : array_like of bool, optional
        Where to divide; elsewhere (the axis) ``Dr = 0``. Default ``reference != 0``.
    valid : array_like of bool, optional
        Where the result holds; elsewhere NaN (e.g. ``isfinite(y')``). Default everywhere.

    Returns
    -------
    ndarray
        ``Dr`` (fraction, dimensionless), the broadcast shape of the inputs.
    """
    D = np.asarray(D, dtype=float)
    ref = np.asarray(reference, dtype=float)
    nz = ref != 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(nz if off_axis is None else off_axis, D / np.where(nz, ref, 1.0), 0.0)
    return r if valid is None else np.where(valid, r, np.nan)


def plane_label(s_prime: float, defocus: float, note: str = "") -> str:
    """A plane described in words: ``s' = … mm (Gaussian plane)`` or ``(defocus ±… mm)``.

    Parameters
    ----------
    s_prime : float
        mm from H' (Pestrecov's s').
    defocus : float
        mm from the Gaussian image plane (+ away from the lens); within ``1e-9 × max(1, |s'|)``
        of zero the plane is called the Gaussian plane.
    note : str
        Text appended inside the parentheses (e.g. ``" at 587.6 nm"``).
    """
    g = (
        "Gaussian plane"
        if abs(defocus) <= 1e-9 * max(1.0, abs(s_prime))
        else f"defocus {defocus:+.4f} mm"
    )
    return f"s' = {s_prime:.4f} mm ({g}{note})"


def requested_fields(
    lens: Lens,
    infinite: bool,
    fields_deg: npt.ArrayLike | None,
    heights_mm: npt.ArrayLike | None,
    heights_name: str = "object_heights_mm",
) -> tuple[str, np.ndarray]:
    """The fields of a 1-D analysis as ``(kind, values)`` for :func:`raytrace.trace.aim`.

    Parameters
    ----------
    lens : Lens
        Gives the default: 11 fields from 0 to the lens file's field (as angles when the file
        gives a height but the object is at infinity).
    infinite : bool
        Whether the object is at infinity.
    fields_deg : array_like or None
        Field angles in degrees (nominal angles with a finite object): kind ``"angle"``.
    heights_mm : array_like or None
        Object heights (or radii) in mm: kind ``"height"``. Give at most one of the two.
    heights_name : str
        The keyword the heights came as, for the error message.

    Returns
    -------
    kind : str
        ``"angle"`` or ``"height"``.
    values : ndarray
        (n,) degrees or mm.

    Raises
    ------
    TraceError
        Both ``fields_deg`` and ``heights_mm`` given, or a value that is no field (a bool, a
        complex number: :func:`raytrace.trace.chief.field_values`).
    """
    if fields_deg is not None and heights_mm is not None:
        raise TraceError(f"give fields_deg or {heights_name}, not both")
    from raytrace.trace.chief import field_values

    if heights_mm is not None:
        return "height", np.atleast_1d(field_values(heights_mm, heights_name)).ravel()
    if fields_deg is not None:
        return "angle", np.atleast_1d(field_values(fields_deg, "fields_deg")).ravel()
    fk = lens.field.kind if not (infinite and lens.field.kind == "height") else "angle"
    return fk, np.linspace(0.0, lens.field.value, 11)


def fields_and_abscissa(
    lens: Lens,
    par: ParaxialResult,
    fields_deg: npt.ArrayLike | None,
    object_heights_mm: npt.ArrayLike | None,
) -> tuple[str, np.ndarray, str, np.ndarray]:
    """The fields of a 1-D traced analysis and Pestrecov's abscissa of orthoscopy.

    Parameters
    ----------
    lens : Lens
    par : ParaxialResult
        The object and wavelength of the analysis.
    fields_deg, object_heights_mm : array_like or None
        As :func:`requested_fields` (default: 11 fields from 0 to the lens file's field).

    Returns
    -------
    aim_kind : str
        ``"angle"`` or ``"height"`` (for :func:`raytrace.trace.aim`).
    fields : ndarray
        (n,) degrees or mm.
    kind : str
        The result's field kind (:func:`curve_field_kind`).
    x : ndarray
        (n,) ``tan α`` (object at infinity) or the object height y (mm)
        (:func:`raytrace.paraxial.orthoscopy_abscissa`).

    Raises
    ------
    TraceError
        No fields, both kinds given, or object heights with an object at infinity.
    """
    from raytrace.paraxial import orthoscopy_abscissa

    fk, f = requested_fields(lens, par.infinite, fields_deg, object_heights_mm)
    if f.size == 0:  # the words of every trace (chief_rays, distortion_grid, ...)
        name = "object_heights_mm" if object_heights_mm is not None else "fields_deg"
        raise TraceError(f"no fields given: {name} is empty")
    kind = curve_field_kind(fk, par.infinite)
    return fk, f, kind, orthoscopy_abscissa(par, f, fk)


def curve_field_kind(field_kind: str, infinite: bool) -> str:
    """The field kind of a result (``ANGLE``, ``HEIGHT`` or ``NOMINAL_ANGLE``) from the kind the
    fields were given as (``"angle"`` | ``"height"``) and whether the object is at infinity.

    Raises
    ------
    TraceError
        Object heights with an object at infinity.
    """
    if field_kind == "height" and infinite:
        raise TraceError("object heights need a finite object distance")
    return ANGLE if infinite else (HEIGHT if field_kind == "height" else NOMINAL_ANGLE)


class FieldKindMixin:
    """``finite`` and ``symbol`` of a result with a ``field_kind`` attribute (``ANGLE``,
    ``HEIGHT`` or ``NOMINAL_ANGLE``)."""

    __slots__ = ()
    field_kind: str

    @property
    def finite(self) -> bool:
        """True for finite conjugates (constant M0), False for an object at infinity (F0)."""
        return self.field_kind != ANGLE

    @property
    def symbol(self) -> str:
        """``"F"`` (object at infinity) or ``"M"`` (finite conjugates)."""
        return "M" if self.finite else "F"


@dataclass(frozen=True, eq=False)
class DistortionCurve(FieldKindMixin):
    """Characteristic (or any reference) distortion curve in one image plane.

    fields:     field values as given: angles in degrees (``field_kind="angle"`` or
                ``"nominal-angle"``) or object heights in mm (``"height"``).
    field_kind: ``"angle"`` (object at infinity), ``"height"`` or ``"nominal-angle"`` (finite
                conjugates; a nominal angle α stands for the object height ``y = p0·tan α``).
    x:          abscissa of orthoscopy: ``tan α`` (object at infinity) or the object height y (mm).
    y0p:        ideal image size ``y0' = K0·x`` (mm).
    D0:         linear distortion ``y' − y0'`` (mm), Eq. (9).
    constant:   K0: F0 (mm) for an object at infinity, M0 (dimensionless) for finite conjugates.
    name, plane, source: free text for titles and tables (lens, image plane, origin).
    decimals:   decimals to print linear quantities with (3 reproduces the paper's Tables I–II).
    """

    fields: np.ndarray
    field_kind: str
    x: np.ndarray
    y0p: np.ndarray
    D0: np.ndarray
    constant: float
    name: str = ""
    plane: str = ""
    source: str = ""
    decimals: int = 4
    extra: dict = field(default_factory=dict, compare=False)

    @property
    def yp(self) -> np.ndarray:
        """Actual image size ``y' = y0' + D0`` (mm)."""
        return self.y0p + self.D0

    @property
    def Dr(self) -> np.ndarray:
        """Characteristic relative distortion ``D0 / y0'`` as a fraction; 0 on the axis."""
        return relative_distortion(self.D0, self.y0p)

    @property
    def field_label(self) -> str:
        return {ANGLE: "α (deg)", HEIGHT: "y (mm)", NOMINAL_ANGLE: "nominal α (deg)"}[
            self.field_kind
        ]

    def __len__(self) -> int:
        return int(self.fields.size)


def make_curve(
    fields,
    D0,
    *,
    field_kind: str = ANGLE,
    constant: float,
    x=None,
    y0p=None,
    name: str = "",
    plane: str = "",
    source: str = "",
    decimals: int = 4,
) -> DistortionCurve:
    """Build a :class:`DistortionCurve` from arrays, computing ``x`` and ``y0'`` when not given
    (``x = tan α`` for angles, ``x = y`` for heights; a nominal-angle curve needs ``x``).

    Parameters
    ----------
    fields : array_like
        Field values: angles α in degrees (``"angle"``, ``"nominal-angle"``) or object heights y
        in mm (``"height"``).
    D0 : array_like
        Linear distortion ``D0 = y' − y0'`` in mm (Pestrecov 1958, Eq. 9), one per field.
    field_kind : {"angle", "height", "nominal-angle"}
        ``"angle"`` (default): object at infinity; ``"height"``: finite conjugates;
        ``"nominal-angle"``: finite conjugates, α standing for the object height y = p0 tan α.
    constant : float
        K0 of Eq. (8): F0 in mm (object at infinity) or M0 (finite conjugates; signed, negative
        for a real inverted image).
    x : array_like, optional
        The abscissa of orthoscopy, ``tan α`` or y (mm); default from ``fields``.
    y0p : array_like, optional
        The ideal image size y0' in mm; default ``constant·x``.
    name, plane, source : str
        Free text for titles and tables (lens, image plane, origin).
    decimals : int
        Decimals to print linear quantities with (default 4; 3 reproduces the paper's tables).

    Returns
    -------
    DistortionCurve

    Raises
    ------
    ValueError
        An unknown ``field_kind``, a nominal-angle curve without ``x``, arrays of different
        lengths, a value of ``fields``, ``D0``, ``x`` or ``y0p`` that is not finite, a field angle
        not strictly between −90° and 90° (the tracer's check,
        :func:`raytrace.trace.chief.checked_aim_request`), or a ``constant`` that is zero or not
        finite; each message names the input (and the index). Negative fields and a constant of
        either sign are curves (an erecting system with an intermediate image has F0 < 0).
    """
    if field_kind not in FIELD_KINDS:
        raise ValueError(f"unknown field kind {field_kind!r}; expected one of {FIELD_KINDS}")
    f = np.asarray(fields, dtype=float).ravel()
    d = np.asarray(D0, dtype=float).ravel()
    _require_finite(f, "fields", "degrees" if field_kind != HEIGHT else "mm")
    if field_kind != HEIGHT:
        check_field_angles(f, "make_curve: fields", ValueError)
    try:
        k = math.nan if isinstance(constant, (bool, str)) else float(constant)
        shown = repr(constant) if isinstance(constant, (bool, str)) else f"{k:g}"
    except (TypeError, ValueError):
        k, shown = math.nan, repr(constant)
    if not (math.isfinite(k) and k != 0.0):
        raise ValueError(
            f"make_curve: constant = {shown} is not a finite nonzero number: K0 is F0 in mm "
            "(object at infinity) or M0 (finite conjugates)"
        )
    if x is None:
        if field_kind == ANGLE:
            x = np.tan(np.radians(f))
        elif field_kind == HEIGHT:
            x = f.copy()
        else:
            raise ValueError("a nominal-angle curve needs x (object heights y = p0 tan α)")
    xa = np.asarray(x, dtype=float).ravel()
    ya = k * xa if y0p is None else np.asarray(y0p, dtype=float).ravel()
    if not (f.size == d.size == xa.size == ya.size):
        raise ValueError("fields, x, y0p and D0 must have the same length")
    for values, what in ((xa, "x"), (ya, "y0p"), (d, "D0")):
        _require_finite(values, what, "mm" if what != "x" or field_kind == HEIGHT else "", f)
    return DistortionCurve(f, field_kind, xa, ya, d, k, name, plane, source, decimals)
