"""The distortion curve as data: Pestrecov's characteristic distortion in one image plane (Eq. 9).

A curve holds, per field point, the abscissa of orthoscopy ``x`` (``tan α`` for an object at
infinity, the object height ``y`` in mm for finite conjugates), the ideal image size
``y0' = K0·x`` with ``K0`` = F0 (mm) or M0, and the linear distortion ``D0 = y' − y0'`` (mm). The
relative distortion ``Dr = D0 / y0'`` is kept as a fraction internally and printed in per cent as
in the paper. Curves come from a trace (:mod:`distortion.characteristic`) or from a table file
(:mod:`distortion.tablefile`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

ANGLE = "angle"
HEIGHT = "height"
NOMINAL_ANGLE = "nominal-angle"
FIELD_KINDS = (ANGLE, HEIGHT, NOMINAL_ANGLE)


@dataclass(frozen=True, eq=False)
class DistortionCurve:
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
    def finite(self) -> bool:
        """True for finite conjugates (constant M0), False for an object at infinity (F0)."""
        return self.field_kind != ANGLE

    @property
    def symbol(self) -> str:
        """``"F"`` (object at infinity) or ``"M"`` (finite conjugates)."""
        return "M" if self.finite else "F"

    @property
    def yp(self) -> np.ndarray:
        """Actual image size ``y' = y0' + D0`` (mm)."""
        return self.y0p + self.D0

    @property
    def Dr(self) -> np.ndarray:
        """Characteristic relative distortion ``D0 / y0'`` as a fraction; 0 on the axis."""
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.where(self.y0p != 0.0, self.D0 / np.where(self.y0p != 0.0, self.y0p, 1.0), 0.0)
        return r

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
    (``x = tan α`` for angles, ``x = y`` for heights; a nominal-angle curve needs ``x``)."""
    if field_kind not in FIELD_KINDS:
        raise ValueError(f"unknown field kind {field_kind!r}; expected one of {FIELD_KINDS}")
    f = np.asarray(fields, dtype=float).ravel()
    d = np.asarray(D0, dtype=float).ravel()
    if x is None:
        if field_kind == ANGLE:
            x = np.tan(np.radians(f))
        elif field_kind == HEIGHT:
            x = f.copy()
        else:
            raise ValueError("a nominal-angle curve needs x (object heights y = p0 tan α)")
    xa = np.asarray(x, dtype=float).ravel()
    ya = constant * xa if y0p is None else np.asarray(y0p, dtype=float).ravel()
    if not (f.size == d.size == xa.size == ya.size):
        raise ValueError("fields, x, y0p and D0 must have the same length")
    return DistortionCurve(f, field_kind, xa, ya, d, float(constant), name, plane, source, decimals)
