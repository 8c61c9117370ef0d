"""Least-squares fits of camera models to point correspondences, and model-order selection.

A correspondence is an ideal direction (X/Z, Y/Z, or a 3-D direction with Z > 0; x right, y down)
and the image point observed for it (OpenCV pixels unless ``pixels=`` says otherwise;
:mod:`distortion.camera.conventions`). A traced chief-ray grid is such a set; so is a
calibration target.

The fit (:func:`fit_camera_model`) minimises image residuals in pixels with
``scipy.optimize.least_squares`` (Levenberg–Marquardt; trust-region reflective when there are
fewer residuals than parameters). The parameter Jacobian is exact: complex-step differentiation
of the model's closed-form map (every model function is analytic in its parameters). For
models whose closed form is the inverse direction (``australis``, COLMAP division) the
minimised residual is the collinearity residual of photogrammetry — (ideal(observed) − ideal) ×
the focal length in pixels — which equals the image residual to first order; the reported RMS
is always the true image residual (project the ideal points, compare in pixels).

Reported: RMS of the 2-D residual lengths |Δ| over the points (px), the largest |Δ|, standard
errors s·√diag((JᵀJ)⁻¹) with s² = Σ r² / (2N − n) (for noise-free traced data they measure the
misfit of the model's form, not noise), the correlation matrix, and
BIC = 2N ln(Σ r² / 2N) + n ln(2N).

**Model-order selection** (:func:`select_camera_model`), the criterion: fit the candidates in
order of increasing complexity; the first whose RMS is at or below ``rms_target_px``
(default 0.001 px) is chosen; otherwise a candidate is accepted only if it lowers the RMS of the
last accepted one by more than ``min_improvement`` (default 10 %), and the last accepted one is
chosen. (BIC is reported for each candidate but not used: for noise-free traced data it keeps
falling with every term that removes round-off.)
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import DataError
from .conventions import photo_mm_to_opencv_pixels, to_opencv_pixels
from .models import (
    OK,
    OPENCV_ORDERS,
    CameraModel,
    equidistant_coordinates,
    focal_lengths_px,
    frame_to_native,
    model_spec,
    pinhole_camera,
    project,
)

_CS_STEP = 1e-100  # complex step


@dataclass(frozen=True, eq=False)
class CameraFit:
    """A fitted camera model.

    Attributes
    ----------
    camera:
        The fitted :class:`~distortion.camera.models.CameraModel`.
    free:
        Names of the fitted parameters (the others were held at their initial values).
    std_errors:
        Standard error of each free parameter (same order as ``free``).
    correlation:
        (n, n) correlation matrix of the free parameters.
    residual_px:
        (N, 2) model − observed, OpenCV pixels (NaN where the model cannot project the point).
    rms_px, max_px:
        RMS and maximum of |residual| (px) over the points the model projects.
    n_points, n_failed:
        Correspondences used, and those the fitted model could not project.
    bic:
        Bayesian information criterion of the image residuals (module docstring).
    condition:
        Condition number of the column-scaled Jacobian (large: parameters poorly separated).
    """

    camera: CameraModel
    free: tuple[str, ...]
    std_errors: tuple[float, ...]
    correlation: np.ndarray
    residual_px: np.ndarray
    rms_px: float
    max_px: float
    n_points: int
    n_failed: int
    bic: float
    condition: float
    nfev: int
    notes: tuple[str, ...] = ()

    def std_error(self, name: str) -> float:
        return self.std_errors[self.free.index(name)]

    def __repr__(self) -> str:
        return (
            f"CameraFit({self.camera.model}, {len(self.free)} free parameters, {self.n_points} "
            f"points: RMS {self.rms_px:.3g} px, max {self.max_px:.3g} px)"
        )


def _ideal_array(ideal) -> np.ndarray:
    a = np.asarray(ideal, dtype=float)
    if a.ndim != 2 or a.shape[1] not in (2, 3):
        raise DataError("ideal must be (N, 2) X/Z, Y/Z or (N, 3) directions")
    if a.shape[1] == 3:
        if not np.all(a[:, 2] > 0):
            raise DataError("ideal directions must point forward (Z > 0)")
        a = a[:, :2] / a[:, 2:3]
    return a


def _linear_pinhole(x, u):
    """u = f x + c by least squares (one axis)."""
    a = np.column_stack([x, np.ones_like(x)])
    (f, c), *_ = np.linalg.lstsq(a, u, rcond=None)
    return float(f), float(c)


def initial_camera(
    model: str,
    ideal,
    image_px,
    *,
    width: int,
    height: int,
    pixel_size_mm: tuple[float, float] | None = None,
) -> CameraModel:
    """A starting camera of ``model`` from correspondences (image points in OpenCV pixels):
    focal lengths and principal point by a linear fit of a distortion-free camera in the
    model's projection (perspective, or equidistant for the fisheye models), every coefficient
    at its identity."""
    spec = model_spec(model)
    xy = _ideal_array(ideal)
    uv = np.asarray(image_px, dtype=float)
    x, y = xy[:, 0], xy[:, 1]
    if spec.projection == "equidistant":
        x, y = equidistant_coordinates(x, y)
    fx, cx = _linear_pinhole(x, uv[:, 0])
    fy, cy = _linear_pinhole(y, uv[:, 1])
    if not (fx > 0 and fy > 0):
        raise DataError(
            "the correspondences do not look like a camera: image x must grow with X/Z and image "
            "y with Y/Z (OpenCV axes: x right, y down)"
        )
    cam = pinhole_camera(spec.name, width, height, fx, fy, cx, cy, pixel_size_mm=pixel_size_mm)
    if spec.name == "colmap:FOV":
        cam = cam.replace(omega=0.1)  # omega = 0 is a stationary point of COLMAP's FOV model
    return cam


def _free_names(spec, free) -> tuple[str, ...]:
    if free is None:
        return spec.default_free
    if isinstance(free, int | np.integer):
        if spec.name != "opencv" or int(free) not in OPENCV_ORDERS:
            raise DataError(
                f"free={free!r}: an integer selects an OpenCV coefficient count "
                f"({', '.join(map(str, OPENCV_ORDERS))}) for the opencv model"
            )
        return ("fx", "fy", "cx", "cy", *OPENCV_ORDERS[int(free)])
    names = tuple(free)
    bad = [n for n in names if n not in spec.params]
    if bad:
        raise DataError(
            f"{spec.name} has no parameter {', '.join(bad)} (parameters: {', '.join(spec.params)})"
        )
    return names


def fit_camera_model(
    ideal,
    image_px,
    model: str | CameraModel,
    *,
    width: int | None = None,
    height: int | None = None,
    pixel_size_mm: tuple[float, float] | None = None,
    free: Sequence[str] | int | None = None,
    pixels: str = "opencv",
) -> CameraFit:
    """Fit a camera model to correspondences by least squares.

    Parameters
    ----------
    ideal:
        (N, 2) ideal normalised coordinates X/Z, Y/Z (x right, y down), or (N, 3) directions.
    image_px:
        (N, 2) observed image points in ``pixels`` (default OpenCV pixels).
    model:
        A model name (started from :func:`initial_camera`) or a :class:`CameraModel` (the
        start; parameters not in ``free`` keep its values).
    width, height, pixel_size_mm:
        The image (taken from ``model`` when it is a CameraModel); ``pixel_size_mm`` is needed
        by mm models (``australis``).
    free:
        Parameter names to fit (default: the model's ``spec.default_free``), or for ``opencv``
        a coefficient count 4, 5, 8, 12 or 14 (with fx, fy, cx, cy).
    pixels:
        Frame of ``image_px`` (``"opencv"``, ``"colmap"``, ``"metashape"``, ``"photo_mm"``).

    Returns
    -------
    CameraFit
    """
    from scipy.optimize import least_squares

    if isinstance(model, CameraModel):
        start = model
    else:
        if width is None or height is None:
            raise DataError("fit_camera_model: give width and height of the image (pixels)")
        start = None
    w = start.width if start else int(width)
    h = start.height if start else int(height)
    ps = start.pixel_size_mm if start and start.pixel_size_mm else pixel_size_mm
    xy = _ideal_array(ideal)
    obs = np.asarray(image_px, dtype=float)
    if obs.shape != xy.shape:
        raise DataError(f"ideal and image points differ in shape: {xy.shape} vs {obs.shape}")
    if not (np.all(np.isfinite(xy)) and np.all(np.isfinite(obs))):
        raise DataError("the correspondences contain non-finite values")
    if pixels == "photo_mm":
        if ps is None:
            raise DataError("image points in photo_mm need pixel_size_mm=(pitch_x, pitch_y)")
        obs_cv = photo_mm_to_opencv_pixels(obs, w, h, ps)
    else:
        obs_cv = to_opencv_pixels(obs, pixels)
    if start is None:
        start = initial_camera(model, xy, obs_cv, width=w, height=h, pixel_size_mm=ps)
    spec = start.spec
    names = _free_names(spec, free)
    n = len(names)
    m = 2 * xy.shape[0]
    if m < n:
        raise DataError(
            f"{n} free parameters need at least {math.ceil(n / 2)} points, got {m // 2}"
        )
    idx = [spec.params.index(k) for k in names]
    base = np.array(start.params, dtype=float)
    obs_native = frame_to_native(start, obs_cv, "opencv")
    x, y = xy[:, 0], xy[:, 1]

    if spec.explicit == "forward":

        def model_residual(pd):
            u, v, _ = spec.evaluate(pd, x, y, start)
            return np.concatenate([u - obs_native[:, 0], v - obs_native[:, 1]])
    else:
        sx, sy = (abs(v) for v in focal_lengths_px(start))

        def model_residual(pd):
            a, b, _ = spec.evaluate(pd, obs_native[:, 0], obs_native[:, 1], start)
            return np.concatenate([(a - x) * sx, (b - y) * sy])

    def pdict(z, cplx=None):
        vals = base.astype(complex if cplx is not None else float)
        vals[idx] = z
        if cplx is not None:
            vals[idx[cplx]] += 1j * _CS_STEP
        return dict(zip(spec.params, vals, strict=True))

    def fun(z):
        with np.errstate(all="ignore"):
            r = model_residual(pdict(z))
        return np.where(np.isfinite(r), r, 1e6)

    def jac(z):
        cols = []
        with np.errstate(all="ignore"):
            for i in range(n):
                cols.append(np.imag(model_residual(pdict(z.astype(complex), i))) / _CS_STEP)
        j = np.column_stack(cols)
        return np.where(np.isfinite(j), j, 0.0)

    z0 = base[idx]
    method = "lm" if m >= n else "trf"
    sol = least_squares(
        fun,
        z0,
        jac=jac,
        method=method,
        x_scale="jac",
        ftol=1e-15,
        xtol=1e-15,
        gtol=1e-15,
        max_nfev=200 * (n + 1),
    )
    vals = base.copy()
    vals[idx] = sol.x
    cam = CameraModel(spec.name, tuple(vals), w, h, start.pixel_size_mm)
    return _assess(cam, names, xy, obs_cv, jac(sol.x), sol.nfev)


def _assess(cam, names, xy, obs_cv, j, nfev) -> CameraFit:
    proj = project(cam, xy, pixels="opencv")
    res = proj.points - obs_cv
    ok = proj.status == OK
    d = np.hypot(res[ok, 0], res[ok, 1])
    notes = []
    if not np.all(ok):
        notes.append(f"{int(np.count_nonzero(~ok))} points cannot be projected by the fitted model")
    n = len(names)
    m = 2 * int(np.count_nonzero(ok))
    rss = float(np.sum(d**2))
    rms = float(np.sqrt(np.mean(d**2))) if d.size else math.nan
    mx = float(np.max(d)) if d.size else math.nan
    scale = np.linalg.norm(j, axis=0)
    scale = np.where(scale > 0, scale, 1.0)
    js = j / scale
    sv = np.linalg.svd(js, compute_uv=False)
    cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else math.inf
    if m > n:
        s2 = rss / (m - n)
        cov = np.linalg.pinv(js.T @ js) * s2 / np.outer(scale, scale)
        se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
        with np.errstate(all="ignore"):
            corr = cov / np.outer(se, se)
        corr[~np.isfinite(corr)] = np.nan
    else:
        se = np.full(n, math.nan)
        corr = np.full((n, n), math.nan)
    bic = m * math.log(max(rss, 1e-300) / m) + n * math.log(m) if m else math.nan
    return CameraFit(
        cam,
        tuple(names),
        tuple(float(v) for v in se),
        corr,
        res,
        rms,
        mx,
        xy.shape[0],
        int(np.count_nonzero(~ok)),
        bic,
        cond,
        int(nfev),
        tuple(notes),
    )


#: candidate ladders for :func:`select_camera_model`, simplest first
FAMILIES: dict[str, tuple[tuple[str, tuple[str, ...] | int | None], ...]] = {
    "opencv": tuple(("opencv", k) for k in (4, 5, 8, 12, 14)),
    "opencv_fisheye": tuple(
        ("opencv_fisheye", ("fx", "fy", "cx", "cy", *(f"k{i}" for i in range(1, k + 1))))
        for k in (1, 2, 3, 4)
    ),
    "colmap": tuple(
        (f"colmap:{m}", None) for m in ("SIMPLE_RADIAL", "RADIAL", "OPENCV", "FULL_OPENCV")
    ),
    "colmap_fisheye": tuple(
        (f"colmap:{m}", None)
        for m in ("SIMPLE_RADIAL_FISHEYE", "RADIAL_FISHEYE", "OPENCV_FISHEYE", "THIN_PRISM_FISHEYE")
    ),
    "metashape": (
        ("metashape", ("f", "cx", "cy", "k1", "k2", "k3", "p1", "p2")),
        ("metashape", ("f", "cx", "cy", "k1", "k2", "k3", "k4", "p1", "p2")),
        ("metashape", ("f", "cx", "cy", "b1", "b2", "k1", "k2", "k3", "k4", "p1", "p2")),
    ),
    "australis": (
        ("australis", ("c", "xp", "yp", "K1", "K2", "K3", "P1", "P2")),
        ("australis", ("c", "xp", "yp", "K1", "K2", "K3", "P1", "P2", "b1", "b2")),
    ),
}


@dataclass(frozen=True, eq=False)
class ModelSelection:
    """The fits of a candidate ladder and the one chosen by the stated criterion."""

    chosen: CameraFit
    fits: tuple[CameraFit, ...]
    criterion: str

    def __repr__(self) -> str:
        return f"ModelSelection(chosen {self.chosen!r} of {len(self.fits)} candidates)"


def select_camera_model(
    ideal,
    image_px,
    family: str | Sequence[tuple[str, Sequence[str] | int | None]] = "opencv",
    *,
    width: int,
    height: int,
    pixel_size_mm: tuple[float, float] | None = None,
    rms_target_px: float = 1e-3,
    min_improvement: float = 0.1,
    pixels: str = "opencv",
) -> ModelSelection:
    """Fit a ladder of candidates (a family of :data:`FAMILIES`, or (model, free) pairs,
    simplest first) and choose by the criterion of the module docstring.

    Parameters
    ----------
    ideal : array_like
        (N, 2) ideal normalised coordinates X/Z, Y/Z (x right, y down), or (N, 3) directions.
    image_px : array_like
        (N, 2) observed image points in the frame ``pixels``.
    family : str or sequence of (str, free)
        A family of :data:`FAMILIES` (``"opencv"``, ``"opencv_fisheye"``, ``"colmap"``,
        ``"colmap_fisheye"``, ``"metashape"``, ``"australis"``), or the candidates as (model
        name, free) pairs, simplest first; ``free`` as in :func:`fit_camera_model` (parameter
        names, an OpenCV coefficient count, or None for the model's default).
    width, height : int
        The image size in pixels.
    pixel_size_mm : (float, float), optional
        Pixel pitch (x, y) in mm; needed by models in mm (``australis``).
    rms_target_px : float
        The first candidate with an RMS residual at or below this (px) is chosen (default
        0.001 px).
    min_improvement : float
        Otherwise a candidate is accepted only if it lowers the RMS of the last accepted one by
        more than this fraction (default 0.1, i.e. 10 %).
    pixels : str
        Frame of ``image_px``: ``"opencv"`` (default), ``"colmap"``, ``"metashape"``,
        ``"photo_mm"``.

    Returns
    -------
    ModelSelection
        ``chosen`` (a :class:`CameraFit`), every candidate's fit, and the criterion in words.

    Raises
    ------
    DataError
        An unknown family, or a candidate :func:`fit_camera_model` refuses.
    """
    ladder = FAMILIES.get(family) if isinstance(family, str) else tuple(family)
    if ladder is None:
        raise DataError(f"unknown model family {family!r}; use one of {', '.join(FAMILIES)}")
    fits = tuple(
        fit_camera_model(
            ideal,
            image_px,
            mdl,
            width=width,
            height=height,
            pixel_size_mm=pixel_size_mm,
            free=free,
            pixels=pixels,
        )
        for mdl, free in ladder
    )
    chosen = fits[0]
    for f in fits[1:]:
        if chosen.rms_px <= rms_target_px:
            break
        if f.rms_px < (1.0 - min_improvement) * chosen.rms_px:
            chosen = f
    crit = (
        f"simplest candidate with RMS <= {rms_target_px:g} px; otherwise each step must lower the "
        f"RMS by more than {100 * min_improvement:g} %"
    )
    return ModelSelection(chosen, fits, crit)
