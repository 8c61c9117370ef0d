"""Calibrated distortion (Pestrecov 1958, Section IV, Eqs. 10–15).

A calibration replaces the paraxial constant of orthoscopy K0 (F0 in mm for an object at infinity,
M0 for finite conjugates) by a calibrated constant Kc (F_c or M_c). Nothing physical changes: the
actual image sizes ``y' = y0' + D0`` stay the same. With ``x = tan α`` (or the object height y):

- calibrated image size    ``y_c' = Kc·x``
- calibrated linear        ``D_c = y' − Kc·x = D0 − (Kc/K0 − 1)·y0'``           Eqs. (10)–(12)
- rotation of the axis     ``tan ρ = Kc/K0 − 1``; with plot exaggeration k, ``tan ρ_k = k·tan ρ``
                                                                                 Eqs. (13)–(14)
- calibrated relative      ``D_rc = Dr·K0/Kc + (K0/Kc − 1)``; on the axis ``K0/Kc − 1`` ≠ 0
                                                                                 Eq. (15)

``D_c`` is linear in Kc, so every criterion is a one-parameter fit of a line through the origin
``y' ≈ Kc·x`` (:func:`fit_scale`), which :mod:`distortion.compensation` reuses.

Methods (criteria, ``METHODS``):

- ``two-point``: equal magnitude and opposite sign of D_c at two chosen fields (the paper's
  example, 37.5° and 45°): ``Kc = (y'_a + y'_b)/(x_a + x_b)``.
- ``minimax``: the smallest maximum |D_c| over the curve's field points: the exact Chebyshev
  best approximation by a line through the origin, solved as a linear program and polished to the
  intersection of the two active lines (not by sampling candidates).
- ``least-squares``: minimum Σ D_c² over the field points (normal equation ``Σ x y' / Σ x²``).
- ``zero-at``: D_c = 0 at one chosen off-axis field: ``Kc = y'_a / x_a``.
- ``given``: a user-supplied Kc.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from raytrace.units import is_whole

from .curve import HEIGHT, DistortionCurve, check_field_angles, require_choice
from .errors import CalibrationError

if TYPE_CHECKING:
    from .characteristic import CharacteristicDistortion

#: The calibration methods (criteria), in the order the docs list them.
METHODS = ("two-point", "minimax", "least-squares", "zero-at", "given")
CRITERIA = METHODS  # the paper's word; same tuple


def axis_spread(values: np.ndarray, on_axis: float) -> float:
    """max − min of ``values`` together with the curve's value on the axis ``on_axis``."""
    v = np.append(np.asarray(values, dtype=float), on_axis)
    return float(np.max(v) - np.min(v))


#: How near (degrees) a field of the curve an angle read as radians must land to look like
#: radians: a value rounded to 0.01 rad is within 0.29° of the angle it stands for.
RADIANS_MATCH_DEG = 0.5


def looks_like_radians(angle_deg: float, fields_deg: np.ndarray) -> bool:
    """Whether a field angle given in degrees looks like radians: 0 < |a| <= π/2 and, read as
    radians, within :data:`RADIANS_MATCH_DEG` of a nonzero field of the curve (0.65 for 37.5°,
    0.79 for 45°). Used where such a value is no field of the curve; any other value is taken
    as degrees (1 on a lens of 55° is a field of 1°)."""
    a = float(angle_deg)
    if not 0.0 < abs(a) <= math.pi / 2:
        return False
    f = np.asarray(fields_deg, dtype=float)
    f = f[f != 0.0]
    return bool(f.size) and float(np.min(np.abs(f - math.degrees(a)))) <= RADIANS_MATCH_DEG


def match_fields(fields: np.ndarray, at, what: str, *, angles: bool = False) -> list[int]:
    """Indices of the ``at`` field values among ``fields`` (CalibrationError naming ``what``).

    ``angles``: the fields are angles in degrees; an ``at`` value not strictly between −90° and
    90° is refused with the tracer's message (:func:`~distortion.curve.check_field_angles`), and
    one that is no field point but, read as radians, lands on one of the curve's fields says
    that it looks like radians (``0.65`` for 37.5°; :func:`looks_like_radians`).
    """
    lo, hi = float(np.min(fields)), float(np.max(fields))
    span = max(abs(lo), abs(hi), 1.0)
    idx = []
    listing = ", ".join(f"{v:g}" for v in fields)
    for a in at:
        if not math.isfinite(float(a)):
            raise CalibrationError(f"{what}: field {float(a)!r} is not a finite number")
    if angles:
        check_field_angles(at, f"{what}: field", CalibrationError, index=False)
    for a in at:
        a = float(a)
        unit = ""
        if angles and looks_like_radians(a, fields):
            unit = (
                f"; {a:g} looks like radians ({a:g} rad = {math.degrees(a):.4g}°): the fields are "
                "in degrees"
            )
        hit = np.nonzero(np.abs(fields - a) <= 1e-9 * span)[0]
        if not hit.size:  # a value copied from the listing below (6 significant digits)
            hit = np.nonzero([f"{v:g}" == f"{a:g}" for v in fields])[0]
            hit = hit if hit.size == 1 else hit[:0]
        if hit.size:
            idx.append(int(hit[0]))
            continue
        if a < lo - 1e-9 * span or a > hi + 1e-9 * span:
            raise CalibrationError(
                f"{what}: field {a:g} is outside the curve's fields ({lo:g} … {hi:g}){unit}"
            )
        raise CalibrationError(
            f"{what}: field {a:g} is not one of the curve's field points ({listing}); "
            f"choose one of them (or trace the curve with that field included){unit}"
        )
    return idx


def calibration_fields(
    fields: np.ndarray, method: str, at: Sequence[float], *, angles: bool = False
) -> list[int] | None:
    """The indices among ``fields`` of the ``at`` fields of a calibration ``method``: two for
    ``two-point``, one for ``zero-at``, None (and no ``at``) for the others.

    The one check of ``at`` (:func:`calibrate`, and the ``distortion`` command before it traces):
    CalibrationError for the wrong number of fields or a field that is not among ``fields``
    (:func:`match_fields`; ``angles``: the fields are degrees).
    """
    what = f"calibration ({method})"
    require_choice(method, METHODS, "calibration method", CalibrationError)
    need = {"two-point": 2, "zero-at": 1}.get(method, 0)
    if need and len(at) != need:
        raise CalibrationError(f"{what} needs exactly {need} field(s) in at=, got {len(at)}")
    if not need and at:
        raise CalibrationError(f"{what} takes no at= fields")
    return match_fields(np.asarray(fields, dtype=float), at, what, angles=angles) if need else None


#: A given calibrated constant is refused outside this factor of the curve's own scales (K0 and
#: y'/x at every off-axis field point). Least squares and minimax (weighted means of y'/x, and a
#: line through the origin that misses them all fits no point better), zero-at and two-point at
#: fields on one side of the axis give a K_c inside those scales; for a real lens they lie
#: within its distortion of K0 (Table I: 0.3 %; a fisheye y' = F0·θ to 85° reaches down to
#: 0.13·F0 and its minimax F_c ≈ 0.19·F0 lies inside), so a factor of 2 beyond them refuses no
#: such calibration, while a unit slip (metres or µm for mm: a factor of 1000) is far outside.
#: (Two-point at fields on both sides of the axis gives a chord slope of the curve instead,
#: which a strongly distorting lens can put outside them.)
GIVEN_FACTOR = 2.0


def check_given_constant(value: object, curve: DistortionCurve, what: str) -> float:
    """The calibrated constant ``value`` of method ``given`` as a float, checked against the
    curve (:data:`GIVEN_FACTOR`).

    Raises
    ------
    CalibrationError
        Naming ``value=``: not a finite nonzero number, of the other sign than K0, or outside a
        factor of :data:`GIVEN_FACTOR` of the curve's scales; for F (mm) a value that would fit in
        metres or micrometres says so.
    """
    s = curve.symbol
    ok = isinstance(value, numbers.Real) and not isinstance(value, bool)
    v = float(value) if ok else math.nan  # type: ignore[arg-type]
    if not (math.isfinite(v) and v != 0.0):
        raise CalibrationError(
            f"{what}: value= must be a finite nonzero number, the calibrated constant {s}_c"
            f"{'' if curve.finite else ' in mm'}, got {value!r}"
        )
    K0 = curve.constant
    if v * K0 < 0:
        raise CalibrationError(
            f"{what}: {s}_c = {value!r} must have the sign of {s}0 = {K0:.6g} (a calibration "
            "rescales the image; it does not flip it)"
        )
    off = (curve.x != 0.0) & np.isfinite(curve.yp)
    scales = np.append(curve.yp[off] / curve.x[off] / K0, 1.0)
    lo, hi = float(np.min(scales)) / GIVEN_FACTOR, float(np.max(scales)) * GIVEN_FACTOR
    q = v / K0
    if lo <= q <= hi:
        return v
    unit = "" if curve.finite else " mm"
    head = f"{what}: value={v:g} is {q:.4g} times {s}0 = {K0:.6g}{unit}"
    if not curve.finite:
        for factor, name in ((1000.0, "metres"), (1e-3, "micrometres")):
            if lo <= q * factor <= hi:
                raise CalibrationError(
                    f"{head}: it looks like {name}; {s}_c is in mm (value={v * factor:g})"
                )
    raise CalibrationError(
        f"{head}, beyond a factor of {GIVEN_FACTOR:g} of the curve's scales y'/x "
        f"({K0 * lo * GIVEN_FACTOR:.6g} … {K0 * hi / GIVEN_FACTOR:.6g}{unit}): no calibration of "
        "this curve gives it"
    )


def _minimax(x: np.ndarray, r: np.ndarray) -> float:
    """Exact argmin over K of max_i |r_i − K x_i| (Chebyshev fit of a line through the origin).

    Linear program (variables K, t; minimise t subject to ±(r_i − K x_i) ≤ t) solved by HiGHS,
    then polished: the optimum of this convex piecewise-linear function of K is the intersection
    of an active decreasing line and an active increasing line, computed in closed form.
    """
    from scipy.optimize import linprog

    n = x.size
    scale = float(np.max(np.abs(x)))
    xs = x / scale  # K' = K*scale keeps the LP well conditioned
    A = np.zeros((2 * n, 2))
    A[:n, 0], A[:n, 1] = -xs, -1.0  # r - K x <= t  ->  -x K - t <= -r
    A[n:, 0], A[n:, 1] = xs, -1.0  # -(r - K x) <= t ->  x K - t <= r
    b = np.concatenate([-r, r])
    res = linprog([0.0, 1.0], A_ub=A, b_ub=b, bounds=[(None, None), (0.0, None)], method="highs")
    if not res.success:  # pragma: no cover - an LP this small always solves
        raise CalibrationError(f"minimax calibration failed: {res.message}")
    K = float(res.x[0]) / scale

    def worst(k: float) -> float:
        return float(np.max(np.abs(r - k * x)))

    best, bestv = K, worst(K)
    e = r - K * x
    m = np.max(np.abs(e))
    active = np.nonzero(np.abs(np.abs(e) - m) <= 1e-7 * max(m, 1e-300) + 1e-15)[0]
    # slope of |e_i| as a function of K at the active set: -x_i sign(e_i)
    dec = [i for i in active if -x[i] * np.sign(e[i]) < 0]
    inc = [i for i in active if -x[i] * np.sign(e[i]) > 0]
    for i in dec:
        for j in inc:
            # sign(e_i)(r_i - K x_i) = sign(e_j)(r_j - K x_j)
            si, sj = np.sign(e[i]), np.sign(e[j])
            den = si * x[i] - sj * x[j]
            if den != 0.0:
                k = float((si * r[i] - sj * r[j]) / den)
                v = worst(k)
                if v <= bestv:
                    best, bestv = k, v
    return best


def fit_scale(
    x: np.ndarray,
    r: np.ndarray,
    method: str,
    *,
    idx: list[int] | None = None,
    given: float | None = None,
) -> float:
    """The scale K of the line ``r ≈ K·x`` by a calibration method (see module docstring).

    ``idx`` are the indices of the chosen fields for ``two-point`` (two) and ``zero-at`` (one).
    Raises :class:`CalibrationError` for an unknown method or a degenerate request.
    """
    x = np.asarray(x, dtype=float)
    r = np.asarray(r, dtype=float)
    require_choice(method, METHODS, "calibration method", CalibrationError)
    if method == "given":
        if given is None or not math.isfinite(given) or given == 0.0:
            raise CalibrationError("method 'given' needs a finite nonzero calibrated constant")
        return float(given)
    off = x != 0.0
    if method == "two-point":
        if idx is None or len(idx) != 2:
            raise CalibrationError("method 'two-point' needs exactly two fields (at=(A, B))")
        a, b = idx
        if a == b or x[a] == 0.0 or x[b] == 0.0 or x[a] + x[b] == 0.0:
            raise CalibrationError(
                "method 'two-point' needs two different off-axis fields (D_c is 0 on the axis "
                "for every constant)"
            )
        return float((r[a] + r[b]) / (x[a] + x[b]))
    if method == "zero-at":
        if idx is None or len(idx) != 1:
            raise CalibrationError("method 'zero-at' needs exactly one field (at=A)")
        a = idx[0]
        if x[a] == 0.0:
            raise CalibrationError(
                "method 'zero-at' needs an off-axis field (D_c is 0 on the axis)"
            )
        return float(r[a] / x[a])
    if np.count_nonzero(off) < 2:
        raise CalibrationError(
            f"method {method!r} needs at least two off-axis field points, got "
            f"{np.count_nonzero(off)}"
        )
    if method == "least-squares":
        sol, *_ = np.linalg.lstsq(x[:, None], r, rcond=None)
        return float(sol[0])
    return _minimax(x[off], r[off])


@dataclass(frozen=True, eq=False)
class CalibrationResult:
    """A calibrated distortion curve (one row of Pestrecov's Table II per field).

    Kc, K0: calibrated and characteristic constants: F_c, F0 in mm (object at infinity) or
        M_c, M0 (finite conjugates); ``symbol`` says which ("F" / "M").
    scale_error: ``Kc/K0 − 1`` = tan ρ (Eq. 13).
    rho_deg, k, rho_k_deg: ρ and, for plot exaggeration k, ρ_k with tan ρ_k = k·tan ρ (Eq. 14).
    ycp: calibrated image size ``y_c' = Kc·x`` (mm). Dc: ``y' − y_c'`` (mm), Eqs. (10)–(12).
    Drc: ``y'/y_c' − 1`` as a fraction, Eq. (15) (on the axis its limit, the constant term).
    Drc_axis: ``K0/Kc − 1``, the constant term of Eq. (15) (fraction).
    Dc_max_abs, Dc_spread (max − min of D_c, mm), Drc_spread, Dr_spread (fractions),
    D0_max_abs, D0_spread (mm) summarise the field points.
    """

    curve: DistortionCurve
    method: str
    at: tuple[float, ...]
    Kc: float
    k: float
    ycp: np.ndarray
    Dc: np.ndarray
    Drc: np.ndarray

    @property
    def symbol(self) -> str:
        return self.curve.symbol

    def __repr__(self) -> str:
        at = f" at {', '.join(f'{a:g}' for a in self.at)}" if self.at else ""
        unit = "" if self.curve.finite else " mm"
        s = self.symbol
        return (
            f"CalibrationResult({self.method}{at}: {s}_c = {self.Kc:.6f}{unit}, "
            f"{s}0 = {self.K0:.6f}{unit}, max |D_c| = {self.Dc_max_abs:.6g} mm, "
            f"D_rc on the axis = {100 * self.Drc_axis:+.4f} %)"
        )

    @property
    def K0(self) -> float:
        return self.curve.constant

    @property
    def scale_error(self) -> float:
        return self.Kc / self.K0 - 1.0

    @property
    def rho_deg(self) -> float:
        return math.degrees(math.atan(self.scale_error))

    @property
    def rho_k_deg(self) -> float:
        return math.degrees(math.atan(self.k * self.scale_error))

    @property
    def Drc_axis(self) -> float:
        return self.K0 / self.Kc - 1.0

    @property
    def Dc_max_abs(self) -> float:
        return float(np.max(np.abs(self.Dc)))

    # spreads run over the whole curve, whose axis point (D0 = Dr = Dc = 0, Drc = Drc_axis) is
    # there whether or not the table lists it: Pestrecov's spreads of Table I (0.355 mm, 0.298 %)
    @property
    def Dc_spread(self) -> float:
        return axis_spread(self.Dc, 0.0)

    @property
    def Drc_spread(self) -> float:
        return axis_spread(self.Drc, self.Drc_axis)

    @property
    def D0_max_abs(self) -> float:
        return float(np.max(np.abs(self.curve.D0)))

    @property
    def D0_spread(self) -> float:
        return axis_spread(self.curve.D0, 0.0)

    @property
    def Dr_spread(self) -> float:
        return axis_spread(self.curve.Dr, 0.0)

    @property
    def yp(self) -> np.ndarray:
        """Actual image size, the same before and after calibration: ``y_c' + D_c``."""
        return self.ycp + self.Dc


def calibrate(
    distortion: DistortionCurve | CharacteristicDistortion,
    method: str = "minimax",
    *,
    at: float | Sequence[float] | str | None = None,
    value: float | None = None,
    k: float = 200.0,
    plane: int = 0,
) -> CalibrationResult:
    """Calibrate a characteristic distortion curve (Pestrecov Eqs. 10–15).

    Parameters
    ----------
    distortion : DistortionCurve or CharacteristicDistortion
        The characteristic curve: a table (:func:`distortion.tablefile.read_distortion_table`)
        or a traced result (its image plane number ``plane``, 0-based).
    method : {"two-point", "minimax", "least-squares", "zero-at", "given"}
        How the calibrated constant K_c (F_c in mm, or M_c) is chosen (module docstring):
        equal and opposite D_c at the two ``at`` fields (the paper's example), the smallest
        maximum |D_c| (exact; the default, the one that needs no fields), least squares,
        D_c = 0 at the ``at`` field, or ``value``.
    at : float, sequence of float or "A,B", optional
        Field values (same kind and unit as the curve's fields: degrees or mm) for
        ``two-point`` (two) and ``zero-at`` (one); they must be field points of the curve.
    value : float, optional
        F_c (mm) or M_c for ``given``: finite, of the sign of K0 and within a factor of
        :data:`GIVEN_FACTOR` (2) of the curve's own scales (K0 and y'/x at its field points,
        where every criterion puts K_c); beyond that it is refused, and an F_c that would fit in
        metres or micrometres is refused as looking like them (0.154 for 154 mm).
    k : float
        Plot exaggeration for ρ_k (Eq. 14; the paper's Fig. 2 uses 200).
    plane : int
        Which image plane of a traced result (0-based).

    Returns
    -------
    CalibrationResult
        K_c, D_c (mm), D_rc (fraction), ρ, ρ_k and spreads (one row of Table II per field).
    """
    what = f"calibration ({method})"
    try:
        if at is None:
            at_t: tuple[float, ...] = ()
        elif isinstance(at, str):  # "37.5,45", as the command line writes it
            at_t = tuple(float(a) for a in at.split(",") if a.strip())
        elif np.ndim(at) == 0:
            at_t = (float(at),)  # type: ignore[arg-type]
        else:
            at_t = tuple(float(a) for a in at)  # type: ignore[union-attr]
    except (TypeError, ValueError):
        raise CalibrationError(
            f"{what}: at={at!r} is not a field value or a list of them (e.g. at=(37.5, 45))"
        ) from None
    curve = _as_curve(distortion, plane, at_t)
    require_choice(method, METHODS, "calibration method", CalibrationError)
    if isinstance(k, bool) or not (isinstance(k, numbers.Real) and k > 0 and math.isfinite(k)):
        raise CalibrationError(f"k={k!r}: the plot exaggeration of Eq. 14 is a positive number")
    if curve.fields.size < 2:
        raise CalibrationError(f"{what}: a curve needs at least two field points")
    idx = calibration_fields(curve.fields, method, at_t, angles=curve.field_kind != HEIGHT)
    if method == "given" and value is None:
        raise CalibrationError(f"{what} needs the calibrated constant {curve.symbol}_c (value=)")
    if method != "given" and value is not None:
        raise CalibrationError(
            f"{what} chooses {curve.symbol}_c itself: value= goes with method 'given'"
        )
    given = check_given_constant(value, curve, what) if method == "given" else None
    Kc = fit_scale(curve.x, curve.yp, method, idx=idx, given=given)
    if not math.isfinite(Kc) or Kc == 0.0:
        raise CalibrationError(f"{what} gave a degenerate constant {Kc!r}")
    ycp = Kc * curve.x
    Dc = curve.yp - ycp
    # D_rc = y'/y_c' − 1 off the axis; on the axis its limit, the constant term of Eq. (15)
    # (for a characteristic curve y' = K0 x + D0 this is D_r K0/Kc + (K0/Kc − 1), Eq. 15)
    with np.errstate(divide="ignore", invalid="ignore"):
        Drc = np.where(
            ycp != 0.0, curve.yp / np.where(ycp != 0.0, ycp, 1.0) - 1.0, curve.constant / Kc - 1.0
        )
    return CalibrationResult(curve, method, at_t, float(Kc), float(k), ycp, Dc, Drc)


def _as_curve(d, plane: int, at=None) -> DistortionCurve:
    if isinstance(d, DistortionCurve):
        return d
    if hasattr(d, "curve") and hasattr(d, "n_planes"):
        if not is_whole(plane):
            raise CalibrationError(f"plane={plane!r}: the image plane's number (0-based), an int")
        if not 0 <= int(plane) < d.n_planes:
            raise CalibrationError(
                f"plane={plane}: the result has {d.n_planes} image plane(s) (0-based index)"
            )
        from raytrace.trace.results import status_name

        for a in np.atleast_1d(np.asarray(at if at is not None else [], dtype=float)):
            hit = np.nonzero(np.isclose(d.fields, a, rtol=0, atol=1e-9 * max(1.0, abs(a))))[0]
            if hit.size and d.status[hit[0]] != 0:
                name = status_name(d.status[hit[0]])
                raise CalibrationError(
                    f"field {a:g} could not be traced (status {name}): calibrate at fields "
                    "the lens passes"
                )
        return d.curve(int(plane))
    hint = (
        ": pick one wavelength, e.g. result.at(587.5618) (nm; or result[0], in the order of its "
        "wavelengths)"
        if hasattr(d, "n_wavelengths")
        else ""
    )
    raise CalibrationError(
        f"expected a DistortionCurve or a CharacteristicDistortion, got {type(d).__name__}{hint}"
    )
