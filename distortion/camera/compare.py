"""Comparing two camera models over a sensor — a measured calibration against the prescription's
prediction (Fraser & Shortis 1992 compare measured and predicted distortion profiles the same way)
— and the radial distortion profile of any model.

The distortion part of a model (any model of :mod:`distortion.camera`)
    Near the axis every model is a pinhole: ``u ≈ u0 + J x`` with ``u0`` the image of the axis
    direction and ``J`` the model's Jacobian there (OpenCV pixels; fx, skew, fy — what
    ``cv2.undistort`` maps to). The *distortion* at a measured image point u is the rest:
    ``d(u) = u − (u0 + J x(u))`` with ``x(u)`` the model's ideal direction of u (its inverse
    map) — distortion at the **measured** position, positive outward for pincushion, as the
    photogrammetric profiles of Fraser & Shortis.

Comparison (:func:`compare_cameras`)
    Two models of the same sensor are compared at the same image offset q from each one's own
    principal point u0 (calibrations differ in principal point and principal distance; the
    distortion pattern travels with them): ``Δd(q) = d_predicted(u0_p + q) − d_measured(u0_m +
    q)`` over a grid of q that covers the sensor, in pixels — the map. The **radial profiles**
    are the azimuthal means of the radial component of d on circles of measured radius r about
    u0 (mm when the pixel size is known): decentering and thin-prism terms, being first
    harmonics in azimuth, average out. The **projection difference** ``u_p(x) − u_m(x)`` for the
    same ideal direction x (the measured camera's directions of the grid) includes the
    principal-point and principal-distance differences as well; it is reported beside the map.

Units: pixels (OpenCV frame, :mod:`distortion.camera.conventions`), mm and µm where stated.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import DataError
from .convert import grid_size, sensor_grid
from .models import (
    NOT_CONVERGED,
    OK,
    CameraModel,
    native_to_frame,
    project,
    project_jacobian,
    unproject,
)
from .sensor import check_pixel_size_mm

#: azimuths of a radial profile
N_AZIMUTHS = 72
DEFAULT_GRID = (41, 31)
DEFAULT_RADII = 40
#: Newton tolerance (px) of a second try of the inverse map for points that did not converge to
#: the models' own 1e-12 px (or 16 ulp): the evaluation noise of a model whose rational terms
#: nearly cancel can exceed that floor; 1e-9 px is still far below any distortion compared
INVERSE_TOL_PX = 1e-9


def pinhole_part(camera: CameraModel) -> tuple[np.ndarray, np.ndarray]:
    """(u0, J): the image of the axis direction (2,) and the 2 × 2 Jacobian d(u, v)/d(x, y) there
    (OpenCV pixels; the model's analytic Jacobian carried from its native frame)."""
    m = project(camera, np.zeros((1, 2)), pixels="opencv")
    jn = project_jacobian(camera, np.zeros((1, 2)))[0]
    if not (np.all(m.status == OK) and np.all(np.isfinite(jn))):
        raise DataError(f"{camera.model}: the model cannot project directions near its axis")
    e = native_to_frame(camera, np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), "opencv")
    lin = np.column_stack([e[1] - e[0], e[2] - e[0]])  # native -> OpenCV pixels (affine)
    return m.points[0].copy(), lin @ jn


def distortion_at(camera: CameraModel, image_px) -> np.ndarray:
    """(N, 2) distortion d(u) = u − (u0 + J x(u)) at image points u (OpenCV pixels; NaN where
    the model cannot unproject u) — module docstring."""
    u = np.asarray(image_px, dtype=float).reshape(-1, 2)
    u0, j = pinhole_part(camera)
    x = ideal_of(camera, u)
    return u - (u0 + x @ j.T)


def ideal_of(camera: CameraModel, image_px: np.ndarray) -> np.ndarray:
    """(N, 2) ideal directions of OpenCV pixels (NaN where the model cannot invert them): the
    model's inverse to its own tolerance, and a second try to INVERSE_TOL_PX for the points that
    did not converge to it."""
    u = np.asarray(image_px, dtype=float).reshape(-1, 2)
    back = unproject(camera, u, pixels="opencv")
    x = np.where((back.status == OK)[:, None], back.points, np.nan)
    again = back.status == NOT_CONVERGED
    if np.any(again):
        m = unproject(camera, u[again], pixels="opencv", tol_px=INVERSE_TOL_PX)
        x[again] = np.where((m.status == OK)[:, None], m.points, np.nan)
    return x


@dataclass(frozen=True, eq=False)
class RadialProfile:
    """The radial distortion of a model, averaged over azimuth, at measured radii.

    ``radius_px`` (n,) along the x axis of the pixels; ``radius_mm`` (n,) or None without a
    pixel size; ``dr_px`` (n,) radial distortion in pixels (x pixels), ``dr_um`` (n,) in µm
    (or None); ``spread_px`` (n,) the largest departure of the radial component from the mean
    over the circle (decentering / prism / anisotropy); ``inside`` (n,) True where the whole
    circle lies on the sensor."""

    radius_px: np.ndarray
    radius_mm: np.ndarray | None
    dr_px: np.ndarray
    dr_um: np.ndarray | None
    spread_px: np.ndarray
    inside: np.ndarray


def radial_profile(
    camera: CameraModel,
    radii: np.ndarray | None = None,
    *,
    pixel_size_mm: tuple[float, float] | None = None,
    n_azimuths: int = N_AZIMUTHS,
) -> RadialProfile:
    """Radial distortion (module docstring) of ``camera`` at measured radii about its principal
    point.

    Parameters
    ----------
    camera : CameraModel
    radii : array_like, optional
        Radii in mm when a pixel size is known (the camera's or ``pixel_size_mm``), else in
        pixels. Default: 40 radii from 0 to the half-diagonal of the image.
    pixel_size_mm : (float, float), optional
        Pixel pitch (mm) when the camera does not carry one (checked as
        :func:`~distortion.camera.sensor.check_pixel_size_mm` checks it).
    n_azimuths : int
        Points per circle.
    """
    if pixel_size_mm is not None:
        pixel_size_mm = check_pixel_size_mm(pixel_size_mm)
    ps = camera.pixel_size_mm or pixel_size_mm
    u0, _ = pinhole_part(camera)
    px, py = ps if ps is not None else (1.0, 1.0)
    half_diag = math.hypot((camera.width - 1) / 2.0 * px, (camera.height - 1) / 2.0 * py)
    r = (
        np.linspace(0.0, half_diag, DEFAULT_RADII)
        if radii is None
        else np.atleast_1d(np.asarray(radii, dtype=float))
    )
    phi = np.linspace(0.0, 2 * np.pi, int(n_azimuths), endpoint=False)
    c, s = np.cos(phi), np.sin(phi)
    # circle in the image (radius r in the units of ps), pixels with v down
    qx = r[:, None] * c[None, :] / px
    qy = r[:, None] * s[None, :] / py
    u = np.stack([u0[0] + qx, u0[1] + qy], axis=-1).reshape(-1, 2)
    d = distortion_at(camera, u).reshape(r.size, phi.size, 2)
    # radial component in the image's metric frame (unit vector along the circle's radius)
    rad = (d[..., 0] * px) * c[None, :] + (d[..., 1] * py) * s[None, :]  # units of ps
    mean = np.nanmean(rad, axis=1) if rad.size else np.zeros(0)
    spread = np.nanmax(np.abs(rad - mean[:, None]), axis=1) / px
    inside = (
        (u0[0] - r / px >= -0.5)
        & (u0[0] + r / px <= camera.width - 0.5)
        & (u0[1] - r / py >= -0.5)
        & (u0[1] + r / py <= camera.height - 0.5)
    )
    return RadialProfile(
        radius_px=r / px,
        radius_mm=r.copy() if ps is not None else None,
        dr_px=mean / px,
        dr_um=mean * 1000.0 if ps is not None else None,
        spread_px=spread,
        inside=inside,
    )


@dataclass(frozen=True, eq=False)
class CameraComparison:
    """Two camera models of one sensor compared (module docstring).

    Attributes
    ----------
    measured, predicted : CameraModel
    label_measured, label_predicted : str
    offsets_px : ndarray
        (gy, gx, 2) the offsets q from the principal point (OpenCV px) of the map.
    image_px : ndarray
        (gy, gx, 2) the predicted camera's image points u0_p + q (where the map is drawn).
    difference_px : ndarray
        (gy, gx, 2) Δd(q) = d_predicted − d_measured (px; NaN where either model cannot
        unproject).
    projection_difference_px : ndarray
        (gy, gx, 2) u_predicted(x) − u_measured(x) for the measured directions x of the grid.
    profile_measured, profile_predicted : RadialProfile
        At the same radii.
    principal_point_difference_px : (float, float)
        u0_predicted − u0_measured.
    focal_difference_px : (float, float)
        J_predicted − J_measured on the diagonal (fx, fy).
    rms_px, max_px : float
        Of |Δd| over the map.
    projection_rms_px, projection_max_px : float
        Of the projection difference.
    notes : tuple of str
    prediction : TracedCamera or None
        The traced prediction, when the predicted camera comes from a lens.
    """

    measured: CameraModel
    predicted: CameraModel
    label_measured: str
    label_predicted: str
    offsets_px: np.ndarray
    image_px: np.ndarray
    difference_px: np.ndarray
    projection_difference_px: np.ndarray
    profile_measured: RadialProfile
    profile_predicted: RadialProfile
    principal_point_difference_px: tuple[float, float]
    focal_difference_px: tuple[float, float]
    rms_px: float
    max_px: float
    projection_rms_px: float
    projection_max_px: float
    notes: tuple[str, ...] = ()
    prediction: object = None

    @property
    def radial_difference_um(self) -> np.ndarray | None:
        """Predicted − measured radial distortion (µm) at the profiles' radii."""
        a, b = self.profile_predicted.dr_um, self.profile_measured.dr_um
        return None if a is None or b is None else a - b

    def __repr__(self) -> str:
        return (
            f"CameraComparison({self.label_predicted} - {self.label_measured}: distortion "
            f"difference RMS {self.rms_px:.3g} px, max {self.max_px:.3g} px; projection "
            f"difference RMS {self.projection_rms_px:.3g} px)"
        )


def _stats(v: np.ndarray) -> tuple[float, float]:
    d = np.hypot(v[..., 0], v[..., 1]).ravel()
    d = d[np.isfinite(d)]
    if not d.size:
        return math.nan, math.nan
    return float(np.sqrt(np.mean(d**2))), float(d.max())


def compare_cameras(
    measured: CameraModel,
    predicted: CameraModel,
    *,
    pixel_size_mm: tuple[float, float] | None = None,
    grid: tuple[int, int] = DEFAULT_GRID,
    radii: np.ndarray | None = None,
    label_measured: str = "measured",
    label_predicted: str = "predicted",
    notes: tuple[str, ...] = (),
    allow_large: bool = False,
) -> CameraComparison:
    """Compare two models of the same sensor (module docstring): the map of the distortion
    difference, the radial profiles, the projection difference and the principal-point and
    focal-length differences.

    Parameters
    ----------
    measured, predicted : CameraModel
        Same image size (pixels).
    pixel_size_mm : (float, float), optional
        Pixel pitch (mm) for profiles in mm and µm (default: the cameras' own); two positive
        numbers within 0.0003..1 mm (the pitch range of :meth:`Sensor.from_spec
        <distortion.camera.Sensor.from_spec>`: a larger one reads as µm and is refused;
        :func:`~distortion.camera.sensor.check_pixel_size_mm`).
    grid : (int, int) or int
        Columns × rows of the map over the sensor (n: n × n), whole numbers of at least 2; at
        most :data:`raytrace.limits.MAX_FIELDS` points without ``allow_large`` (the limit of
        :func:`~distortion.grid.field.distortion_grid`).
    radii : array_like, optional
        Radii of the profiles (mm with a pixel size, else px); default 40 up to the
        half-diagonal.
    label_measured, label_predicted : str
        Names of the two models in listings and plots.
    notes : tuple of str
        Carried into the result.
    allow_large : bool
        Lift the limit on the map's points.

    Returns
    -------
    CameraComparison
        The map Δd = d_predicted − d_measured (px), the projection difference, the radial
        profiles, and the principal-point and focal-length differences (predicted − measured).
    """
    if (measured.width, measured.height) != (predicted.width, predicted.height):
        raise DataError(
            f"the cameras differ in image size: {measured.width}x{measured.height} (measured) vs "
            f"{predicted.width}x{predicted.height} px; compare calibrations of the same sensor"
        )
    if pixel_size_mm is not None:
        pixel_size_mm = check_pixel_size_mm(pixel_size_mm)
    grid = grid_size(grid, allow_large)
    ps = pixel_size_mm or measured.pixel_size_mm or predicted.pixel_size_mm
    u0m, jm = pinhole_part(measured)
    u0p, jp = pinhole_part(predicted)
    g = sensor_grid(predicted.width, predicted.height, grid, allow_large=allow_large)
    q = g - u0p
    dp = distortion_at(predicted, g)
    dm = distortion_at(measured, u0m + q)
    diff = (dp - dm).reshape(grid[1], grid[0], 2)
    xm = ideal_of(measured, g)
    ok = np.all(np.isfinite(xm), axis=1)
    proj = np.full(g.shape, np.nan)
    if np.any(ok):
        pp = project(predicted, xm[ok], pixels="opencv")
        v = pp.points - g[ok]
        v[pp.status != OK] = np.nan
        proj[ok] = v
    proj = proj.reshape(grid[1], grid[0], 2)
    pm = radial_profile(measured, radii, pixel_size_mm=ps)
    ppr = radial_profile(predicted, pm.radius_mm if pm.radius_mm is not None else pm.radius_px,
                         pixel_size_mm=ps)  # fmt: skip
    rms, mx = _stats(diff)
    prms, pmx = _stats(proj)
    return CameraComparison(
        measured=measured,
        predicted=predicted,
        label_measured=label_measured,
        label_predicted=label_predicted,
        offsets_px=q.reshape(grid[1], grid[0], 2),
        image_px=g.reshape(grid[1], grid[0], 2),
        difference_px=diff,
        projection_difference_px=proj,
        profile_measured=pm,
        profile_predicted=ppr,
        principal_point_difference_px=(float(u0p[0] - u0m[0]), float(u0p[1] - u0m[1])),
        focal_difference_px=(float(jp[0, 0] - jm[0, 0]), float(jp[1, 1] - jm[1, 1])),
        rms_px=rms,
        max_px=mx,
        projection_rms_px=prms,
        projection_max_px=pmx,
        notes=tuple(notes),
    )
