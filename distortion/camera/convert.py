"""Convert a camera model into another: exact algebra where it exists, a refit otherwise.

**Exact** (``method="exact"``): the polynomial-family models (OpenCV standard and fisheye,
COLMAP's pinhole, radial, OPENCV, FULL_OPENCV and fisheye models, Metashape) share one canonical
form in OpenCV pixels — focal lengths, skew, principal point, radial numerator and rational
denominator, tangential p1 p2 (OpenCV's placement), Metashape's tangential multiplier, thin
prism, tilt. A target that holds every nonzero term of the source gets its parameters by
renaming, the p1/p2 swap of Metashape, the +0.5 of COLMAP/Metashape pixels, Metashape's centre
offsets and fx = f + b1, skew = b2, and OpenCV fisheye's α = skew / fx. The projection is then
the same function; the residual over the grid is round-off (≈ 1e-12 px).

**Refit** (``method="refit"``): otherwise (a term the target lacks, a different projection,
the Australis correction, COLMAP's FOV / division / EUCM): a grid of image points over the whole
sensor (``grid`` columns × rows, corners included, OpenCV pixels) is unprojected with the source
model, and the target is fitted to those correspondences (:func:`distortion.camera.fit.
fit_camera_model`). The conversion's residual — RMS and maximum over the grid of |target(ideal) −
source image point| in pixels — is part of the result, with the terms the target could not hold.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import DataError
from .fit import CameraFit, fit_camera_model, initial_camera
from .models import (
    OK,
    OPENCV_ORDERS,
    CameraModel,
    NotRepresentable,
    model_spec,
    project,
    unproject,
)
from .sensor import check_pixel_size_mm

DEFAULT_GRID = (41, 31)

#: parameters a refit frees by default (all of the target's, except where noted)
_REFIT_FREE = {
    # the thin prism and tilt terms only where the source has them (they correlate with the
    # principal point and focal lengths of a centred distortion)
    "opencv": ("fx", "fy", "cx", "cy", *OPENCV_ORDERS[8]),
}


@dataclass(frozen=True, eq=False)
class Conversion:
    """A converted camera model and how well it reproduces the source.

    Attributes
    ----------
    camera:
        The target-model camera.
    source:
        The camera that was converted.
    method:
        ``"exact"`` (algebra) or ``"refit"``.
    rms_px, max_px:
        RMS and maximum over the grid of |target projection − source image point| (OpenCV px).
    n_points, n_dropped:
        Grid points compared, and grid points the source could not unproject (left out).
    lost_terms:
        What the target could not hold exactly (why a refit was needed).
    fit:
        The :class:`~distortion.camera.fit.CameraFit` of a refit (None for exact).
    """

    camera: CameraModel
    source: CameraModel
    method: str
    rms_px: float
    max_px: float
    n_points: int
    n_dropped: int
    lost_terms: tuple[str, ...]
    fit: CameraFit | None = None

    def __repr__(self) -> str:
        return (
            f"Conversion({self.source.model} -> {self.camera.model}, {self.method}: RMS "
            f"{self.rms_px:.3g} px, max {self.max_px:.3g} px over {self.n_points} points)"
        )


def convert_exact(camera: CameraModel, target: str) -> CameraModel:
    """The exact equivalent of ``camera`` in ``target`` (raises
    :class:`~distortion.camera.models.NotRepresentable` naming the terms it cannot hold)."""
    spec = model_spec(target)
    src = camera.spec
    if spec.name == src.name:
        return camera
    if spec.frame == "photo_mm" and camera.pixel_size_mm is None:
        raise DataError(f"{spec.name} works in mm: the camera needs pixel_size_mm")
    t = src.terms(camera.as_dict(), camera)
    if t is None:
        raise NotRepresentable(
            f"{src.name} with these parameters has no exact form in {spec.name}",
            [f"the {src.name} form"],
        )
    params = spec.from_terms(t, camera)
    return CameraModel.create(
        spec.name, camera.width, camera.height, pixel_size_mm=camera.pixel_size_mm, **params
    )


#: the smallest model of each target that holds a source exactly is searched in this order
EXACT_LADDERS = {
    "opencv": ("opencv", "opencv_fisheye"),
    "colmap": tuple(
        f"colmap:{m}"
        for m in (
            "SIMPLE_PINHOLE",
            "PINHOLE",
            "SIMPLE_RADIAL",
            "RADIAL",
            "OPENCV",
            "FULL_OPENCV",
            "SIMPLE_FISHEYE",
            "FISHEYE",
            "SIMPLE_RADIAL_FISHEYE",
            "RADIAL_FISHEYE",
            "OPENCV_FISHEYE",
            "THIN_PRISM_FISHEYE",
            "RAD_TAN_THIN_PRISM_FISHEYE",
        )
    ),
    "metashape": ("metashape",),
    "australis": ("australis",),
}


def smallest_exact(camera: CameraModel, target: str) -> CameraModel:
    """The first model of the ``target`` family ("opencv", "colmap", "metashape",
    "australis") that holds ``camera`` exactly; a camera already of that family is returned as
    it is. Raises NotRepresentable (with the terms lost by the largest candidate)."""
    if target not in EXACT_LADDERS:
        raise DataError(f"unknown target {target!r}; use one of {', '.join(EXACT_LADDERS)}")
    if camera.spec.target == target:
        return camera
    last: NotRepresentable | None = None
    for name in EXACT_LADDERS[target]:
        try:
            return convert_exact(camera, name)
        except NotRepresentable as e:
            last = e
    raise last


def grid_size(grid, allow_large: bool = False) -> tuple[int, int]:
    """(columns, rows) of a grid over the image, checked as
    :func:`~distortion.grid.field.distortion_grid` checks its ``grid`` (the same functions):
    ``n`` or ``(nx, ny)``, whole numbers of at least 2, and at most
    :data:`raytrace.limits.MAX_FIELDS` points unless ``allow_large``. DataError naming
    ``grid=`` and the fix, before anything is allocated."""
    from ..grid.field import check_field_count, grid_points

    if grid is None:
        grid = DEFAULT_GRID
    gx, gy = grid_points(grid)
    check_field_count(gx, gy, allow_large, f"grid={grid!r}")
    return gx, gy


def sensor_grid(
    width: int, height: int, grid: tuple[int, int] = DEFAULT_GRID, *, allow_large: bool = False
) -> np.ndarray:
    """(gx·gy, 2) OpenCV pixel coordinates of a regular grid over the whole image, from the
    centre of the first pixel to the centre of the last (corners included); ``grid`` and
    ``allow_large`` as :func:`grid_size` checks them."""
    gx, gy = grid_size(grid, allow_large)
    u, v = np.meshgrid(np.linspace(0.0, width - 1.0, gx), np.linspace(0.0, height - 1.0, gy))
    return np.column_stack([u.ravel(), v.ravel()])


def _compare(src: CameraModel, dst: CameraModel, grid_px: np.ndarray):
    back = unproject(src, grid_px, pixels="opencv")
    ok = back.status == OK
    ideal = back.points[ok]
    proj = project(dst, ideal, pixels="opencv")
    good = proj.status == OK
    d = np.hypot(*(proj.points[good] - grid_px[ok][good]).T)
    failed = int(np.count_nonzero(~good))
    rms = float(np.sqrt(np.mean(d**2))) if d.size else math.nan
    mx = float(np.max(d)) if d.size else math.nan
    if failed:
        mx = math.inf
    return ideal, grid_px[ok], rms, mx, int(np.count_nonzero(~ok))


def convert_camera_model(
    camera: CameraModel,
    target: str,
    *,
    grid: tuple[int, int] = DEFAULT_GRID,
    free: Sequence[str] | int | None = None,
    pixel_size_mm: tuple[float, float] | None = None,
    exact: bool = True,
    allow_large: bool = False,
) -> Conversion:
    """Convert ``camera`` to the model ``target`` over its image.

    Parameters
    ----------
    camera:
        The source camera.
    target:
        A model name (:data:`~distortion.camera.models.MODEL_NAMES`).
    grid:
        Columns × rows of the comparison (and refit) grid over the image (or n: n × n); at
        most :data:`raytrace.limits.MAX_FIELDS` points without ``allow_large``.
    free:
        Parameters a refit may change (default: all of the target's; for ``opencv`` fx fy cx cy
        and the 8 coefficients k1..k6 p1 p2 — give 12 or 14 to add prism and tilt).
    pixel_size_mm:
        Pixel size (mm) for a target in mm (``australis``) when the source has none; checked
        as :func:`~distortion.camera.sensor.check_pixel_size_mm` checks it (0.0003..1 mm).
    exact:
        Try exact algebra first (default; not when ``free`` is given: naming what a refit may
        change asks for a refit). ``False`` forces a refit.
    allow_large:
        Lift the limit on the grid's points.

    Returns
    -------
    Conversion
        With ``method``, the residual over the grid and the terms the target could not hold.
    """
    spec = model_spec(target)
    if pixel_size_mm is not None:
        pixel_size_mm = check_pixel_size_mm(pixel_size_mm)
    grid = grid_size(grid, allow_large)
    ps = camera.pixel_size_mm or pixel_size_mm
    if spec.frame == "photo_mm" and ps is None:
        raise DataError(
            f"converting to {spec.name} (mm) needs the pixel size: give pixel_size_mm=(pitch_x, "
            "pitch_y) in mm"
        )
    src = (
        camera
        if camera.pixel_size_mm or ps is None
        else CameraModel(camera.model, camera.params, camera.width, camera.height, ps)
    )
    grid_px = sensor_grid(src.width, src.height, grid)
    lost: tuple[str, ...] = ()
    if exact and free is None:
        try:
            out = convert_exact(src, spec.name)
        except NotRepresentable as e:
            lost = e.terms
        else:
            _i, _g, rms, mx, dropped = _compare(src, out, grid_px)
            return Conversion(out, camera, "exact", rms, mx, len(_g), dropped, ())
    back = unproject(src, grid_px, pixels="opencv")
    ok = back.status == OK
    if np.count_nonzero(ok) < len(spec.params):
        raise DataError(
            f"{camera.model}: only {int(np.count_nonzero(ok))} grid points could be unprojected; "
            "the model is not invertible over this image"
        )
    names = free if free is not None else _REFIT_FREE.get(spec.name, spec.params)
    fit = None
    for start in _refit_starts(src, spec.name, back.points[ok], grid_px[ok]):
        if isinstance(free, int | np.integer):  # N coefficients: the others are 0, not held
            keep = {"fx", "fy", "cx", "cy", *OPENCV_ORDERS.get(int(free), ())}
            p = {k: (v if k in keep else 0.0) for k, v in start.as_dict().items()}
            start = CameraModel.create(
                spec.name, start.width, start.height, pixel_size_mm=start.pixel_size_mm, **p
            )
        trial = fit_camera_model(back.points[ok], grid_px[ok], start, free=names)
        if fit is None or trial.rms_px < fit.rms_px:
            fit = trial
    _i, _g, rms, mx, dropped = _compare(src, fit.camera, grid_px)
    return Conversion(fit.camera, camera, "refit", rms, mx, len(_g), dropped, lost, fit)


def _refit_starts(src: CameraModel, target: str, ideal, image_px) -> list[CameraModel]:
    """Starting cameras of a refit: the source's terms that the target holds (the others
    dropped), when the projections agree; and a distortion-free camera fitted to the grid."""
    starts = []
    spec = model_spec(target)
    t = src.spec.terms(src.as_dict(), src)
    if t is not None and t.projection == spec.projection:
        try:
            params = spec.from_terms(t, src, lenient=True)
            starts.append(
                CameraModel.create(
                    target, src.width, src.height, pixel_size_mm=src.pixel_size_mm, **params
                )
            )
        except DataError:
            pass
    starts.append(
        initial_camera(
            target,
            ideal,
            image_px,
            width=src.width,
            height=src.height,
            pixel_size_mm=src.pixel_size_mm,
        )
    )
    return starts
