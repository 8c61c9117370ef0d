"""The full Brown–Conrady model of close-range photogrammetry fitted to a traced 2-D distortion
field: Fraser's 10-parameter model (Fraser 1997, *Digital camera self-calibration*, ISPRS J.
Photogramm. 52, Eqs. 1–3) — principal distance c, principal point (xp, yp), radial K1–K3,
decentering P1, P2, affinity and shear b1, b2 — as the ``australis`` model of
:mod:`distortion.camera` (one implementation: its formulas, its least-squares fit with
correlations, its conversion to OpenCV).

The correspondences of a traced grid (docs/design.md, "2-D distortion"; frames in
:mod:`distortion.grid.field`): the ideal direction of a field in OpenCV's camera frame is
(X/Z, Y/Z) = (tx, −ty), and its measured image point in the photogrammetric frame (mm, x right, y
up) is the chief ray's point (x', y') in the lens frame, shifted by the sensor's principal-point
offset when a sensor is given. So Australis' correction reads x̄ + Δx = c·tx, ȳ + Δy = c·ty with
x̄ = x' − xp, ȳ = y' − yp: its K_i, P_j are a *correction* at the measured radius (to first
order the negatives of the distortion-form coefficients of :mod:`distortion.grid.decompose`).

b1, b2 describe a sensor (pixel-axis scale difference and non-orthogonality); a lens alone has
none, so a traced grid should give b1 = b2 = 0 (exactly, by symmetry, for a centred lens on a
grid symmetric in x and in y). A value whose effect at the edge of the field, |b|·r_max, exceeds
``AFFINITY_WARNING_MM`` is reported as a warning: it is model misfit (asymmetric grid, radial
distortion beyond K3) or a real asymmetry of the lens, not a sensor property.

Units: the fit runs in pixels of a virtual camera whose pitch is ``pixel_mm`` (default 1 µm, so
that residuals in pixels are micrometres) and whose image spans the traced points; reported
values are mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import DataError
from .decompose import RANK_RCOND, point_pairs, radial_shortfall, rank_shortfall

#: |b|·r_max (mm) above which b1 / b2 are reported as a warning
AFFINITY_WARNING_MM = 1e-6
#: default pitch of the virtual camera (mm): residuals in its pixels are micrometres
PIXEL_MM = 1e-3
BROWN_PARAMS = ("c", "xp", "yp", "K1", "K2", "K3", "P1", "P2", "b1", "b2")


@dataclass(frozen=True, eq=False)
class BrownConradyFit:
    """Fraser's 10-parameter (Brown–Conrady) model fitted to a traced grid.

    Attributes
    ----------
    plane : int
        The grid's plane (0-based); -1 for points given directly.
    camera : CameraModel
        The fitted ``australis`` camera (virtual pixels of ``pixel_mm``).
    fit : CameraFit
        The camera module's fit (residuals in pixels, BIC, condition, ...).
    values : dict
        c, xp, yp (mm); K1 (mm^-2), K2 (mm^-4), K3 (mm^-6); P1, P2 (mm^-1); b1, b2.
    std_errors : dict
        Standard errors of the free parameters (for noise-free traced data: model misfit).
    free : tuple of str
        The fitted parameters, in the order of ``correlation``.
    correlation : ndarray
        (n, n) correlations of the free parameters.
    rms_mm, max_mm : float
        RMS and maximum image residual (mm).
    r_max_mm : float
        Largest image radius of the points about the principal point (mm).
    opencv : Conversion or None
        The same camera in OpenCV's model (k1, k2, p1, p2, k3; a refit by
        :func:`distortion.camera.convert_camera_model` with its residual), when asked for.
    warnings : tuple of str
    not_determined : str
        "" for a fitted model; else why the points do not determine it (too few distinct field
        radii or traced points, a rank-deficient Jacobian): then ``camera``, ``fit`` and
        ``opencv`` are None, every value is NaN and ``std_errors`` and ``free`` are empty.
    """

    plane: int
    camera: object
    fit: object
    values: dict
    std_errors: dict
    free: tuple[str, ...]
    correlation: np.ndarray
    rms_mm: float
    max_mm: float
    r_max_mm: float
    pixel_mm: float
    opencv: object = None
    warnings: tuple[str, ...] = ()
    not_determined: str = ""

    @property
    def determined(self) -> bool:
        """Whether the points determined the model (else ``not_determined`` says why)."""
        return not self.not_determined

    @property
    def opencv_coefficients(self) -> dict:
        """OpenCV's k1, k2, p1, p2, k3 of :attr:`opencv` (empty without a conversion)."""
        if self.opencv is None:
            return {}
        d = self.opencv.camera.as_dict()
        return {k: d[k] for k in ("k1", "k2", "p1", "p2", "k3")}

    def correlation_of(self, a: str, b: str) -> float:
        return float(self.correlation[self.free.index(a), self.free.index(b)])

    def __repr__(self) -> str:
        v = self.values
        if not self.determined:
            return f"BrownConradyFit(plane {self.plane}: not determined: {self.not_determined})"
        return (
            f"BrownConradyFit(plane {self.plane}: c = {v['c']:.6f} mm, xp = {v['xp']:.3g}, "
            f"yp = {v['yp']:.3g} mm, K1 = {v['K1']:.4g}, P1 = {v['P1']:.3g}, P2 = {v['P2']:.3g}, "
            f"b1 = {v['b1']:.3g}, b2 = {v['b2']:.3g}; RMS {self.rms_mm:.3g} mm"
            + (f"; {len(self.warnings)} warning(s)" if self.warnings else "")
            + ")"
        )


def fit_brown_conrady_points(
    t,
    image_mm,
    *,
    camera_constant: float | None = None,
    affinity: bool = True,
    offset_mm: tuple[float, float] = (0.0, 0.0),
    pixel_mm: float = PIXEL_MM,
    opencv: bool = True,
    plane: int = -1,
) -> BrownConradyFit:
    """Fit Fraser's 10-parameter model to correspondences.

    Parameters
    ----------
    t : array_like
        (N, 2) normalised ideal coordinates (tx, ty): direction tangents, y up (module
        docstring); OpenCV's ideal direction is (tx, −ty).
    image_mm : array_like
        (N, 2) image points (mm) in the lens frame (x right, y up).
    camera_constant : float, optional
        Start value of c (mm); default from a linear fit.
    affinity : bool
        Fit b1, b2 too (the full 10 parameters); False: 8 (b1 = b2 = 0).
    offset_mm : (float, float)
        The lens axis measured from the image centre (a sensor's principal-point offset, mm,
        x right, y up): photogrammetric coordinates are image_mm + offset.
    pixel_mm : float
        Pitch (mm) of the virtual camera the fit runs in.
    opencv : bool
        Also convert to OpenCV (k1 k2 p1 p2 k3) by the camera module's refit.

    Returns
    -------
    BrownConradyFit
        When the points cannot determine the model (fewer distinct field radii than the four
        radial unknowns c, K1, K2, K3, e.g. a 3x3 grid; too few points; a rank-deficient
        Jacobian) it is returned with ``not_determined`` saying why and NaN values.
    """
    from ..camera import CameraModel, convert_camera_model, fit_camera_model

    t, img, good = point_pairs(t, image_mm, "image_mm")
    t, img = t[good], img[good]
    free = BROWN_PARAMS if affinity else BROWN_PARAMS[:8]
    n_free = len(free)
    p = float(pixel_mm)
    if not (p > 0 and math.isfinite(p)):
        raise DataError(f"pixel_mm={pixel_mm!r}: the virtual camera's pitch is a positive mm")
    if t.shape[0] * 2 <= n_free:
        return _undetermined(
            plane,
            p,
            f"{n_free} parameters need more than {n_free // 2} traced points, there are "
            f"{t.shape[0]}: use a grid with more fields (5x5 or more)",
        )
    why = radial_shortfall(t, ("c", "K1", "K2", "K3"))
    if why:
        return _undetermined(plane, p, why)
    photo = img + np.asarray(offset_mm, dtype=float)
    w = 2 * math.ceil(float(np.max(np.abs(photo[:, 0]))) / p) + 3
    h = 2 * math.ceil(float(np.max(np.abs(photo[:, 1]))) / p) + 3
    if camera_constant is None:
        sel = np.hypot(t[:, 0], t[:, 1]) > 0
        num = np.sum(t[sel] * photo[sel])
        den = np.sum(t[sel] * t[sel])
        camera_constant = num / den if den > 0 else 1.0
    if not camera_constant > 0:
        raise DataError("the image does not grow with the field: no positive camera constant")
    why = rank_shortfall(_linear_design(t, float(camera_constant), free), free)
    if why:
        return _undetermined(plane, p, why)
    start = CameraModel.create(
        "australis", w, h, pixel_size_mm=(p, p), c=float(camera_constant), xp=0.0, yp=0.0
    )
    ideal = np.column_stack([t[:, 0], -t[:, 1]])
    fit = fit_camera_model(ideal, photo, start, free=free, pixels="photo_mm")
    if fit.condition * RANK_RCOND > 1.0:  # the Jacobian at the solution: a safety net
        return _undetermined(
            plane,
            p,
            f"the traced fields do not separate the model's parameters (condition number "
            f"{fit.condition:.3g} of the fit's Jacobian): use a grid with more fields "
            "(5x5 or more)",
        )
    cam = fit.camera
    values = cam.as_dict()
    values = {k: float(values[k]) for k in BROWN_PARAMS}
    se = {k: float(v) for k, v in zip(fit.free, fit.std_errors, strict=True)}
    r_max = float(np.max(np.hypot(photo[:, 0] - values["xp"], photo[:, 1] - values["yp"])))
    warnings = list(fit.notes)
    for b in ("b1", "b2"):
        if abs(values[b]) * r_max > AFFINITY_WARNING_MM:
            warnings.append(
                f"{b} = {values[b]:.3g} moves the edge of the field by "
                f"{abs(values[b]) * r_max * 1000:.3g} um: b1/b2 describe a sensor, and a lens "
                "gives them only through model misfit or an asymmetric lens"
            )
    conv = None
    if opencv:
        conv = convert_camera_model(cam, "opencv", free=5, exact=False)
    return BrownConradyFit(
        plane=int(plane),
        camera=cam,
        fit=fit,
        values=values,
        std_errors=se,
        free=tuple(fit.free),
        correlation=fit.correlation,
        rms_mm=float(fit.rms_px) * p,
        max_mm=float(fit.max_px) * p,
        r_max_mm=r_max,
        pixel_mm=p,
        opencv=conv,
        warnings=tuple(warnings),
    )


def _linear_design(t: np.ndarray, c: float, free) -> np.ndarray:
    """The column-scaled design matrix of Fraser's model linearised at zero distortion, at the
    ideal points x̄ = c·t (mm): the correction x̄ + Δx = c tx, ȳ + Δy = c ty with
    Δx = x̄ (K1 r² + K2 r⁴ + K3 r⁶) + P1 (r² + 2x̄²) + 2 P2 x̄ȳ + b1 x̄ + b2 ȳ,
    Δy = ȳ (K1 r² + ...) + 2 P1 x̄ȳ + P2 (r² + 2ȳ²) (:mod:`distortion.camera.models`), columns
    in the order of ``free`` (its rank is that of the fit's Jacobian)."""
    x, y = c * t[:, 0], c * t[:, 1]
    r2 = x * x + y * y
    one, zero = np.ones_like(x), np.zeros_like(x)
    cols = {
        "c": (t[:, 0], t[:, 1]),
        "xp": (one, zero),
        "yp": (zero, one),
        "K1": (x * r2, y * r2),
        "K2": (x * r2**2, y * r2**2),
        "K3": (x * r2**3, y * r2**3),
        "P1": (r2 + 2 * x * x, 2 * x * y),
        "P2": (2 * x * y, r2 + 2 * y * y),
        "b1": (x, zero),
        "b2": (y, zero),
    }
    A = np.stack([np.concatenate(cols[n]) for n in free], axis=1)
    norm = np.linalg.norm(A, axis=0)
    return A / np.where(norm > 0, norm, 1.0)


def _undetermined(plane: int, pixel_mm: float, why: str) -> BrownConradyFit:
    """A :class:`BrownConradyFit` the points do not determine: NaN values, no fit."""
    return BrownConradyFit(
        plane=int(plane),
        camera=None,
        fit=None,
        values={k: math.nan for k in BROWN_PARAMS},
        std_errors={},
        free=(),
        correlation=np.zeros((0, 0)),
        rms_mm=math.nan,
        max_mm=math.nan,
        r_max_mm=math.nan,
        pixel_mm=pixel_mm,
        opencv=None,
        not_determined=why,
    )


def fit_brown_conrady(
    grid,
    plane: int = 0,
    *,
    affinity: bool = True,
    opencv: bool = True,
    pixel_mm: float = PIXEL_MM,
) -> BrownConradyFit:
    """Fit Fraser's 10-parameter Brown–Conrady model to the traced field of ``grid`` (a
    :class:`~distortion.grid.field.DistortionGrid`) in ``plane`` (module docstring).

    The principal distance c and principal point (xp, yp) are fitted together with K1–K3, P1,
    P2 (and b1, b2 when ``affinity``); their correlations are in ``correlation``. With a grid
    made for a sensor the photogrammetric frame's origin is the sensor centre. ``opencv``: also
    OpenCV's k1 k2 p1 p2 k3 (camera module conversion, with its residual).

    Parameters
    ----------
    grid : DistortionGrid
        The traced grid; its camera constant in ``plane`` starts c.
    plane : int
        The grid's image plane, 0-based (default 0).
    affinity : bool
        Fit b1, b2 too (the full 10 parameters; default); False: 8 parameters, b1 = b2 = 0.
    opencv : bool
        Also convert to OpenCV's k1 k2 p1 p2 k3 (default True).
    pixel_mm : float
        Pitch in mm of the virtual camera the fit runs in (default :data:`PIXEL_MM`, 1 µm, so
        residuals in its pixels are micrometres).

    Returns
    -------
    BrownConradyFit
        c, xp, yp (mm), K1 (mm⁻²), K2 (mm⁻⁴), K3 (mm⁻⁶), P1, P2 (mm⁻¹), b1, b2 — Australis'
        correction at the measured radius — their standard errors and correlations, the residuals
        (mm) and the OpenCV conversion. A grid that cannot determine the model gives a result
        with ``not_determined`` saying why and NaN values.

    Raises
    ------
    DataError
        ``plane`` out of range, or an image that does not grow with the field (no positive
        camera constant).
    """
    p = grid.plane_index(plane)
    t = np.stack([grid.tx.ravel(), grid.ty.ravel()], axis=1)
    img = grid.actual[p].reshape(-1, 2)
    off = (0.0, 0.0)
    sensor = grid.sensor
    if sensor is not None and hasattr(sensor, "principal_point_offset_mm"):
        off = tuple(float(v) for v in sensor.principal_point_offset_mm)
    return fit_brown_conrady_points(
        t,
        img,
        camera_constant=float(grid.camera_constant[p]),
        affinity=affinity,
        offset_mm=off,
        pixel_mm=pixel_mm,
        opencv=opencv,
        plane=p,
    )
