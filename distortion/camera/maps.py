"""Distortion and undistortion maps in the form ``cv2.remap`` takes, and a picture of a lens's
distortion at true scale (a grid or checkerboard warped by ``cv2.remap``).

``cv2.remap(src, map1, map2, interpolation)`` makes ``dst(x, y) = src(map1(x, y), map2(x, y))``:
the maps hold, for every pixel of the image to be made (dst), where to read it in the image one
has (src). Both are float32 arrays of the dst image's shape (rows, columns), OpenCV pixels (pixel
centres at integers).

``direction="undistort"``
    dst is the **ideal** (pinhole) image of a camera matrix K (default the model's own pinhole
    part: the image of the axis direction and the Jacobian there,
    :func:`distortion.camera.compare.pinhole_part`), src is the **camera's** (distorted) image:
    map(u') = model(K⁻¹ u') — the maps ``cv2.initUndistortRectifyMap(K, dist, None, K, size,
    cv2.CV_32FC1)`` makes for an OpenCV model (checked in the tests).
``direction="distort"``
    dst is the camera's image, src the ideal image: map(u) = K x(u), x(u) the model's ideal
    direction of the pixel u (its inverse map; Newton's method for the forward models). This is
    what renders an ideal (synthetic) image as the lens would record it.

``scale`` (0 < scale ≤ 1) makes maps for a smaller copy of both images (a preview): pixel u of
the small image is the pixel (u + ½)/scale − ½ of the full one (the same field of view), and
the map values are in the small images' pixels too. Pixels whose map cannot be computed (the
model cannot invert them) get −1, which ``cv2.remap`` treats as outside.

The maps are computed in rows of at most ``CHUNK`` pixels, so memory stays bounded for a
large sensor (a 6000 × 4000 map pair is 192 MB of float32).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import DataError
from .compare import pinhole_part
from .models import OK, CameraModel, project, unproject

DIRECTIONS = ("undistort", "distort")
CHUNK = 1 << 20
PATTERNS = ("grid", "checkerboard")
#: largest preview width (pixels) of :func:`distortion_picture` unless a scale is given
PICTURE_WIDTH = 1200
#: Newton tolerance (px) of the inverse map behind the ``distort`` maps: float32 maps hold about
#: 1e-3 px at 10 000 px, so 1e-6 px is exact for them (and robust for models whose rational
#: terms nearly cancel, whose evaluation noise can exceed the models' 1e-12 px default)
MAP_TOL_PX = 1e-6


@dataclass(frozen=True, eq=False)
class RemapMaps:
    """``map1``, ``map2`` (float32, rows × columns) for ``cv2.remap`` (module docstring), the
    ``direction``, the ideal camera matrix ``camera_matrix`` (3 × 3, full-size pixels), the
    ``scale`` and the dst image ``size`` (columns, rows)."""

    map1: np.ndarray
    map2: np.ndarray
    direction: str
    camera_matrix: np.ndarray
    scale: float
    size: tuple[int, int]

    def __repr__(self) -> str:
        return (
            f"RemapMaps({self.direction}, {self.size[0]}x{self.size[1]} px, scale {self.scale:g})"
        )


def _camera_matrix(camera: CameraModel, new_camera_matrix) -> np.ndarray:
    if new_camera_matrix is not None:
        k = np.asarray(new_camera_matrix, dtype=float)
        if k.shape != (3, 3) or not np.allclose(k[2], (0.0, 0.0, 1.0)) or k[1, 0] != 0:
            raise DataError("new_camera_matrix must be a 3 x 3 camera matrix [[fx, s, cx], "
                            "[0, fy, cy], [0, 0, 1]]")  # fmt: skip
        return k
    u0, j = pinhole_part(camera)
    return np.array([[j[0, 0], j[0, 1], u0[0]], [j[1, 0], j[1, 1], u0[1]], [0.0, 0.0, 1.0]])


def remap_maps(
    camera: CameraModel,
    direction: str = "undistort",
    *,
    new_camera_matrix=None,
    scale: float = 1.0,
) -> RemapMaps:
    """The ``cv2.remap`` maps of ``camera`` (module docstring).

    Parameters
    ----------
    camera : CameraModel
    direction : {"undistort", "distort"}
        Make the ideal image from the camera's (``undistort``) or the camera's from an ideal one
        (``distort``).
    new_camera_matrix : (3, 3) array_like, optional
        The ideal pinhole camera (full-size OpenCV pixels); default the model's own pinhole part.
    scale : float
        0 < scale ≤ 1: maps for images ``scale`` times the size (a preview).

    Returns
    -------
    RemapMaps
    """
    if direction not in DIRECTIONS:
        raise DataError(f"direction={direction!r}; use one of {', '.join(DIRECTIONS)}")
    s = float(scale)
    if not (0.0 < s <= 1.0 and math.isfinite(s)):
        raise DataError(f"scale must lie in (0, 1], got {scale!r}")
    k = _camera_matrix(camera, new_camera_matrix)
    kinv = np.linalg.inv(k)
    w = max(1, int(round(camera.width * s)))
    h = max(1, int(round(camera.height * s)))
    map1 = np.empty((h, w), dtype=np.float32)
    map2 = np.empty((h, w), dtype=np.float32)
    rows = max(1, CHUNK // w)
    us = (np.arange(w) + 0.5) / s - 0.5
    for r0 in range(0, h, rows):
        r1 = min(h, r0 + rows)
        vs = (np.arange(r0, r1) + 0.5) / s - 0.5
        uu, vv = np.meshgrid(us, vs)
        full = np.column_stack([uu.ravel(), vv.ravel()])
        if direction == "undistort":
            x = full @ kinv[:2, :2].T + kinv[:2, 2]
            m = project(camera, x, pixels="opencv")
            out = m.points
        else:
            m = unproject(camera, full, pixels="opencv", tol_px=MAP_TOL_PX)
            out = m.points @ k[:2, :2].T + k[:2, 2]
        bad = (m.status != OK) | ~np.all(np.isfinite(out), axis=1)
        out = (out + 0.5) * s - 0.5
        out[bad] = -1.0
        map1[r0:r1] = out[:, 0].reshape(r1 - r0, w)
        map2[r0:r1] = out[:, 1].reshape(r1 - r0, w)
    return RemapMaps(map1, map2, direction, k, s, (w, h))


@dataclass(frozen=True, eq=False)
class DistortionPicture:
    """A pattern drawn in the ideal image and warped by ``cv2.remap`` into the camera's image:
    ``image`` (uint8, rows × columns), the ``pattern``, its ``spacing_px`` (full-size pixels of
    the ideal image), the preview ``scale`` and the ``camera``."""

    image: np.ndarray
    pattern: str
    spacing_px: float
    scale: float
    camera: CameraModel


def _pattern(shape, origin, centre, spacing: float, pattern: str, line: float) -> np.ndarray:
    """The ideal pattern on a canvas whose pixel (0, 0) is ``origin`` of the ideal image:
    lines (grid) or squares (checkerboard) ``spacing`` apart, aligned with ``centre``."""
    h, w = shape
    x = np.arange(w) + origin[0] - centre[0]
    y = np.arange(h) + origin[1] - centre[1]
    if pattern == "grid":
        fx = np.abs((x + 0.5 * spacing) % spacing - 0.5 * spacing) < 0.5 * line
        fy = np.abs((y + 0.5 * spacing) % spacing - 0.5 * spacing) < 0.5 * line
        img = np.full((h, w), 235, dtype=np.uint8)
        img[fy, :] = 20
        img[:, fx] = 20
        return img
    cx = np.floor(x / spacing).astype(np.int64)
    cy = np.floor(y / spacing).astype(np.int64)
    return np.where(((cy[:, None] + cx[None, :]) % 2) == 0, 235, 20).astype(np.uint8)


def distortion_picture(
    camera: CameraModel,
    pattern: str = "grid",
    *,
    spacing_px: float | None = None,
    scale: float | None = None,
    new_camera_matrix=None,
) -> DistortionPicture:
    """A grid or checkerboard of the ideal (pinhole) image as ``camera`` records it, at true
    scale — no exaggeration: straight lines curve exactly as much as the lens bends them. The
    warping is ``cv2.remap`` (the optional extra ``camera``) with the ``distort`` maps of
    :func:`remap_maps`.

    Parameters
    ----------
    camera : CameraModel
    pattern : {"grid", "checkerboard"}
    spacing_px : float, optional
        Line or square spacing in full-size pixels of the ideal image (default: a tenth of the
        image height).
    scale : float, optional
        Preview scale (default: at most 1200 pixels wide).
    new_camera_matrix : (3, 3) array_like, optional
        The ideal camera (default: the model's pinhole part).

    Returns
    -------
    DistortionPicture
        The warped pattern (uint8 image at the preview scale) with its spacing and scale.

    Raises
    ------
    DataError
        OpenCV is not installed (the ``camera`` extra), or an unknown pattern.
    """
    try:
        import cv2
    except ImportError:
        raise DataError(
            "the distortion picture warps with OpenCV: install the optional extra 'camera' "
            "(pip install 'orthoscope[camera]')"
        ) from None
    if pattern not in PATTERNS:
        raise DataError(f"pattern={pattern!r}; use one of {', '.join(PATTERNS)}")
    s = min(1.0, PICTURE_WIDTH / camera.width) if scale is None else float(scale)
    maps = remap_maps(camera, "distort", new_camera_matrix=new_camera_matrix, scale=s)
    sp = camera.height / 10.0 if spacing_px is None else float(spacing_px)
    if not sp > 0:
        raise DataError(f"spacing_px must be positive, got {spacing_px!r}")
    good = maps.map1 >= -0.5
    if not np.any(good):
        raise DataError(f"{camera.model}: no pixel of the image could be mapped")
    lo = np.floor([maps.map1[good].min(), maps.map2[good].min()]) - 2
    hi = np.ceil([maps.map1[good].max(), maps.map2[good].max()]) + 2
    w, h = int(hi[0] - lo[0]) + 1, int(hi[1] - lo[1]) + 1
    centre = (maps.camera_matrix[0, 2] + 0.5) * s - 0.5, (maps.camera_matrix[1, 2] + 0.5) * s - 0.5
    canvas = _pattern((h, w), lo, centre, sp * s, pattern, max(1.5, 0.004 * sp * s * 10))
    m1 = np.where(good, maps.map1 - np.float32(lo[0]), -1).astype(np.float32)
    m2 = np.where(good, maps.map2 - np.float32(lo[1]), -1).astype(np.float32)
    img = cv2.remap(canvas, m1, m2, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT,
                    borderValue=128)  # fmt: skip
    return DistortionPicture(img, pattern, sp, s, camera)
