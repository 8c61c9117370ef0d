"""Camera models per object distance, for one focus setting: traced from the lens, or predicted
from two measured calibrations by Brown's and Fraser & Shortis' formulas — a table of models.

**Traced** (:func:`traced_models_by_distance`): the lens stays focused (the sensor stays in the
Gaussian image plane of the focused object, unit focusing); for each object distance the chief
rays are traced onto the sensor and the model fitted. The model *form* (model and free terms) is
the one chosen at the focused distance by the criterion of
:func:`~distortion.camera.fit.select_camera_model`, so that the table's columns are the same
coefficients at every distance; each row carries its own fit residual, and the residual of the
focused model left unchanged at that distance (what ignoring the variation costs).

**From two calibrations** (:func:`calibrated_models_by_distance`; Fraser & Shortis 1992):
two calibrations of the lens focused at s1 and s2 (each with the object at its focus) give
Gaussian radial profiles δr_s1, δr_s2 at common measured radii (azimuthal means,
:func:`distortion.camera.compare.radial_profile`). For the focus s and an object at s':

- Brown's Eqs. (3)–(4): δr_s = α_s δr_s1 + (1 − α_s) δr_s2, α_s = (s2 − s)/(s2 − s1) ·
  (s1 − f)/(s − f) (:func:`distortion.variation.models.brown_alpha`, ``brown_interpolate``);
  δr_s' likewise;
- ``method="brown"``: Eq. (1), δr_ss' = δr_s' / γ_ss' with γ_ss' = (s'/s)(s − f)/(s' − f);
- ``method="fraser-shortis"``: Eq. (6), δr_ss' = δr_s + g_ss' (δr_s' − δr_s) with a given g
  (Fraser & Shortis report about 0.45 for 65–120 mm wide-angle lenses, 0.25–0.31 for a 240 mm
  lens).

The principal distance of focus s, c_s = f + f²/(s − f) for a thin lens, is affine in 1/(s − f),
so α interpolates it exactly between the calibrated c_s1 and c_s2; the principal point and the
decentering terms are interpolated with the same α (their variation within the field, a few µm
for the lenses Fraser & Shortis measured, is not modelled). Each row is an OpenCV model
(k1 k2 p1 p2 k3) with fx = c_s / pitch: k1..k3 from δr_ss' by
:func:`distortion.coefficients.opencv_model` (measured radius → ideal radius, Gaussian form).

Distances: the traced table uses the project's ``object_distance`` (mm from the first vertex;
``inf``; ``"12x"``; a unit in strings). Brown's formulas are thin-lens formulas: their s, s1,
s2, s' are distances from the lens in mm (``inf`` allowed), all beyond f, as in
:mod:`distortion.variation.models`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import DataError
from .models import OPENCV_ORDERS, CameraModel
from .sensor import check_pixel_size_mm

METHODS = ("brown", "fraser-shortis")
#: the fewest radii of a calibrated profile: opencv_model fits k1, k2, k3 to it
MIN_RADII = 3
#: the range of c / f accepted between the calibrations' principal distance c and the focal
#: length f of Brown's formulas: c = f (1 + m) for a thin lens at magnification m, so c/f is 1
#: at infinity and 2 at 1:1; 0.5..8 leaves room for a nominal f and macro up to 7:1 (5:1 macro
#: lenses exist: Canon MP-E 65 mm, Laowa 2.5-5x, c/f = 6 at 5x), while f in metres or µm (c/f
#: near 1000 or 0.001), centimetres (10 or more) or inches (25 or more) falls outside
FOCAL_RATIO_RANGE = (0.5, 8.0)
#: unit slips tried for a refused focal length: (name, symbol, mm per unit)
_SLIPS = (("metres", "m", 1000.0), ("centimetres", "cm", 10.0), ("inches", "in", 25.4),
          ("micrometres", "µm", 1e-3))  # fmt: skip


@dataclass(frozen=True, eq=False)
class ModelTable:
    """Camera models of one lens and focus setting at several object distances.

    Attributes
    ----------
    name : str
        The lens (or the calibrations) the models come from.
    method : str
        ``"traced"``, ``"brown"`` or ``"fraser-shortis"``.
    focus : str
        The focus setting.
    object_distances : ndarray
        (n,) mm (from the first vertex for a traced table; from the lens for Brown's formulas);
        inf for infinity.
    cameras : tuple of CameraModel
        One model per distance, the same form in every row.
    rms_px, max_px : ndarray
        (n,) each row's own residual (traced: the fit to the chief rays; calibrated: the radial
        polynomial fit to δr_ss') in pixels.
    focused_rms_px : ndarray or None
        (n,) traced tables: the residual of the model of the focused distance left unchanged at
        each distance (what ignoring the variation costs).
    notes : tuple of str
    """

    name: str
    method: str
    focus: str
    object_distances: np.ndarray
    cameras: tuple[CameraModel, ...]
    rms_px: np.ndarray
    max_px: np.ndarray
    focused_rms_px: np.ndarray | None
    notes: tuple[str, ...]

    @property
    def model(self) -> str:
        return self.cameras[0].model

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """The columns of the model (OpenCV: fx fy cx cy and the shortest coefficient vector
        that holds every row's nonzero terms)."""
        if self.model == "opencv":
            n = max(c.n_opencv_coefficients for c in self.cameras)
            return ("fx", "fy", "cx", "cy", *OPENCV_ORDERS[n])
        return self.cameras[0].spec.params

    def rows(self) -> tuple[list[str], list[list[float]]]:
        """(header, rows) of the table: ``object_distance_mm``, the model's parameters (its
        own names and units), ``rms_px``, ``max_px`` [, ``focused_model_rms_px``]."""
        head = ["object_distance_mm", *self.parameter_names, "rms_px", "max_px"]
        if self.focused_rms_px is not None:
            head.append("focused_model_rms_px")
        out = []
        for i, cam in enumerate(self.cameras):
            d = cam.as_dict()
            row = [float(self.object_distances[i]), *(d[n] for n in self.parameter_names),
                   float(self.rms_px[i]), float(self.max_px[i])]  # fmt: skip
            if self.focused_rms_px is not None:
                row.append(float(self.focused_rms_px[i]))
            out.append(row)
        return head, out

    def __repr__(self) -> str:
        d = ", ".join("inf" if math.isinf(v) else f"{v:g}" for v in self.object_distances)
        return (
            f"ModelTable({self.name!r}, {self.method}, {self.model}, {self.focus}, object "
            f"distances [{d}] mm)"
        )


def traced_models_by_distance(
    lens,
    sensor,
    object_distances: Sequence,
    model: str = "opencv",
    *,
    n_coefficients: int | None = None,
    **setup,
) -> ModelTable:
    """The camera model of ``lens`` at each object distance for one focus setting (module
    docstring).

    Parameters
    ----------
    lens : Lens
    sensor : Sensor, CameraSetup or path
        As :func:`~distortion.camera.traced.camera_model`.
    object_distances : sequence
        Object planes in ``object_distance``'s words (mm from the first vertex, ``inf``,
        ``"12x"``, ``"2m"``).
    model, n_coefficients
        The model (family words as :func:`~distortion.camera.traced.camera_model`); its form is
        chosen at the focused distance and kept for every row.
    setup
        ``focus`` / ``focus_s`` / ``focus_scale`` or an image plane, ``wavelength``, ``grid``,
        ``clip`` (an object keyword here is refused: the distances are the table's rows).
        Default focus: the first object distance.

    Returns
    -------
    ModelTable
        One traced model per object distance (``method = "traced"``).
    """
    from .setup import make_setup
    from .traced import camera_residual, fit_points, trace_camera_points

    objs = list(object_distances)
    if not objs:
        raise DataError("give at least one object distance")
    bad = [k for k in ("object_distance", "object_s", "object_scale") if setup.get(k) is not None]
    if bad:
        raise DataError(f"the object distances are the table's rows: do not give {bad[0]}")
    base = make_setup(sensor, setup)
    focus_keys = ("focus", "focus_s", "focus_scale", "s_prime", "from_last_vertex", "defocus")
    if all(getattr(base, k) is None for k in focus_keys):
        base = base.replace(focus=objs[0])
    # the model's form at the focused distance
    geo0 = base.resolve(lens)
    if geo0.focus_object_distance is not None:
        at_focus = trace_camera_points(
            lens, base.replace(object_distance=_od_text(geo0.focus_object_distance))
        )
        first = fit_points(at_focus, model, n_coefficients=n_coefficients)
    else:
        first = fit_points(trace_camera_points(lens, base.replace(object_distance=objs[0])),
                           model, n_coefficients=n_coefficients)  # fmt: skip
    form = first.camera.model
    free = first.fit.free
    n_cv = first.camera.n_opencv_coefficients if form == "opencv" else None
    cams, rms, mx, frms, dists = [], [], [], [], []
    for o in objs:
        pts = trace_camera_points(lens, base.replace(object_distance=o))
        tc = (
            fit_points(pts, "opencv", n_coefficients=n_cv)
            if n_cv is not None
            else fit_points(pts, form, free=free)
        )
        cams.append(tc.camera)
        rms.append(tc.rms_px)
        mx.append(tc.max_px)
        frms.append(camera_residual(first.camera, pts).rms_px)
        dists.append(pts.geometry.object_distance)
    notes = (
        f"model form chosen at the focused distance: {form} ({first.criterion})",
        f"unit focusing: {geo0.focus}; sensor plane {geo0.from_last_vertex:.6g} mm from the last "
        "vertex for every row",
        geo0.projection_centre,
        "rms_px, max_px: each row's fit to its chief rays; focused_model_rms_px: the focused "
        "distance's model left unchanged, against the chief rays of the row",
    )
    return ModelTable(
        name=lens.name,
        method="traced",
        focus=geo0.focus,
        object_distances=np.array(dists, dtype=float),
        cameras=tuple(cams),
        rms_px=np.array(rms),
        max_px=np.array(mx),
        focused_rms_px=np.array(frms),
        notes=notes,
    )


def _od_text(v: float):
    return "inf" if math.isinf(v) else float(v)


def _distance(v, what: str) -> float:
    if isinstance(v, str):
        from raytrace.units import UnitError, length_mm

        try:
            return length_mm(v, what, allow_inf=True, positive=True)
        except UnitError as e:
            raise DataError(str(e)) from None
    d = float(v)
    if not d > 0:
        raise DataError(f"{what} must be a positive distance from the lens (mm), got {v!r}")
    return d


def _check_focal_length(f: float, cals: Sequence[CameraModel], ps) -> None:
    """Refuse an f of Brown's formulas whose ratio to the calibrations' principal distances c
    (mm, from each model's Jacobian on the axis) lies outside :data:`FOCAL_RATIO_RANGE`,
    naming the unit that would bring it inside."""
    from .compare import pinhole_part

    cs = []
    for cal in cals:
        _, j = pinhole_part(cal)
        cs.append(0.5 * (abs(j[0, 0]) * ps[0] + abs(j[1, 1]) * ps[1]))
    lo, hi = FOCAL_RATIO_RANGE
    if all(lo <= c / f <= hi for c in cs):
        return
    fix = "give f in mm"
    for name, sym, mm in _SLIPS:
        if all(lo <= c / (f * mm) <= hi for c in cs):
            fix = f"{name}? {f:g} {sym} = {f * mm:g} mm; {fix}"
            break
    raise DataError(
        f"focal_length_mm={f:g} mm is far from the calibrations' principal distances "
        f"{' and '.join(f'{c:.4g}' for c in cs)} mm (c/f = "
        f"{' and '.join(f'{c / f:.4g}' for c in cs)}; c = f (1 + magnification), so c/f lies "
        f"within {lo:g}..{hi:g}, macro up to {hi - 1:g}:1): {fix}"
    )


def _check_n_radii(n_radii) -> int:
    """n_radii as a whole number of radii, MIN_RADII..MAX_FIELDS; DataError naming it."""
    from raytrace.limits import MAX_FIELDS
    from raytrace.units import is_whole

    if not (is_whole(n_radii) and MIN_RADII <= int(n_radii) <= MAX_FIELDS):
        raise DataError(
            f"n_radii={n_radii!r}: give a whole number of radii, {MIN_RADII}..{MAX_FIELDS} "
            "(k1, k2, k3 are fitted to the profiles)"
        )
    return int(n_radii)


def _opencv_of(cal: CameraModel, what: str):
    """(camera in OpenCV's 5-term form, note) — exact when it can be, else a refit."""
    from .convert import convert_camera_model

    if cal.model == "opencv" and cal.n_opencv_coefficients <= 5:
        return cal, None
    conv = convert_camera_model(cal, "opencv", free=5, exact=cal.model != "opencv")
    if conv.method == "exact" and conv.camera.n_opencv_coefficients <= 5:
        return conv.camera, None
    if conv.method == "exact":
        conv = convert_camera_model(cal, "opencv", free=5, exact=False)
    return conv.camera, (
        f"{what}: {cal.model} refitted as OpenCV k1 k2 p1 p2 k3 over the sensor (RMS "
        f"{conv.rms_px:.3g} px, max {conv.max_px:.3g} px)"
    )


def calibrated_models_by_distance(
    calibration_1: CameraModel,
    s1,
    calibration_2: CameraModel,
    s2,
    *,
    focal_length_mm: float,
    focus,
    object_distances: Sequence,
    method: str = "brown",
    g: float | None = None,
    pixel_size_mm: tuple[float, float] | None = None,
    n_radii: int = 25,
    name: str = "two calibrations",
) -> ModelTable:
    """OpenCV models at each object distance for focus ``focus``, predicted from two measured
    calibrations by Brown's Eqs. (1)–(4) or Fraser & Shortis' Eq. (6) (module docstring).

    Parameters
    ----------
    calibration_1, calibration_2 : CameraModel
        The lens calibrated focused at ``s1`` and ``s2`` (object at the focus), same image size.
    s1, s2, focus : float or str
        Distances from the lens (mm, or with a unit: ``"2m"``; ``"inf"``), beyond f.
    focal_length_mm : float
        f of Brown's formulas (mm). Refused when the calibrations' principal distance c is not
        within 0.5..8 × f (:data:`FOCAL_RATIO_RANGE`; c = f (1 + magnification), macro up to
        7:1): f in metres, centimetres, inches or µm.
    object_distances : sequence
        s' of each row (distances from the lens).
    method : {"brown", "fraser-shortis"}
        Eq. (1), or Eq. (6) with ``g``.
    pixel_size_mm : (float, float), optional
        Pixel pitch (mm) when the calibrations carry none (checked as
        :func:`~distortion.camera.sensor.check_pixel_size_mm` checks it: 0.0003..1 mm).
    n_radii : int
        Radii of the profiles, from half-diagonal / n_radii to the half-diagonal: a whole
        number, at least 3 (:data:`MIN_RADII`: k1, k2, k3 are fitted to them), at most
        :data:`raytrace.limits.MAX_FIELDS`.

    Returns
    -------
    ModelTable
        One OpenCV model per object distance, with the method and the distances as given.
    """
    from ..coefficients import opencv_model
    from ..variation.models import (
        brown_alpha,
        brown_gamma,
        brown_interpolate,
        brown_predict,
        fs_predict,
    )
    from .compare import radial_profile

    if method not in METHODS:
        raise DataError(f"method={method!r}; use one of {', '.join(METHODS)}")
    if method == "fraser-shortis" and g is None:
        raise DataError("method 'fraser-shortis' needs g (Eq. 6's g_ss', e.g. 0.45)")
    if method == "brown" and g is not None:
        raise DataError("g belongs to method='fraser-shortis'; Brown's Eq. (1) has none")
    c1, c2 = calibration_1, calibration_2
    if (c1.width, c1.height) != (c2.width, c2.height):
        raise DataError("the two calibrations are of different image sizes")
    if pixel_size_mm is not None:
        pixel_size_mm = check_pixel_size_mm(pixel_size_mm, pixels=(c1.width, c1.height))
    ps = pixel_size_mm or c1.pixel_size_mm or c2.pixel_size_mm
    if ps is None:
        raise DataError("give pixel_size_mm=(pitch_x, pitch_y) in mm: the profiles are in mm")
    n_radii = _check_n_radii(n_radii)
    f = float(focal_length_mm)
    if not (f > 0 and math.isfinite(f)):
        raise DataError(f"focal_length_mm must be positive, got {focal_length_mm!r}")
    _check_focal_length(f, (c1, c2), ps)
    s1v, s2v, sv = (_distance(v, w) for v, w in ((s1, "s1"), (s2, "s2"), (focus, "focus")))
    objs = [_distance(v, "object distance") for v in object_distances]
    if not objs:
        raise DataError("give at least one object distance")
    cv1, n1 = _opencv_of(c1, "calibration 1")
    cv2_, n2 = _opencv_of(c2, "calibration 2")
    cv1 = CameraModel(cv1.model, cv1.params, cv1.width, cv1.height, ps)
    cv2_ = CameraModel(cv2_.model, cv2_.params, cv2_.width, cv2_.height, ps)
    half = math.hypot((c1.width - 1) / 2 * ps[0], (c1.height - 1) / 2 * ps[1])
    r = np.linspace(half / n_radii, half, int(n_radii))
    pr1 = radial_profile(cv1, r, pixel_size_mm=ps).dr_um
    pr2 = radial_profile(cv2_, r, pixel_size_mm=ps).dr_um
    d1, d2 = cv1.as_dict(), cv2_.as_dict()
    pitch = 0.5 * (ps[0] + ps[1])
    a_s = brown_alpha(sv, s1v, s2v, f)

    def interp(key, a):
        return a * d1[key] + (1.0 - a) * d2[key]

    # principal distance of the focus setting (exact for a thin lens: affine in 1/(s - f))
    c_s = a_s * 0.5 * (d1["fx"] * ps[0] + d1["fy"] * ps[1]) + (1.0 - a_s) * 0.5 * (
        d2["fx"] * ps[0] + d2["fy"] * ps[1]
    )
    dr_s = brown_interpolate(pr1, pr2, a_s)
    cams, rms, mx = [], [], []
    for so in objs:
        a_o = brown_alpha(so, s1v, s2v, f)
        dr_o = brown_interpolate(pr1, pr2, a_o)
        if method == "brown":
            dr = brown_predict(dr_o, brown_gamma(sv, so, f))
        else:
            dr = fs_predict(dr_s, dr_o, float(g))
        ok = np.isfinite(dr)
        m = opencv_model(r[ok], dr[ok], principal_distance_mm=c_s, pixel_pitch_um=pitch * 1000)
        cams.append(
            CameraModel.create(
                "opencv",
                c1.width,
                c1.height,
                pixel_size_mm=ps,
                fx=c_s / ps[0],
                fy=c_s / ps[1],
                cx=interp("cx", a_s),
                cy=interp("cy", a_s),
                k1=m.k1,
                k2=m.k2,
                k3=m.k3,
                p1=interp("p1", a_s),
                p2=interp("p2", a_s),
            )
        )
        rms.append(m.rms_px)
        mx.append(m.max_abs_px)
    eq = (
        "Brown Eq. (1): dr_ss' = dr_s' / gamma_ss'"
        if method == "brown"
        else f"Fraser & Shortis Eq. (6): dr_ss' = dr_s + g (dr_s' - dr_s), g = {g:g}"
    )
    notes = tuple(
        n
        for n in (
            f"calibrations focused at s1 = {s1v:g} mm and s2 = {s2v:g} mm; f = {f:g} mm; "
            "distances from the lens (Brown's thin lens)",
            f"Brown Eqs. (3)-(4): alpha_s = {a_s:.6g} at the focus {sv:g} mm; principal "
            f"distance c_s = {c_s:.6g} mm (interpolated with alpha_s), principal point and "
            "decentering interpolated likewise",
            eq,
            "k1, k2, k3 from dr_ss' by distortion.coefficients.opencv_model (Gaussian form, "
            "measured radius moved to the ideal radius); rms_px, max_px: that radial fit",
            n1,
            n2,
        )
        if n
    )
    return ModelTable(
        name=name,
        method=method,
        focus=f"focus {sv:g} mm from the lens",
        object_distances=np.array(objs, dtype=float),
        cameras=tuple(cams),
        rms_px=np.array(rms, dtype=float),
        max_px=np.array(mx, dtype=float),
        focused_rms_px=None,
        notes=notes,
    )


__all__ = [
    "METHODS",
    "ModelTable",
    "calibrated_models_by_distance",
    "traced_models_by_distance",
]
