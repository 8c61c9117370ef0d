"""Compensation of a camera's distortion by a printer (Pestrecov 1958, Section VI, Eqs. 16–17).

Camera (object at infinity): ``y' = F1·tan α + D1(α)`` in the negative.
Printer (finite conjugates, negative → print, image-space magnification M2): its characteristic
curve gives the print height ``y'' = M2·h + Dp(h)`` of a negative point at height h (Dp in the
print plane, mm). In the negative plane its distortion is ``D2(h) = h − y''/M2 = −Dp(h)/M2``.

The print of the camera's image is ``y'' = M2·(y' − D2(y'))`` and its ideal size ``M·F1·tan α``.
The residual, in the negative plane (Eq. 16 rearranged), is

    R(α) = D1 − D2 − (M/M2 − 1)·F1·tan α = (y'' − M·F1·tan α)/M2,

and ``M2·R`` is the distortion of the print itself (mm in the print plane). D2 is evaluated at
the actual negative point ``y' = F1 tan α + D1`` the printer images (exact); Pestrecov's
first-order reading evaluates it at ``F1 tan α`` — the difference is of order ``D·dD/dy``.
The printer curve is interpolated in h by a cubic spline of the odd extension D2(−h) = −D2(h)
(nodes are reproduced exactly); heights beyond the printer's field raise a DataError.

R is linear in M, so the M that best removes it is a calibration fit (``fit_scale``) of
``r = D1 − D2 + F1 tan α`` against ``x = F1 tan α / M2`` with any criterion of
:mod:`distortion.calibration`. Recalibrating either curve (Eq. 11) leaves the print's distortion
unchanged (Eq. 16 ⇔ Eq. 17).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from .calibration import METHODS, axis_spread, fit_scale, match_fields
from .curve import DistortionCurve, require_choice
from .errors import CalibrationError, DataError

#: A given print magnification factor M is checked against the printer's own M2. A real print
#: differs from M2's scale by about the distortion of the two lenses (per cent at most; the
#: fitted methods move M by well under 1 % on the bundled lenses), so |M/M2 - 1| above
#: ``M_WARN`` (10 %) draws a :class:`MagnificationWarning` -- the residual R is then mostly the
#: scale term (M/M2 - 1) F1 tan(alpha) -- and M/M2 outside [1/M_REFUSE, M_REFUSE] (a factor of
#: 2) is refused: the printer at M2 makes no such print.
M_WARN = 0.1
M_REFUSE = 2.0


class MagnificationWarning(UserWarning):
    """A given print magnification factor M far (more than :data:`M_WARN`) from the printer's
    M2."""


@dataclass(frozen=True, eq=False)
class CompensationResult:
    """Residual distortion of the print (Section VI).

    alpha_deg: the camera's field angles; F1 (mm) and M2 the constants the two curves use;
    M: the print magnification factor (Eq. 16) used for the residual;
    y1: camera image ``F1 tan α`` (mm, negative plane); yp: actual negative point (mm);
    D1, D2: the camera's and the printer's distortion in the negative plane (mm);
    residual: R = D1 − D2 − (M/M2 − 1) F1 tan α (mm, negative plane);
    print_residual: M2·R, the distortion of the print (mm, print plane).
    """

    alpha_deg: np.ndarray
    F1: float
    M2: float
    M: float
    method: str
    y1: np.ndarray
    yp: np.ndarray
    D1: np.ndarray
    D2: np.ndarray
    residual: np.ndarray
    print_residual: np.ndarray

    @property
    def max_abs(self) -> float:
        """max |R| (mm, negative plane)."""
        return float(np.max(np.abs(self.residual)))

    @property
    def spread(self) -> float:
        """max − min of R over the field, the axis (R = 0) included."""
        return axis_spread(self.residual, 0.0)


def printer_negative_distortion(printer: DistortionCurve, h) -> np.ndarray:
    """D2(h) = −Dp(h)/M2: the printer's distortion referred to the negative plane at negative
    heights h (mm), by a cubic spline of the odd extension of the printer curve."""
    from scipy.interpolate import CubicSpline

    if not printer.finite:
        raise DataError("the printer curve must be for finite conjugates (object heights, M2)")
    x = np.asarray(printer.x, dtype=float)
    d2 = -printer.D0 / printer.constant
    ax = np.abs(x)
    sd = np.where(x < 0, -d2, d2)  # odd extension: D2 for positive heights
    order = np.argsort(ax)
    ax, sd = ax[order], sd[order]
    if ax[0] != 0.0:
        ax, sd = np.concatenate([[0.0], ax]), np.concatenate([[0.0], sd])
    xx = np.concatenate([-ax[:0:-1], ax])
    yy = np.concatenate([-sd[:0:-1], sd])
    h = np.asarray(h, dtype=float)
    hmax = ax[-1]
    if np.any(np.abs(h) > hmax * (1 + 1e-12)):
        bad = float(np.max(np.abs(h)))
        raise DataError(
            f"the camera image reaches {bad:.4f} mm in the negative but the printer curve only "
            f"covers object heights up to {hmax:.4f} mm"
        )
    if xx.size < 4:
        return np.interp(h, xx, yy)
    return CubicSpline(xx, yy)(h)


def compensate(
    camera: DistortionCurve,
    printer: DistortionCurve,
    *,
    method: str = "given",
    magnification: float | None = None,
    at=None,
) -> CompensationResult:
    """Residual distortion of the print of ``camera``'s negative by ``printer`` (Pestrecov 1958,
    Eq. 16).

    The residual in the negative plane is ``R = D1 − D2 − (M/M2 − 1)·F1·tan α`` (module
    docstring); D2 is taken at the actual negative point ``y' = F1 tan α + D1``.

    Parameters
    ----------
    camera : DistortionCurve
        The camera lens for an object at infinity: field angles α (degrees), constant F1 (mm), D1
        (mm) in the negative.
    printer : DistortionCurve
        The printer for finite conjugates with the negative as its object: object heights h in
        the negative (mm), constant M2 (its image-space magnification, signed), D0 (mm) in the
        print plane. Its heights must reach the camera's largest image height.
    method : {"given", "two-point", "zero-at", "minimax", "least-squares"}
        How the print magnification factor M is chosen: ``"given"`` (default) uses
        ``magnification`` (default M2 — the paper's compensation condition for characteristic
        curves); the others are calibration fits over the camera's fields
        (:mod:`distortion.calibration`), ``"two-point"`` and ``"zero-at"`` at the ``at`` fields.
    magnification : float, optional
        M (Eq. 16), with ``method="given"`` only; finite, of the sign of M2 and within a factor
        of 2 of it (a warning beyond 10 %: :data:`M_WARN`).
    at : sequence of float, optional
        Field angles (degrees) of the camera curve: two for ``"two-point"``, one for
        ``"zero-at"``; none for the other methods.

    Returns
    -------
    CompensationResult
        F1, M2, the M used, the camera image ``F1 tan α`` and the actual negative point (mm), D1
        and D2 (mm, negative plane), the residual R (mm, negative plane) and ``M2·R``, the
        distortion of the print (mm, print plane).

    Raises
    ------
    DataError
        The camera curve is not for an object at infinity, the printer curve not for finite
        conjugates, or the camera's image reaches beyond the printer curve's heights.
    CalibrationError
        An unknown method; ``at`` with a method that takes none, or the wrong number of ``at``
        fields, or one that is not among the camera's fields; ``magnification`` with a method
        other than ``"given"``; a ``magnification`` that is not finite, zero, of the other sign
        than M2 or more than a factor of 2 from it (:data:`M_REFUSE`); a degenerate
        magnification.

    Warns
    -----
    MagnificationWarning
        A given ``magnification`` more than 10 % from M2 (:data:`M_WARN`).
    """
    if camera.finite:
        raise DataError("the camera curve must be for an object at infinity (field angles, F1)")
    require_choice(method, METHODS, "method", CalibrationError)
    F1, M2 = camera.constant, printer.constant
    y1 = camera.y0p
    yp = camera.yp
    D1 = camera.D0
    D2 = printer_negative_distortion(printer, yp)
    x = y1 / M2
    r = D1 - D2 + y1
    need = {"two-point": 2, "zero-at": 1}.get(method, 0)
    if not need and at:
        raise CalibrationError(f"compensation ({method}) takes no at= fields")
    if method != "given" and magnification is not None:
        raise CalibrationError(
            f"compensation ({method}) chooses the magnification itself: magnification= goes "
            "with method 'given'"
        )
    if magnification is not None:
        _check_magnification(float(magnification), M2, D1 - D2, y1)
    idx = match_fields(camera.fields, at or (), f"compensation ({method})") if need else None
    if need and (idx is None or len(idx) != need):
        raise CalibrationError(f"method {method!r} needs {need} field(s) in at=")
    Mv = fit_scale(
        x,
        r,
        method,
        idx=idx,
        given=M2 if (method == "given" and magnification is None) else magnification,
    )
    if not math.isfinite(Mv):
        raise CalibrationError("compensation gave a degenerate magnification")
    R = D1 - D2 - (Mv / M2 - 1.0) * y1
    return CompensationResult(
        camera.fields.copy(), F1, M2, float(Mv), method, y1, yp, D1, D2, R, M2 * R
    )


def _check_magnification(m: float, M2: float, d: np.ndarray, y1: np.ndarray) -> None:
    """Refuse (CalibrationError) or warn (:class:`MagnificationWarning`) a given print
    magnification factor ``m`` that no print of the printer at ``M2`` can have (criterion at
    :data:`M_WARN`); ``d`` = D1 − D2 and ``y1`` = F1 tan α (mm) say what the scale term does."""
    if not math.isfinite(m) or m == 0.0:
        raise CalibrationError(
            f"magnification M = {m:g} is no print magnification factor: M (Eq. 16) is finite and "
            f"nonzero, of the sign of the printer's M2 = {M2:g}"
        )
    if m * M2 < 0:
        raise CalibrationError(
            f"magnification M = {m:g} has the other sign than the printer's M2 = {M2:g}: M is "
            f"the print's magnification factor (Eq. 16), of the sign of M2 (e.g. {-m:g})"
        )
    q = m / M2
    if not 1.0 / M_REFUSE <= q <= M_REFUSE:
        raise CalibrationError(
            f"magnification M = {m:g} is {q:.4g} times the printer's M2 = {M2:g}: no print of this "
            f"printer has that scale (M lies within a factor of {M_REFUSE:g} of M2; a "
            "compensating M differs from it by about the distortion, per cent at most)"
        )
    if abs(q - 1.0) > M_WARN:
        with np.errstate(invalid="ignore"):
            scale = float(np.nanmax(np.abs((q - 1.0) * y1))) if y1.size else 0.0
            dist = float(np.nanmax(np.abs(d))) if np.isfinite(d).any() else 0.0
        warnings.warn(
            f"the print magnification factor M = {m:g} is {100.0 * (q - 1.0):+.3g} % from the "
            f"printer's M2 = {M2:g} (more than {100.0 * M_WARN:g} %): the residual is then "
            f"mostly the scale term (M/M2 - 1) F1 tan(alpha), up to {scale:.4g} mm against "
            f"|D1 - D2| <= {dist:.4g} mm; a real print is within about the distortion of M2",
            MagnificationWarning,
            stacklevel=3,
        )
