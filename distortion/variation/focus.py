"""Distortion, camera constant and principal point versus focus, for a lens whose configurations
change thicknesses (focus positions), and Brown's variation model tested on it (issue 13 item 4).

Brown (1971) and Fraser & Shortis (1992) model a lens focused by moving it as a whole (*unit
focusing*): the thin-lens equation then gives the principal distance ``c_s = f (1 + 1/N)`` of the
lens focused at image scale N (Gaussian magnification −1/N), hence Eq. (2)
``γ_ss' = c_s'/c_s`` and Eq. (4) ``α_s``, both in :mod:`distortion.variation.models`. A lens that
focuses by moving a group (front-cell, inner or rear focusing) changes its focal length and
principal planes with focus; this module measures how far the model then is from the traced
lens.

Definitions (one per quantity; all from the configured lens, nothing from the thin-lens model):

* **Focus distance** ``distance_mm``: object plane → image plane (the camera's focusing scale
  reads this; it does not move when a group moves). ``object_distance_mm``: object plane → first
  vertex (the Lens convention).
* **Image scale** ``N = −1/m0``, m0 the Gaussian magnification of the object in focus (``inf`` at
  infinity). Brown's γ and α are evaluated in image scales (``brown_gamma_scales``,
  ``brown_alpha_scales``), as Fraser & Shortis label their settings (8×, 12×, ...).
* **Principal distance** ``principal_distance_mm``: image plane → second principal point H'
  (Pestrecov's s'; Brown's c_s). For unit focusing of any thick lens in air Newton's equation
  gives exactly ``c_s = f (1 + 1/N)``: Brown's γ then holds to round-off.
* **Camera constant** ``camera_constant_mm``: ``c = p0'/m_e`` (Pestrecov Eq. 8 with the
  perspective centre at the entrance pupil; ``F0`` at infinity, ``M0·p0`` for a finite object):
  the scale the distortion is measured against.
* **Principal point** ``principal_point_mm``: the image of the axial object point (the real chief
  ray of field 0) in the image plane, meridional coordinate. The study needs first-order data,
  hence a centred lens, for which it is 0: it is reported as traced, not assumed.
* **Distortion** ``dr_um``: the Gaussian profile δr_s of Fraser & Shortis, Pestrecov's
  characteristic D0 (Eqs. 8–9) in the configuration's image plane, outward positive, against the
  actual radius ``r_mm = |y'|`` (:mod:`distortion.variation.traced` has the same definition).

Brown's Eq. (3)–(4) test (:class:`InterpolationTest`): the Gaussian profiles of two calibrated
configurations predict every other configuration's with α_s from the image scales; profiles are
compared on one grid of radii (cubic spline of δr against r, as in
:mod:`distortion.variation.traced`) up to the smallest largest radius of the three.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from raytrace.errors import LensError, TraceError
from raytrace.files.configurations import (
    Configuration,
    Configurations,
    apply_configuration,
    check_surfaces,
)
from raytrace.lens import Lens
from raytrace.units import UnitError, is_whole, length_mm, real_number

from ..errors import DataError
from .analysis import Profile, ProfileSet, VariationAnalysis, analyze_variation
from .models import Conjugate, brown_alpha_scales, brown_gamma_scales, brown_interpolate
from .traced import field_limit, leading_run, radial_profile, resample_spline

DEFAULT_N_FIELDS = 61
DEFAULT_N_R = 25
#: the in-focus solve stops when the Gaussian image is this close to the image plane (mm)
FOCUS_TOLERANCE_MM = 1e-10


# --------------------------------------------------------------------------------------------
# Making focus configurations
# --------------------------------------------------------------------------------------------


def track_length(lens: Lens) -> float:
    """First vertex → image plane (mm): the sum of the thicknesses (a centred, mirror-free lens)."""
    return float(sum(s.thickness for s in lens.surfaces))


def _gaussian_miss(lens: Lens, wavelength: float | None) -> float:
    from raytrace.paraxial import paraxial

    par = paraxial(lens, None, wavelength)
    return float(par.gaussian_image_distance - lens.surfaces[-1].thickness)


def _moved(lens: Lens, moving: int, compensating: int | None, delta: float, distance: float):
    s = list(lens.surfaces)
    s[moving - 1] = replace(s[moving - 1], thickness=s[moving - 1].thickness + delta)
    if compensating is not None:
        c = compensating - 1
        s[c] = replace(s[c], thickness=s[c].thickness - delta)
    out = replace(lens, surfaces=tuple(s), image_solve=None)
    od = math.inf if math.isinf(distance) else distance - track_length(out)
    if not od > 0:
        raise DataError(
            f"{lens.name}: focus distance {distance:g} mm is inside the lens (track "
            f"{track_length(out):g} mm)"
        )
    return replace(out, object_distance=od)


def _focus_distance_mm(value) -> float:
    """A focus distance as a float in mm: a number (mm), or a string with its unit as
    ``object_distance`` takes it (``"2m"``, ``"2000mm"``, ``"inf"``; a bare number is mm).

    Raises
    ------
    DataError
        A value that is no real number or length (``1j``, ``True``, a list, ``"2 parsecs"``),
        naming ``distance_mm`` and what it takes.
    """
    expected = "a focus distance in mm (a number, or a string with its unit such as '2m'; inf)"
    if isinstance(value, str):
        try:
            return length_mm(value, "distance_mm", allow_inf=True)
        except UnitError as e:
            raise DataError(str(e)) from None  # names distance_mm and the units
    return real_number(value, "distance_mm", expected, error=DataError)


def solve_focus(
    lens: Lens,
    distance_mm: float,
    *,
    moving: int,
    compensating: int | None = None,
    name: str | None = None,
    wavelength: float | None = None,
) -> Configuration:
    """The configuration that focuses ``lens`` on an object ``distance_mm`` from its image plane.

    The thickness after surface ``moving`` (1-based) changes by δ, that after ``compensating``
    by −δ (None: nothing compensates); the object distance becomes ``distance_mm`` − track.
    Unit focusing: ``moving`` = the last surface (the whole lens moves away from the image
    plane). Front-cell focusing: ``moving`` = the air space behind the front cell (the cell
    moves forward, the rest stays). Inner focusing: ``moving``/``compensating`` = the air spaces
    before / after the group (the track stays). δ is solved (secant method) until the Gaussian
    image of the object lies within :data:`FOCUS_TOLERANCE_MM` of the image plane.

    Parameters
    ----------
    lens : Lens
        A centred lens; its image plane (the sensor) is the end of its last thickness and stays
        where it is.
    distance_mm : float or str
        Focus distance in mm from the object plane to the image plane (positive; ``inf``), as a
        focusing scale reads it — not the Lens convention (object plane to first vertex). A
        string may carry its unit as ``object_distance`` takes it (``"2m"``; bare: mm).
    moving : int
        The surface (1-based) whose following thickness changes by δ.
    compensating : int, optional
        The surface (1-based, not ``moving``) whose following thickness changes by −δ; default
        none.
    name : str, optional
        The configuration's name; default ``"inf"`` or the distance in metres (``"2 m"``).
    wavelength : float or str, optional
        nm (or what :func:`raytrace.paraxial.paraxial` takes: ``"0.55um"``, a line letter
        ``"d"``); default the lens's reference wavelength. The lens is focused at it.

    Returns
    -------
    Configuration
        The new thicknesses of ``moving`` (and ``compensating``), mm, and the object distance
        (mm from the object plane to the first vertex; ``inf``).

    Raises
    ------
    DataError
        A surface number outside 1..n, ``compensating == moving``, a distance that is no
        number or length (``1j``, ``True``) or not positive, an object plane inside the lens,
        a lens the paraxial trace refuses (afocal, not centred; at the start or on the way), a
        solve that does not converge.
    TraceError
        A wavelength the unit checks refuse.
    """
    n = lens.n_surfaces
    for k, what in ((moving, "moving"), (compensating, "compensating")):
        if k is not None and not 1 <= k <= n:
            raise DataError(f"{what} = {k}: {lens.name} has surfaces 1–{n}")
    if compensating == moving:
        raise DataError("moving and compensating must be different surfaces")
    distance_mm = _focus_distance_mm(distance_mm)
    if not distance_mm > 0:
        raise DataError(
            f"focus distance must be positive (mm from the image plane), got {distance_mm}"
        )

    def miss(d: float) -> float:
        moved = _moved(lens, moving, compensating, d, distance_mm)  # DataError: says why
        try:
            return _gaussian_miss(moved, wavelength)
        except LensError as e:
            raise DataError(
                f"{lens.name}: cannot focus on {distance_mm:g} mm by moving surface {moving}: {e}"
            ) from None

    d0, d1 = 0.0, 1e-3 * max(1.0, abs(lens.surfaces[moving - 1].thickness))
    f0, f1 = miss(d0), miss(d1)
    for _ in range(60):
        if abs(f1) <= FOCUS_TOLERANCE_MM:
            break
        if f1 == f0:
            break
        d0, d1, f0 = d1, d1 - f1 * (d1 - d0) / (f1 - f0), f1
        f1 = miss(d1)
    if not abs(f1) <= FOCUS_TOLERANCE_MM:
        raise DataError(
            f"{lens.name}: focusing on {distance_mm:g} mm by moving surface {moving} did not "
            f"converge (the Gaussian image misses the image plane by {f1:.3g} mm)"
        )
    out = _moved(lens, moving, compensating, d1, distance_mm)
    ks = [moving] + ([compensating] if compensating is not None else [])
    th = tuple(sorted((k, out.surfaces[k - 1].thickness) for k in ks))
    label = name or ("inf" if math.isinf(distance_mm) else f"{distance_mm / 1000:g} m")
    return Configuration(label, th, out.object_distance)


def focus_configurations(
    lens: Lens,
    distances_mm: Sequence[float],
    *,
    moving: int,
    compensating: int | None = None,
    wavelength: float | None = None,
) -> Configurations:
    """:func:`solve_focus` for each focus distance (mm from the image plane; ``inf``).

    Parameters
    ----------
    lens : Lens
    distances_mm : sequence of float
        Focus distances in mm from the object plane to the image plane (positive; ``inf``).
    moving, compensating : int
        Surfaces (1-based) whose following thicknesses change by δ and −δ (``compensating``
        optional), as in :func:`solve_focus`.
    wavelength : float or str, optional
        nm; default the lens's reference wavelength.

    Returns
    -------
    Configurations
        One :class:`~raytrace.files.configurations.Configuration` per distance, in order, named
        as :func:`solve_focus` names them; ``current`` is 1 and ``source`` says which surfaces
        move.

    Raises
    ------
    DataError, TraceError
        As :func:`solve_focus`.
    """
    return Configurations(
        tuple(
            solve_focus(lens, d, moving=moving, compensating=compensating, wavelength=wavelength)
            for d in distances_mm
        ),
        1,
        f"{lens.name}: focus by surface {moving}"
        + ("" if compensating is None else f" against {compensating}"),
    )


# --------------------------------------------------------------------------------------------
# One focus setting
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class FocusSetting:
    """One configuration traced in its own image plane (module docstring for each quantity).

    Lengths in mm, ``dr_um`` in µm; ``fields_deg``: nominal field angles traced; ``defocus_mm``:
    image plane − Gaussian image plane of the object (0 for a configuration in focus)."""

    name: str
    lens: Lens
    object_distance_mm: float
    distance_mm: float
    image_scale: float
    efl_mm: float
    principal_distance_mm: float
    camera_constant_mm: float
    principal_point_mm: float
    from_last_vertex_mm: float
    defocus_mm: float
    fields_deg: np.ndarray
    r_mm: np.ndarray
    dr_um: np.ndarray

    def __repr__(self) -> str:
        return (
            f"FocusSetting({self.name!r}, N={self.image_scale:.6g}, f={self.efl_mm:.6f} mm, "
            f"c={self.principal_distance_mm:.6f} mm)"
        )


def _field_limit(lens: Lens, max_field_deg: float | None) -> float:
    """:func:`~distortion.variation.traced.field_limit`, but a lens whose field is an object
    height needs ``max_field_deg``."""
    if max_field_deg is None and lens.field.kind != "angle":
        raise DataError(
            f"{lens.name}: its field is an object height; give max_field_deg (degrees) for a "
            "focus study"
        )
    return field_limit(lens, max_field_deg)


def trace_focus_setting(
    lens: Lens,
    name: str,
    fields_deg: np.ndarray,
    *,
    object_distance: float | None = None,
    wavelength: float | None = None,
) -> FocusSetting:
    """Trace ``lens`` (one configuration) with the object at ``object_distance`` (default: the
    lens's) in the lens's image plane (its last thickness)."""
    from raytrace.paraxial import paraxial

    from ..characteristic import characteristic_distortion

    od = lens.object_distance if object_distance is None else float(object_distance)
    par = paraxial(lens, od, wavelength)
    t_img = lens.surfaces[-1].thickness
    try:
        cd = characteristic_distortion(
            lens,
            np.asarray(fields_deg, dtype=float),
            object_distance=od,
            from_last_vertex=t_img,
            wavelength=wavelength,
        )
    except TraceError as e:
        raise DataError(f"{lens.name}, configuration {name}: {e}") from None
    finite = math.isfinite(od)
    k0 = float(cd.constant[0])
    c = k0 * par.p0 if finite else k0
    r, dr = radial_profile(cd)
    scale = -1.0 / par.m0 if finite else math.inf
    return FocusSetting(
        name=name,
        lens=lens,
        object_distance_mm=od,
        distance_mm=od + track_length(lens) if finite else math.inf,
        image_scale=float(scale),
        efl_mm=float(par.efl),
        principal_distance_mm=float(cd.s_prime[0]),
        camera_constant_mm=float(c),
        principal_point_mm=float(cd.yp[0, 0]) if cd.fields[0] == 0 else math.nan,
        from_last_vertex_mm=float(t_img),
        defocus_mm=float(cd.defocus[0]),
        fields_deg=np.asarray(cd.fields, dtype=float),
        r_mm=r,
        dr_um=dr,
    )


# --------------------------------------------------------------------------------------------
# Brown's model against the traced lens
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class GammaTest:
    """Brown's Eq. (2) for configuration ``name`` against the ``reference`` one.

    ``gamma_brown`` = ``brown_gamma_scales(N_ref, N)`` (thin lens, unit focusing);
    ``gamma_traced`` = c/c_ref, the ratio of the traced principal distances;
    ``relative_error`` = γ_brown/γ_traced − 1; ``error_um_at_edge`` (µm) = the image-radius
    error at ``r_edge_mm`` (the largest radius all settings reach) of scaling the reference
    calibration's principal distance by γ_brown instead of the true ratio:
    ``relative_error · r_edge``.
    """

    name: str
    reference: str
    gamma_brown: float
    gamma_traced: float
    relative_error: float
    r_edge_mm: float
    error_um_at_edge: float


@dataclass(frozen=True, eq=False)
class InterpolationTest:
    """Brown's Eq. (3)–(4): the Gaussian profile of ``name`` predicted from the calibrated
    configurations ``s1``, ``s2`` with ``alpha`` (image scales), against the traced profile, at
    radii ``r_mm``. ``error_um`` = predicted − traced; ``max_abs_um`` at ``r_at_max_mm``."""

    name: str
    s1: str
    s2: str
    alpha: float
    r_mm: np.ndarray
    traced_um: np.ndarray
    predicted_um: np.ndarray
    error_um: np.ndarray
    rms_um: float
    max_abs_um: float
    r_at_max_mm: float


@dataclass(frozen=True, eq=False)
class FocusStudy:
    """Everything a focus study gives: ``settings`` per configuration, Brown's γ per
    configuration against the first (``gamma``), Eq. (3)–(4) from two calibrated configurations
    (``interpolation``), and, when asked for, the Fraser–Shortis analysis (``analysis``) of the
    Gaussian profiles and of the other configurations' object planes imaged with the lens in
    configuration ``focus_index`` (non-Gaussian profiles δr_ss')."""

    lens_name: str
    settings: tuple[FocusSetting, ...]
    gamma: tuple[GammaTest, ...]
    calibrated: tuple[int, int]
    interpolation: tuple[InterpolationTest, ...]
    analysis: VariationAnalysis | None
    notes: tuple[str, ...]

    def __repr__(self) -> str:
        worst = max((abs(g.relative_error) for g in self.gamma), default=float("nan"))
        return (
            f"FocusStudy({self.lens_name}: {len(self.settings)} configurations "
            f"({', '.join(s.name for s in self.settings)}), Brown's gamma off by up to "
            f"{worst:.3g} (relative), calibrated {self.calibrated})"
        )


def _spline(r: np.ndarray, dr: np.ndarray, grid: np.ndarray, label: str) -> np.ndarray:
    """δr of a traced profile on ``grid`` (:func:`~distortion.variation.traced.resample_spline`
    over its :func:`~distortion.variation.traced.leading_run`), which the radii must reach."""
    r, dr = leading_run(r, dr)
    if r.size < 4 or not np.all(np.diff(r) > 0):
        raise DataError(f"profile {label}: fewer than 4 traced fields, or r does not grow")
    if grid[-1] > r[-1] * (1 + 1e-12):
        raise DataError(f"profile {label}: the radii reach only {r[-1]:.4g} mm")
    return resample_spline(r, dr, grid, label)


def _r_hi(settings: Sequence[FocusSetting]) -> float:
    out = math.inf
    for s in settings:
        r, _ = leading_run(s.r_mm, s.dr_um)
        out = min(out, float(r[-1]) if r.size else 0.0)
    return out


def gamma_tests(settings: Sequence[FocusSetting], reference: int = 0) -> tuple[GammaTest, ...]:
    """Brown's Eq. (2) in image scales against the traced principal distances, every setting
    against ``settings[reference]``."""
    ref = settings[reference]
    r_edge = _r_hi(settings)
    out = []
    for s in settings:
        gb = brown_gamma_scales(ref.image_scale, s.image_scale)
        gt = s.principal_distance_mm / ref.principal_distance_mm
        # an image point at radius r_edge in setting s, scaled from the reference calibration:
        # the radius error of using γ_brown instead of the traced ratio
        err = (gb - gt) / gt * r_edge * 1000.0
        out.append(GammaTest(s.name, ref.name, gb, gt, gb / gt - 1.0, r_edge, err))
    return tuple(out)


def interpolation_tests(
    settings: Sequence[FocusSetting], s1: int, s2: int, *, n_r: int = DEFAULT_N_R
) -> tuple[InterpolationTest, ...]:
    """Brown's Eq. (3)–(4) from ``settings[s1]`` and ``settings[s2]`` for every other setting."""
    a, b = settings[s1], settings[s2]
    if a.image_scale == b.image_scale:
        raise DataError("the two calibrated configurations focus at the same image scale")
    out = []
    for i, s in enumerate(settings):
        if i in (s1, s2):
            continue
        hi = _r_hi([a, b, s])
        grid = np.linspace(hi / n_r, hi, n_r)
        p1 = _spline(a.r_mm, a.dr_um, grid, a.name)
        p2 = _spline(b.r_mm, b.dr_um, grid, b.name)
        p = _spline(s.r_mm, s.dr_um, grid, s.name)
        alpha = brown_alpha_scales(s.image_scale, a.image_scale, b.image_scale)
        pred = brown_interpolate(p1, p2, alpha)
        err = pred - p
        j = int(np.argmax(np.abs(err)))
        out.append(
            InterpolationTest(
                s.name,
                a.name,
                b.name,
                float(alpha),
                grid,
                p,
                pred,
                err,
                float(np.sqrt(np.mean(err**2))),
                float(abs(err[j])),
                float(grid[j]),
            )
        )
    return tuple(out)


def _conj(s: FocusSetting) -> Conjugate:
    return Conjugate(s.image_scale, "x", f"{s.image_scale:.6g}x")


def focus_study(
    lens: Lens,
    configurations: Configurations,
    *,
    calibrated: tuple[int, int] | None = None,
    focus_index: int | None = None,
    n_fields: int = DEFAULT_N_FIELDS,
    n_r: int = DEFAULT_N_R,
    max_field_deg: float | None = None,
    wavelength: float | None = None,
) -> FocusStudy:
    """Trace every configuration of ``lens`` and test Brown's model on them (module docstring).

    Each configuration is traced in its own image plane (the end of its last thickness): its
    image scale N = −1/m0, principal distance (image plane from H'), camera constant p0'/m_e
    (Pestrecov Eq. 8) and Gaussian profile δr_s = Pestrecov's D0 (Eq. 9). Brown's γ_ss' (Fraser &
    Shortis Eq. 2) and Eq. (3)–(4) are then compared with the traced profiles.

    Parameters
    ----------
    lens : Lens
        The base lens (centred).
    configurations : Configurations
        At least two, each focused at a different image scale (e.g. from
        :func:`focus_configurations`). Each must give its object distance (surface 0) or keep
        the lens's.
    calibrated : (int, int), optional
        The two configurations (0-based, different) whose Gaussian profiles calibrate Eq. (3)–(4);
        default the first and the last.
    focus_index : int, optional
        A configuration (0-based). With it, the other configurations' object planes are also
        traced with the lens in this configuration (δr_ss'; configurations focused at infinity
        are skipped) and the whole profile set goes through
        :func:`distortion.variation.analyze_variation` (γ, Eq. 1, g of Eq. 6).
    n_fields : int
        Field angles traced, from 0 to the largest (≥ 8; default 61).
    n_r : int
        Radii of the common grid the profiles are compared on (≥ 2; default 25).
    max_field_deg : float, optional
        The largest field angle in degrees, in (0, 90); default the lens's field, which must then
        be an angle.
    wavelength : float or str, optional
        nm; default the lens's reference wavelength.

    Returns
    -------
    FocusStudy
        ``settings`` (one :class:`FocusSetting` per configuration: lengths in mm, δr in µm,
        outward positive, against r = |y'|), ``gamma`` (Brown's γ against the first),
        ``interpolation`` (Eq. 3–4 tests, with three or more configurations), ``analysis`` (with
        ``focus_index``, else None) and ``notes``.

    Raises
    ------
    PrescriptionError
        A configuration changes a surface the lens does not have.
    DataError
        Fewer than two configurations, ``n_fields`` < 8 or ``n_r`` < 2, a field limit outside
        (0, 90)° or missing for a lens whose field is a height, two configurations at the same
        image scale, a bad ``calibrated`` pair or ``focus_index``, a trace that fails.
    LensError
        A configuration that makes an impossible lens.
    """
    check_surfaces(lens, configurations)
    if len(configurations) < 2:
        raise DataError(f"{lens.name}: a focus study needs at least two configurations")
    if n_fields < 8 or n_r < 2:
        raise DataError("need n_fields >= 8 traced fields and n_r >= 2 radii")
    fields = np.linspace(0.0, _field_limit(lens, max_field_deg), n_fields)
    lenses = [apply_configuration(lens, c) for c in configurations.configurations]
    settings = tuple(
        trace_focus_setting(ln, c.name, fields, wavelength=wavelength)
        for ln, c in zip(lenses, configurations.configurations, strict=True)
    )
    scales = [s.image_scale for s in settings]
    if len(set(scales)) != len(scales):
        raise DataError(f"{lens.name}: two configurations focus at the same image scale")
    n = len(settings)
    cal = (0, n - 1) if calibrated is None else tuple(calibrated)
    if len(cal) != 2 or not all(0 <= i < n for i in cal) or cal[0] == cal[1]:
        raise DataError(f"calibrated must be two different configurations in 0–{n - 1}")
    gam = gamma_tests(settings)
    interp = interpolation_tests(settings, cal[0], cal[1], n_r=n_r) if n > 2 else ()
    analysis = None
    if focus_index is not None:
        analysis = _fs_analysis(settings, focus_index, fields, n_r, wavelength)
    notes = (
        "image scale N = -1/m0 of the object in focus; Brown's gamma and alpha in image scales",
        "principal distance: image plane from H' (Brown's c_s); camera constant p0'/m_e",
        "distortion: Pestrecov's characteristic D0 in the configuration's image plane, "
        "outward positive, against r = |y'|",
    )
    return FocusStudy(lens.name, settings, gam, cal, interp, analysis, notes)


def _fs_analysis(settings, focus_index: int, fields, n_r: int, wavelength) -> VariationAnalysis:
    n = len(settings)
    if not (is_whole(focus_index) and 0 <= focus_index < n):
        why = "" if is_whole(focus_index) else f" (a whole number), got {focus_index!r}"
        raise DataError(f"focus_index must lie in 0–{n - 1}{why}")
    foc = settings[focus_index]
    cross = []
    for i, s in enumerate(settings):
        if i == focus_index or math.isinf(s.distance_mm):
            continue
        od = s.distance_mm - track_length(foc.lens)
        t = trace_focus_setting(
            foc.lens, foc.name, fields, object_distance=od, wavelength=wavelength
        )
        cross.append((s, t))
    every = list(settings) + [t for _, t in cross]
    hi = _r_hi(every)
    grid = np.linspace(hi / n_r, hi, n_r)
    profiles = [
        Profile(_conj(s), _conj(s), grid.copy(), _spline(s.r_mm, s.dr_um, grid, s.name))
        for s in settings
    ]
    profiles += [
        Profile(_conj(foc), _conj(s), grid.copy(), _spline(t.r_mm, t.dr_um, grid, s.name))
        for s, t in cross
    ]
    ps = ProfileSet(tuple(profiles), settings[0].efl_mm, f"{foc.lens.name} (configurations)")
    return analyze_variation(ps)


def unit_focus_configurations(
    lens: Lens, distances_mm: Sequence[float], *, wavelength: float | None = None
) -> Configurations:
    """Unit focusing of ``lens``: only the last thickness (the back focus) and the object
    distance change; :func:`solve_focus` with ``moving`` = the last surface.

    Parameters
    ----------
    lens : Lens
    distances_mm : sequence of float
        Focus distances in mm from the object plane to the image plane (positive; ``inf``).
    wavelength : float or str, optional
        nm; default the lens's reference wavelength.

    Returns
    -------
    Configurations
        One configuration per distance (:func:`focus_configurations`).

    Raises
    ------
    DataError, TraceError
        As :func:`solve_focus`.
    """
    return focus_configurations(lens, distances_mm, moving=lens.n_surfaces, wavelength=wavelength)
