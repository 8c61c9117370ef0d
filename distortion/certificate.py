"""The calibration certificate of a design: what a camera-calibration laboratory would report for
a camera built exactly to the prescription, predicted by real chief rays at a stated object
distance, wavelength, image plane and reference point (docs/design.md, "Sensor metrics and the
calibration certificate").

The form follows the aerial-camera calibration reports of the USGS Optical Science Laboratory and
the ASPRS *Manual of Photogrammetry* (4th ed. 1980, ch. 4 "Camera calibration"): calibrated focal
length, the principal points of autocollimation (PPA) and of best symmetry (PPBS), radial
distortion along the four semi-diagonals of the format at regular field steps and their mean, and
the decentering distortion profile with its axis. It is a *prediction* of the design, not a
measurement, and says so.

The format
    A sensor (``sensor=``: its four corners, seen from the lens axis; the semi-diagonals run from
    the axis to the corners, their azimuths ``atan2(corner)``) or, without one, the circle of the
    lens's field (semi-diagonals at 45°, 135°, 225°, 315°). Coordinates on the certificate are in
    mm in the photogrammetric image frame: x right, y up, looking from the image toward the lens
    (the lens frame of :mod:`distortion.grid.field`), origin at the sensor centre (with a sensor)
    or on the lens axis. A format whose corner chief rays do not trace is refused, with the
    largest field out to which they do: the calibrated focal length is balanced over the
    format the page states, never over a smaller traced part of it. (Fields inside the format
    that fail are left empty and counted in a note.)

Radial distortion (µm, + outward = pincushion)
    Along the semi-diagonal of azimuth φ, for the field θ (``tan θ = |t|``, t the normalised ideal
    coordinates of :mod:`distortion.grid.field`; nominal angles for a finite object): the actual
    radial distance of the image from the reference point R, ``r' = (P' − R)·(cos φ, sin φ)``,
    minus the calibrated one ``c_c tan θ``::

        Δr(θ, φ) = r'(θ, φ) − c_c tan θ

    The mean over the four semi-diagonals is the symmetric radial distortion. R is named
    (``reference_point``): the PPBS (default: the point of best symmetry, about which the
    laboratory reduces radial distortion), the PPA or the image of the axial object point.

Calibrated focal length c_c (the criterion)
    ASPRS (*Manual of Photogrammetry*, glossary; the definition the USGS reports used for film
    cameras): the calibrated focal length is "an adjusted value of the equivalent focal length,
    so computed as to equalize the positive and negative values of distortion over the entire
    field used". That is Pestrecov's calibration (Eqs. 10–15) with the ``minimax`` criterion of
    :mod:`distortion.calibration`: the line ``c_c tan θ`` through the origin that makes the
    largest positive and largest negative mean radial distortion over the format equal in
    magnitude (the Chebyshev fit, solved exactly), on a dense set of fields from the axis to the
    longest semi-diagonal. ``method="least-squares"`` gives the least-squares line instead.
    Pestrecov (1958, Section IV) explains why the choice is the photogrammetrist's ("a search for
    a most favorable scale ... that would minimize the position errors"), and the report states
    it. For a finite object it is the calibrated *principal distance* (mm), the same fit.

Principal points (mm)
    ``ppa``: the image of the object at infinity normal to the image plane; ``ppbs``: the
    principal point of a purely radial least-squares fit to the format's polar grid of fields;
    ``axial``: the image of the axial object point (definitions in :mod:`distortion.grid.field`).
    The format's *polar grid*: fields every 15° of azimuth (and on the semi-diagonals and
    opposite them), 30 per
    azimuth equally spaced in tan θ, out to the boundary of the largest part of the format that
    is symmetric about the axis (t → −t; the whole format when the axis is at its centre). On
    such a grid the PPBS is the centroid of the image points, so for a centred lens it is the
    axis and the decentering below is zero, to round-off.

Decentering
    From the 2-D decomposition of :mod:`distortion.grid.decompose` (distortion form, the
    principal point held at R, the camera constant and five radial terms fitted with P1, P2, S1,
    S2) on the format's polar grid (above): the profile ``P(r) = J r²`` with ``J = √(P1² + P2²)``
    (mm⁻¹; the tangential decentering distortion across its axis, USGS "profile function"),
    tabulated at the radii ``r = c_c tan θ`` of the table, and the axis ψ (degrees from +x
    toward +y) along which the radial decentering distortion is largest (3 J r²); Brown's φ0, the
    axis of maximum tangential distortion, is ψ − 90°. Below ``DECENTERING_FLOOR_MM`` at the edge
    of the format (a centred design) the fitted P1, P2 are round-off of the symmetric sums (for
    the bundled centred lenses J = 7e-20 to 1.4e-18 mm⁻¹, J r² at the edge 3e-13 to 2e-11 µm):
    P1, P2, J and the profile are given as exactly 0 and the axis as NaN, with a note. The floor
    (1e-9 mm = 1e-6 µm at the edge) lies five orders of magnitude below the printed 0.1 µm and
    more than four above that round-off. The thin-prism terms S1, S2 of the same fit (JSON only)
    are treated the same way (``√(S1² + S2²) r²`` at the edge below the floor: 0).

A decentered or tilted lens (``Lens.is_centred`` false) takes its first-order data — Pestrecov's
constants, the Gaussian plane, the field's nominal angles — from its centred lens
(``Lens.nominal()``); its chief rays are traced through the lens as it is.

Radial coefficients (USGS form)
    A least-squares fit of the mean Δr on the dense fields: ``Δr = k0 r + k1 r³ + k2 r⁵ + k3 r⁷``
    (r = c_c tan θ, mm), with its RMS residual.

Work limit
    The semi-diagonals' chief rays (tabulated fields, the dense fields and the corners, on each of
    the four) are counted from the step and the format before anything is traced; more than
    :data:`raytrace.limits.MAX_FIELDS` is refused unless ``allow_large=True`` (``--allow-large``
    on the command line): ``field_step_deg=1e-6`` would take tens of GB.
"""

from __future__ import annotations

import datetime as _dt
import math
import warnings
from dataclasses import dataclass

import numpy as np

from raytrace.errors import TraceError
from raytrace.lens import Lens
from raytrace.limits import MAX_FIELDS

from .errors import DataError

#: methods (criteria) of the calibrated focal length (:mod:`distortion.calibration` methods)
METHODS = ("minimax", "least-squares")
#: reference points the radial distortion may be measured from
CERTIFICATE_POINTS = ("ppbs", "ppa", "axial")
#: default step of the tabulated fields (degrees)
FIELD_STEP_DEG = 7.5
#: dense fields per semi-diagonal (plots, the focal-length fit, the coefficients)
DENSE_FIELDS = 91
#: the format's polar grid of the decomposition: azimuth step (deg) and fields per azimuth
POLAR_AZIMUTH_STEP_DEG = 15.0
POLAR_FIELDS = 30
#: radial terms of the decomposition that gives the decentering
RADIAL_TERMS = 5
#: a decentering profile below this at the edge of the format (mm) is round-off of a centred
#: design: given as 0, with no axis (module docstring, "Decentering")
DECENTERING_FLOOR_MM = 1e-9
#: memory of one chief ray of the semi-diagonals, for the work limit's message (measured: about
#: 820 bytes of peak RSS per ray, cooke-triplet-f4 at field_step_deg=0.001)
BYTES_PER_RAY = 800

METHOD_TEXT = {
    "minimax": (
        "minimax: equal largest positive and negative mean radial distortion over the format "
        "(ASPRS: 'so computed as to equalize the positive and negative values of distortion "
        "over the entire field used'); Pestrecov 1958 Eqs. 10-15"
    ),
    "least-squares": (
        "least squares: minimum sum of squared mean radial distortion over the format's dense "
        "fields; Pestrecov 1958 Eqs. 10-15"
    ),
}


@dataclass(frozen=True, eq=False)
class CalibrationCertificate:
    """The predicted calibration of a design (module docstring). Angles in degrees, lengths in mm,
    distortions in µm (arrays ``..._um``); coordinates x right, y up from the ``origin``.

    Attributes
    ----------
    name, source : str
        Lens name and its source line.
    date : str
        ISO date of the computation.
    object_distance : float
        mm from the object plane to the first vertex (inf).
    wavelength : float
        nm.
    s_prime, from_last_vertex, defocus : float
        The image plane (mm from H', from the last vertex, from the Gaussian plane).
    plane_label : str
    field_kind : str
        ``"angle"`` (object at infinity) or ``"nominal-angle"`` (finite object).
    format : str
        What the semi-diagonals span ("sensor 36 x 24 mm" or "lens field 45 deg").
    sensor : object
        The sensor (Sensor or (w, h) mm) or None.
    origin : str
        ``"sensor centre"`` or ``"lens axis"``.
    reference_point : str
        R of the radial distortion (``CERTIFICATE_POINTS``).
    paraxial_constant_mm : float
        c0: Pestrecov's F0 (EFL in the Gaussian plane) or M0·p0 (mm).
    calibrated_focal_length_mm : float
        c_c (mm).
    method : str
        The criterion of c_c (``METHODS``).
    ppa_mm, ppbs_mm, axial_mm, reference_mm : ndarray
        (2,) the named points in the certificate's frame (mm).
    azimuths_deg : ndarray
        (4,) the semi-diagonals' azimuths.
    max_fields_deg : ndarray
        (4,) the field at each corner (the format's extent along it).
    fields_deg : ndarray
        (n,) tabulated fields.
    radius_mm : ndarray
        (n,) c_c tan θ.
    radial_um : ndarray
        (4, n) Δr per semi-diagonal (NaN beyond its corner or not traced).
    tangential_um : ndarray
        (4, n) the tangential component (counter-clockwise; µm).
    mean_radial_um : ndarray
        (n,) mean over the semi-diagonals that reach the field.
    dense_fields_deg, dense_radial_um, dense_mean_radial_um : ndarray
        (m,), (4, m), (m,) the same on the dense fields.
    decentering : dict
        P1, P2 (mm⁻¹), J (mm⁻¹), axis_deg (ψ), phi0_deg (Brown's φ0), S1, S2 (mm⁻¹),
        residual_rms_um of the decomposition.
    decentering_profile_um, dense_decentering_profile_um : ndarray
        (n,), (m,) J r² at the tabulated and dense fields.
    radial_coefficients : dict
        k0, k1 (mm⁻²), k2 (mm⁻⁴), k3 (mm⁻⁶) and rms_um.
    notes : tuple of str
    """

    name: str
    source: str
    date: str
    object_distance: float
    wavelength: float
    s_prime: float
    from_last_vertex: float
    defocus: float
    plane_label: str
    field_kind: str
    format: str
    sensor: object
    origin: str
    reference_point: str
    paraxial_constant_mm: float
    calibrated_focal_length_mm: float
    method: str
    ppa_mm: np.ndarray
    ppbs_mm: np.ndarray
    axial_mm: np.ndarray
    reference_mm: np.ndarray
    azimuths_deg: np.ndarray
    max_fields_deg: np.ndarray
    fields_deg: np.ndarray
    radius_mm: np.ndarray
    radial_um: np.ndarray
    tangential_um: np.ndarray
    mean_radial_um: np.ndarray
    dense_fields_deg: np.ndarray
    dense_radial_um: np.ndarray
    dense_mean_radial_um: np.ndarray
    decentering: dict
    decentering_profile_um: np.ndarray
    dense_decentering_profile_um: np.ndarray
    radial_coefficients: dict
    notes: tuple[str, ...] = ()

    @property
    def finite(self) -> bool:
        return not math.isinf(self.object_distance)

    @property
    def method_text(self) -> str:
        """The criterion of the calibrated focal length, with its source."""
        return METHOD_TEXT[self.method]

    @property
    def semi_diagonal_labels(self) -> tuple[str, ...]:
        """'+x +y' style quadrant labels of the semi-diagonals."""
        out = []
        for a in self.azimuths_deg:
            c, s = math.cos(math.radians(a)), math.sin(math.radians(a))
            out.append(f"{'+' if c >= 0 else '-'}x {'+' if s >= 0 else '-'}y")
        return tuple(out)

    @property
    def max_abs_radial_um(self) -> float:
        v = np.abs(self.dense_mean_radial_um)
        return float(np.nanmax(v)) if np.isfinite(v).any() else math.nan

    def __repr__(self) -> str:
        obj = "inf" if not self.finite else f"{self.object_distance:g} mm"
        return (
            f"CalibrationCertificate({self.name!r}, object {obj}, {self.wavelength:g} nm, "
            f"{self.format}: calibrated focal length {self.calibrated_focal_length_mm:.4f} mm "
            f"({self.method}), PPBS ({self.ppbs_mm[0]:.4g}, {self.ppbs_mm[1]:.4g}) mm, "
            f"max |mean radial| {self.max_abs_radial_um:.4g} um, decentering J = "
            f"{self.decentering['J']:.3g} mm^-1)"
        )


# ------------------------------------------------------------------------------------------------


def _format(lens: Lens, par, c0: float, sensor, max_field_deg):
    """(corners (4, 2) in the lens frame or None, extent function φ → tan θ_max, offset (2,),
    label)."""
    if sensor is not None:
        from .camera.sensor import Sensor
        from .grid.field import sensor_size

        s = sensor_size(sensor)  # positive, finite width and height
        if isinstance(s, Sensor):
            w, h = s.width_mm, s.height_mm
            off = np.asarray(s.principal_point_offset_mm, dtype=float)
        else:
            w, h = s
            off = np.zeros(2)
        # the sensor in the lens frame: the axis lies at ``off`` from its centre
        xlo, xhi = -w / 2 - off[0], w / 2 - off[0]
        ylo, yhi = -h / 2 - off[1], h / 2 - off[1]
        if not (xlo < 0 < xhi and ylo < 0 < yhi):
            raise DataError(
                "the lens axis lies outside the sensor (principal-point offset larger than half "
                "the sensor): the semi-diagonals start on the axis"
            )
        corners = np.array([[xhi, yhi], [xlo, yhi], [xlo, ylo], [xhi, ylo]])

        def extent(phi: np.ndarray) -> np.ndarray:
            c, s_ = np.cos(phi), np.sin(phi)
            with np.errstate(divide="ignore"):
                bx = np.where(c > 0, xhi / c, np.where(c < 0, xlo / c, np.inf))
                by = np.where(s_ > 0, yhi / s_, np.where(s_ < 0, ylo / s_, np.inf))
            return np.minimum(bx, by) / c0

        label = f"sensor {w:g} x {h:g} mm"
        return corners, extent, off, label
    if max_field_deg is None:
        if lens.field.kind == "angle":
            max_field_deg = float(lens.field.value)
        else:  # an object height: its nominal angle
            max_field_deg = math.degrees(math.atan(abs(float(lens.field.value) / par.p0)))
    T = math.tan(math.radians(float(max_field_deg)))

    def extent_circle(phi: np.ndarray) -> np.ndarray:
        return np.full(np.shape(phi), T)

    rho = T * c0
    a = np.radians([45.0, 135.0, 225.0, 315.0])
    corners = rho * np.column_stack([np.cos(a), np.sin(a)])
    return corners, extent_circle, np.zeros(2), f"lens field {float(max_field_deg):g} deg"


def _check_corners(lens, par, clip, ok, az, th_max, dense, nt, fmt, c0, is_sensor) -> None:
    """Refuse a format whose corner chief rays do not trace: the calibrated focal length would
    be balanced over a smaller field than the page states. ``ok`` (4, nt + nd + 4): the trace
    status of the tabulated, dense and corner fields of each semi-diagonal. The message gives
    the largest field out to which every chief ray of that semi-diagonal traces (to 0.1°)."""
    nd = dense.size
    failed = [i for i in range(az.size) if not ok[i, nt + nd + i]]
    if not failed:
        return
    limits = {i: _traceable_limit(lens, par, clip, az[i], ok[i, nt : nt + nd], dense, th_max[i])
              for i in failed}  # fmt: skip
    i = min(limits, key=limits.get)
    lim = math.floor(limits[i] * 10.0) / 10.0
    c, s = math.cos(az[i]), math.sin(az[i])
    label = f"{'+' if c >= 0 else '-'}x {'+' if s >= 0 else '-'}y"
    if lim > 0:
        reach = f"chief rays trace only to {lim:.1f} deg along it"
        fix = f"give a format within {lim:.1f} deg"
        if is_sensor:
            fix += f" (a sensor whose corners lie within {c0 * math.tan(math.radians(lim)):.1f} mm"
            fix += " of the lens axis)"
        else:
            fix += " (a smaller max field)"
    else:
        reach = "no chief ray off the axis traces along it"
        fix = "check the lens's apertures (semi-diameters) and the object"
    raise DataError(
        f"the format ({fmt}) reaches {th_max[i]:.4g} deg at its {label} corner, but {reach}: {fix}"
    )


def _check_rows(lens, par, clip, c0, sensor, max_field_deg, fmt, theta_max, step) -> None:
    """Refuse a format too small for any tabulated field: its corner ``theta_max`` (deg) within
    5 % of ``step`` (:func:`_table_steps`) leaves the certificate's table empty. The message names
    what set the format (``sensor``, ``max_field_deg`` or the lens's field) and the fix: a sensor
    whose size read as metres gives a format that traces (its four corner chief rays) "looks
    like metres"; otherwise a larger format or the largest ``field_step_deg`` that gives a row
    (the corner itself, tabulated when it lies more than 5 % of a step out)."""
    if _table_count(theta_max, step) > 0:
        return
    # a row needs theta_max > 0.05 step: the largest step that gives one, rounded down to two
    # significant digits, and checked as the table counts rows (0.05 * 6.0 is 0.30000000000000004
    # in floating point, so a format of 0.3 deg gets no row at the bound 6.0 itself)
    bound = theta_max / 0.05
    e = math.floor(math.log10(bound)) - 1
    best = math.floor(bound / 10.0**e) * 10.0**e
    while best > 0 and _table_count(theta_max, best) == 0:
        best -= 10.0**e
    smaller = f"field_step_deg={best:.{max(-e, 0)}f} or less"
    why = (
        f"reaches only {theta_max:.3g} deg off the lens axis, not more than 5 % of "
        f"field_step_deg={step:g} ({0.05 * step:.3g} deg), so the certificate would have no "
        "tabulated field"
    )
    if sensor is None:
        if max_field_deg is not None:
            raise DataError(
                f"max_field_deg={float(max_field_deg):g}: the format {why}; give a larger "
                f"max_field_deg= or {smaller}"
            )
        raise DataError(
            f"the lens's field ({fmt}) {why}; give a larger max_field_deg= or a sensor, or "
            f"{smaller}"
        )
    from raytrace.trace.chief2d import aim_2d

    from .camera.sensor import Sensor
    from .grid.field import sensor_size

    s = sensor_size(sensor)
    w, h = (s.width_mm, s.height_mm) if isinstance(s, Sensor) else s
    # the same size in metres: does the certificate's format trace (its four corners)?
    T = 1000.0 * math.hypot(w, h) / 2.0 / c0
    metres = False
    if math.degrees(math.atan(T)) < 89.0:
        a = np.arctan2([h, h, -h, -h], [w, -w, -w, w])
        FX = np.degrees(np.arctan(T * np.cos(a)))
        FY = np.degrees(np.arctan(T * np.sin(a)))
        cr = aim_2d(lens, FX, FY, "angle", par.object_distance, par.wavelength, clip)
        metres = bool(np.all(np.asarray(cr.ok)))
    label = f"sensor {w:g}x{h:g} (mm)"
    if metres:
        raise DataError(
            f"{label}: the format {why}; it looks like metres: give the size in mm, "
            f"'{1000 * w:g}x{1000 * h:g}' (or write '{w:g}x{h:g}m')"
        )
    raise DataError(f"{label}: the format {why}; give a larger sensor (mm) or {smaller}")


def _traceable_limit(lens, par, clip, azimuth, ok_dense, dense, theta_corner) -> float:
    """The largest field (deg) along ``azimuth`` out to which every chief ray traces: the first
    dense field that fails (or the corner) bracketed, then traced on 64 steps between."""
    from raytrace.trace.chief2d import aim_2d

    inside = dense <= theta_corner * (1 + 1e-12)
    bad = np.flatnonzero(inside & ~ok_dense)
    if bad.size:
        j = int(bad[0])
        if j == 0:
            return 0.0
        lo, hi = float(dense[j - 1]), float(dense[j])
    else:
        lo, hi = float(dense[inside][-1]), float(theta_corner)
    f = np.linspace(lo, hi, 65)
    T = np.tan(np.radians(f))
    FX = np.degrees(np.arctan(T * math.cos(azimuth)))
    FY = np.degrees(np.arctan(T * math.sin(azimuth)))
    cr = aim_2d(lens, FX, FY, "angle", par.object_distance, par.wavelength, clip)
    miss = np.flatnonzero(~np.asarray(cr.ok))
    return float(f[miss[0] - 1]) if miss.size and miss[0] > 0 else lo


def _table_steps(theta_max: float, step: float) -> tuple[int, bool]:
    """(n, edge): the tabulated fields are step, 2 step, ..., n step, then ``theta_max`` itself
    when ``edge`` (it lies more than 5 % of a step beyond n step)."""
    n = int(math.floor(theta_max / step + 1e-9))
    return n, theta_max - n * step > 0.05 * step


def _table_count(theta_max: float, step: float) -> int:
    """The number of tabulated fields of :func:`_table_fields`, without making them."""
    n, edge = _table_steps(theta_max, step)
    return n + int(edge)


def _table_fields(theta_max: float, step: float) -> np.ndarray:
    n, edge = _table_steps(theta_max, step)
    f = step * np.arange(1, n + 1)
    return np.append(f, theta_max) if edge else f


def _check_work(theta_max: float, step: float, n_diagonals: int, allow_large: bool) -> None:
    """Refuse more than ``MAX_FIELDS`` chief rays on the semi-diagonals (tabulated, dense and
    corner fields) without ``allow_large``, before anything is made or traced."""
    nt = _table_count(theta_max, step)
    rays = n_diagonals * (nt + DENSE_FIELDS + n_diagonals)  # the corners: one trace
    if rays > MAX_FIELDS and not allow_large:
        smallest = theta_max / max(MAX_FIELDS // n_diagonals - DENSE_FIELDS - n_diagonals - 1, 1)
        raise DataError(
            f"field_step_deg={step:g}: {nt} tabulated fields on each of the {n_diagonals} "
            f"semi-diagonals ({rays} chief rays), more than {MAX_FIELDS} (about "
            f"{rays * BYTES_PER_RAY / 1e9:.3g} GB and a long run); give a step of at least "
            f"{_round_up(smallest)} deg, or allow_large=True to run it anyway"
        )


def _round_up(x: float) -> str:
    """``x`` rounded up to two significant digits, as text (the smallest step allowed)."""
    if not x > 0:
        return f"{x:g}"
    e = math.floor(math.log10(x)) - 1
    return f"{math.ceil(x / 10.0**e - 1e-9) * 10.0**e:.{max(-e, 0)}f}"


def iso_date(text: str) -> str:
    """``text`` as an ISO date ``YYYY-MM-DD`` (:class:`DataError` when it is not one)."""
    try:
        return _dt.date.fromisoformat(str(text)).isoformat()
    except ValueError:
        raise DataError(
            f"{text!r} is not a date; write it as YYYY-MM-DD, e.g. 2026-01-31"
        ) from None


def calibration_certificate(
    lens: Lens,
    *,
    sensor=None,
    object_distance: float | str | None = None,
    object_s: float | None = None,
    object_scale: float | None = None,
    plane=None,
    s_prime: float | None = None,
    from_last_vertex: float | None = None,
    defocus: float | None = None,
    wavelength: float | str | None = None,
    reference_point: str = "ppbs",
    method: str = "minimax",
    field_step_deg: float = FIELD_STEP_DEG,
    max_field_deg: float | None = None,
    date: str | None = None,
    clip: bool = True,
    allow_large: bool = False,
) -> CalibrationCertificate:
    """The predicted calibration certificate of ``lens`` (module docstring).

    Parameters
    ----------
    lens : Lens
    sensor : Sensor, str or (w, h), optional
        The format (mm; a Sensor may carry a principal-point offset). Default: the lens's field.
    object_distance, object_s, object_scale
        The object plane (docs/design.md, "Vocabulary"); default the lens's.
    plane, s_prime, from_last_vertex, defocus
        ONE image plane; default the Gaussian plane of the object.
    wavelength : float or str, optional
        nm; default the lens's reference wavelength.
    reference_point : {"ppbs", "ppa", "axial"}
        The point radial distortion is measured from.
    method : {"minimax", "least-squares"}
        The criterion of the calibrated focal length (module docstring; the calibration
        ``method`` of the vocabulary).
    field_step_deg : float
        Step of the tabulated fields (default 7.5°); the corner field is added when it is not a
        step.
    max_field_deg : float, optional
        The format's field without a sensor (default the lens's).
    date : str, optional
        The date printed, ISO ``YYYY-MM-DD`` (default today); anything else is refused.
    clip : bool
        Apply the lens's semi-diameters.
    allow_large : bool
        Lift the work limit: more than :data:`raytrace.limits.MAX_FIELDS` chief rays on the
        semi-diagonals (a very small ``field_step_deg``) is refused without it, before any
        trace (module docstring, "Work limit").

    Returns
    -------
    CalibrationCertificate
    """
    from raytrace.paraxial import (
        image_planes,
        paraxial,
        pestrecov_constants,
        plane_z,
        resolve_object_distance,
    )

    from .calibration import fit_scale
    from .grid import decentering_profile, grid_from_fields, solve_linear

    if reference_point not in CERTIFICATE_POINTS:
        raise DataError(
            f"reference_point={reference_point!r}; use one of {', '.join(CERTIFICATE_POINTS)}"
        )
    if method not in METHODS:
        raise DataError(f"method={method!r}; use one of {', '.join(METHODS)}")
    date = iso_date(date) if date is not None else _dt.date.today().isoformat()
    step = float(field_step_deg)
    if not (math.isfinite(step) and 0.0 < step < 90.0):
        raise DataError(f"field_step_deg={field_step_deg!r}: give a step between 0 and 90 degrees")
    if max_field_deg is not None and sensor is not None:
        raise DataError("give a sensor or max_field_deg, not both")
    if max_field_deg is not None and not 0.0 < float(max_field_deg) < 90.0:
        raise DataError(f"max_field_deg={max_field_deg!r}: give a field between 0 and 90 degrees")
    wl = None
    if wavelength is not None:
        from raytrace.units import UnitError, wavelength_nm

        try:
            wl = wavelength_nm(wavelength)
        except UnitError as e:
            raise TraceError(str(e)) from None
    # a decentered or tilted lens: first-order data (Pestrecov's constants, the planes) of its
    # centred lens; the chief rays through the lens as it is
    centred = lens if lens.is_centred else lens.nominal()
    od = resolve_object_distance(
        centred,
        object_distance=object_distance,
        object_s=object_s,
        object_scale=object_scale,
        wavelength=wl,
    )
    par = paraxial(centred, object_distance=od, wavelength=wl)
    planes = image_planes(
        plane, s_prime=s_prime, from_last_vertex=from_last_vertex, defocus=defocus
    )
    if len(planes) != 1:
        raise DataError(f"a certificate is for one image plane; {len(planes)} were given")
    z = plane_z(par, planes)
    sp = float(par.s_prime_of(z[0]))
    K0 = pestrecov_constants(par, sp).scale
    c0 = float(K0 if par.infinite else K0 * par.p0)
    if not c0 > 0:
        raise DataError(f"the paraxial principal distance {c0:g} mm is not positive")
    corners, extent, off, fmt = _format(lens, par, c0, sensor, max_field_deg)
    az = np.arctan2(corners[:, 1], corners[:, 0])
    T_max = np.hypot(corners[:, 0], corners[:, 1]) / c0  # tan θ at each corner
    th_max = np.degrees(np.arctan(T_max))
    if np.any(th_max >= 89.0):
        raise DataError("the format reaches 89 degrees or more; the certificate needs less")
    _check_rows(lens, par, clip, c0, sensor, max_field_deg, fmt, float(np.max(th_max)), step)
    _check_work(float(np.max(th_max)), step, int(az.size), allow_large)

    # 1. the semi-diagonals: tabulated and dense fields and the four corners in one trace (a
    # format whose corners do not trace is refused first)
    fields = _table_fields(float(np.max(th_max)), step)
    dense = np.linspace(0.0, float(np.max(th_max)), DENSE_FIELDS)
    allf = np.concatenate([fields, dense, th_max])
    Ta = np.tan(np.radians(allf))
    FX = np.degrees(np.arctan(Ta[None, :] * np.cos(az)[:, None]))
    FY = np.degrees(np.arctan(Ta[None, :] * np.sin(az)[:, None]))
    kw = dict(plane=planes, clip=clip)
    diag = grid_from_fields(lens, FX, FY, "angle", par, **kw)
    nt, nd = fields.size, dense.size
    _check_corners(lens, par, clip, diag.ok, az, th_max, dense, nt, fmt, c0, sensor is not None)
    allf, Ta = allf[: nt + nd], Ta[: nt + nd]
    diag_ok = diag.ok[:, : nt + nd]
    diag_actual = diag.actual[:, :, : nt + nd]

    # 2. the format's polar grid: PPBS, PPA, axial and the decomposition
    pa = np.radians(np.arange(0.0, 360.0, POLAR_AZIMUTH_STEP_DEG))
    pa = np.unique(np.round(np.mod(np.concatenate([pa, az, az + np.pi]), 2 * np.pi), 12))
    frac = np.linspace(0.0, 1.0, POLAR_FIELDS + 1)[1:]
    # uniform in tan θ up to the boundary of the format's largest part symmetric about the axis
    # (t → −t): on it the PPBS of a centred lens is the axis and its decentering zero, exactly
    Tp = np.minimum(extent(pa), extent(pa + np.pi))[:, None] * frac[None, :]
    tx = np.concatenate([[0.0], (Tp * np.cos(pa)[:, None]).ravel()])
    ty = np.concatenate([[0.0], (Tp * np.sin(pa)[:, None]).ravel()])
    polar = grid_from_fields(
        lens, np.degrees(np.arctan(tx)), np.degrees(np.arctan(ty)), "angle", par, **kw
    )
    R = {"axial": polar.axial_xy, "ppa": polar.ppa_xy, "ppbs": polar.ppbs_xy}[reference_point][0]
    if not np.all(np.isfinite(R)):
        raise DataError(f"the {reference_point} point could not be traced")

    ex = np.cos(az)[:, None]
    ey = np.sin(az)[:, None]
    rel = diag_actual[0] - R  # (4, N, 2)
    r_act = rel[..., 0] * ex + rel[..., 1] * ey
    t_act = -rel[..., 0] * ey + rel[..., 1] * ex
    beyond = allf[None, :] > th_max[:, None] * (1 + 1e-12)
    r_act = np.where(beyond, np.nan, r_act)
    t_act = np.where(beyond, np.nan, t_act)
    with warnings.catch_warnings():  # all-NaN columns (no semi-diagonal traced) give NaN
        warnings.simplefilter("ignore", RuntimeWarning)
        mean_r_dense = np.nanmean(r_act[:, nt:], axis=0)
    ok = np.isfinite(mean_r_dense)
    if np.count_nonzero(ok & (Ta[nt:] > 0)) < 2:
        raise DataError("fewer than two fields of the semi-diagonals could be traced")
    cc = fit_scale(Ta[nt:][ok], mean_r_dense[ok], method)
    dr = 1000.0 * (r_act - cc * Ta[None, :])
    tang = 1000.0 * t_act
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        mean_dr = np.nanmean(dr, axis=0)

    # 3. decentering from the decomposition on the polar grid, principal point held at R
    t = np.column_stack([tx, ty])
    img = polar.actual[0].reshape(-1, 2)
    fit = solve_linear(t, img, radial_terms=RADIAL_TERMS, principal_point=(R[0], R[1]))
    P1, P2 = fit.values["P1"], fit.values["P2"]
    S1, S2 = fit.values["S1"], fit.values["S2"]
    J, psi = decentering_profile(P1, P2)
    r_edge = cc * float(np.max(T_max))
    notes = []
    if J * r_edge**2 < DECENTERING_FLOOR_MM:  # round-off of a centred design (docstring)
        P1 = P2 = J = 0.0
        psi = math.nan
        notes.append(
            f"decentering below {DECENTERING_FLOOR_MM * 1e3:g} um at the edge of the format "
            "(a centred design): P1, P2 and J are given as 0 and the axis is undefined"
        )
    if math.hypot(S1, S2) * r_edge**2 < DECENTERING_FLOOR_MM:
        S1 = S2 = 0.0
    radius = cc * Ta
    prof = 1000.0 * J * radius**2

    # 4. USGS-form radial coefficients of the mean curve
    rr = radius[nt:][ok]
    yy = mean_dr[nt:][ok] / 1000.0
    rs = float(np.max(rr)) or 1.0
    A = np.column_stack([(rr / rs) ** (2 * i + 1) for i in range(4)])
    sol, *_ = np.linalg.lstsq(A, yy, rcond=None)
    k = sol / rs ** (2 * np.arange(4) + 1)
    rms = float(np.sqrt(np.mean((A @ sol - yy) ** 2))) * 1000.0

    bad = int(np.count_nonzero(~(polar.ok))) + int(np.count_nonzero(~diag_ok & ~beyond))
    if bad:
        notes.append(f"{bad} field(s) could not be traced; their entries are empty")
    frame_off = off  # certificate frame = lens frame + offset (origin at the sensor centre)
    return CalibrationCertificate(
        name=lens.name,
        source=str(getattr(lens, "source", "") or ""),
        date=date,
        object_distance=float(od),
        wavelength=float(par.wavelength),
        s_prime=sp,
        from_last_vertex=float(z[0] - par.z_last),
        defocus=float(z[0] - par.z_gauss),
        plane_label=polar.plane_label(0),
        field_kind=polar.field_kind,
        format=fmt,
        sensor=sensor,
        origin="sensor centre" if sensor is not None else "lens axis",
        reference_point=reference_point,
        paraxial_constant_mm=c0,
        calibrated_focal_length_mm=float(cc),
        method=method,
        ppa_mm=polar.ppa_xy[0] + frame_off,
        ppbs_mm=polar.ppbs_xy[0] + frame_off,
        axial_mm=polar.axial_xy[0] + frame_off,
        reference_mm=R + frame_off,
        azimuths_deg=np.mod(np.degrees(az), 360.0),
        max_fields_deg=th_max,
        fields_deg=fields,
        radius_mm=radius[:nt],
        radial_um=dr[:, :nt],
        tangential_um=tang[:, :nt],
        mean_radial_um=mean_dr[:nt],
        dense_fields_deg=dense,
        dense_radial_um=dr[:, nt:],
        dense_mean_radial_um=mean_dr[nt:],
        decentering={
            "P1": P1,
            "P2": P2,
            "J": J,
            "axis_deg": psi,
            "phi0_deg": psi - 90.0 if math.isfinite(psi) else math.nan,
            "S1": S1,
            "S2": S2,
            "residual_rms_um": fit.rms_mm * 1000.0,
        },
        decentering_profile_um=prof[:nt],
        dense_decentering_profile_um=prof[nt:],
        radial_coefficients={"k0": k[0], "k1": k[1], "k2": k[2], "k3": k[3], "rms_um": rms},
        notes=tuple(notes),
    )
