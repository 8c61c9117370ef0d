"""Image-coordinate conventions of the camera-model targets — written once, here.

Every camera model in :mod:`distortion.camera` maps an *ideal direction* to an *image point*.

Ideal direction
    The normalised camera coordinates ``x = X/Z``, ``y = Y/Z`` of a point (X, Y, Z) in the
    camera frame of OpenCV and COLMAP: x to the right, y **down**, z forward toward the object
    (Z > 0; fields beyond 90° from the axis are out of scope). An object point with X/Z > 0 images
    to the right of the principal point, one with Y/Z > 0 below it, as the picture is looked at
    upright on a screen.

Image points — the conventions of the targets
    =========== ============================= ================================================
    target      origin, pixel centres         notes
    =========== ============================= ================================================
    ``opencv``  the centre of the top-left    pixel (i, j) is centred at u = i, v = j; a
                pixel is (0, 0); u right,     centred principal point is cx = (W − 1)/2,
                v down                        cy = (H − 1)/2. **This is the common frame**: every
                                              comparison, fit and conversion of this package
                                              is made in OpenCV pixels.
    ``colmap``  the top-left *corner* of the  pixel centres at +0.5: u_colmap = u_opencv + 0.5;
                image is (0, 0); u right,     a centred cx = W/2 (COLMAP's camera models,
                v down                        ``cameras.txt``).
    ``metashape`` as COLMAP (top-left corner  Metashape's cx, cy are **offsets from the image
                is (0, 0), centres at +0.5)   centre**: u = W/2 + cx + …; so
                                              cx_opencv = (W − 1)/2 + cx_metashape. (Agisoft
                                              Metashape User Manual, Appendix C "Camera
                                              models"; the same frame in easyidp 2.0.4
                                              ``reconstruct.py`` and nerfstudio 1.1.5
                                              ``metashape_utils.py``, which add W/2.)
    ``photo_mm`` photogrammetric (Australis / mm, x right, **y up**, origin at the centre of
                Fraser): the image centre     the sensor (the centre of the pixel array):
                                              x = (u_opencv − (W − 1)/2)·pitch_x,
                                              y = −(v_opencv − (H − 1)/2)·pitch_y; the
                                              principal point (xp, yp) is a model parameter in
                                              the same frame.
    =========== ============================= ================================================

Decentering terms (all targets, written in each target's own symbols)
    OpenCV / COLMAP: ``x_d = … + 2 p1 x y + p2 (r² + 2x²)``, ``y_d = … + p1 (r² + 2y²) + 2 p2 x y``
    — p1 sits on the y term. Metashape: ``x' = … + P1 (r² + 2x²) + 2 P2 x y`` — its P1 is
    OpenCV's p2 (swapped). Brown / Fraser (Australis): ``Δx = … + P1 (r² + 2x̄²) + 2 P2 x̄ ȳ``,
    ``Δy = … + 2 P1 x̄ ȳ + P2 (r² + 2ȳ²)`` in mm with **y up**, as a **correction** measured →
    ideal; OpenCV's p are *distortion* (ideal → distorted) with y down. So Brown's P2 pairs with
    OpenCV's p1 and Brown's P1 with OpenCV's p2, and the signs differ by the direction of the map
    and the flip of the y axis; the conversion between them is a refit (:mod:`.convert`), never a
    renaming. A decentering along +y (down in pixels) makes OpenCV p1 ≠ 0 and p2 = 0.

The functions below convert image points between these frames; nothing else in the package
adds or subtracts 0.5 or W/2.
"""

from __future__ import annotations

import numpy as np

from ..errors import DataError

#: pixel conventions (image points in pixels)
PIXEL_CONVENTIONS = ("opencv", "colmap", "metashape")
#: every image-point frame a model can use natively
IMAGE_FRAMES = (*PIXEL_CONVENTIONS, "photo_mm")

_HALF = {"opencv": 0.0, "colmap": 0.5, "metashape": 0.5}


def _check_convention(convention: str) -> None:
    if convention not in PIXEL_CONVENTIONS:
        raise DataError(
            f"unknown pixel convention {convention!r}; use one of {', '.join(PIXEL_CONVENTIONS)}"
        )


def pixel_centre_offset(convention: str) -> float:
    """u_convention − u_opencv for the same point of the image: 0 (OpenCV) or 0.5 (COLMAP and
    Metashape, whose pixel centres sit at +0.5)."""
    _check_convention(convention)
    return _HALF[convention]


def image_centre(width: int, height: int, convention: str = "opencv") -> tuple[float, float]:
    """The centre of a W × H pixel array in absolute pixel coordinates of ``convention``:
    ((W − 1)/2, (H − 1)/2) for OpenCV, (W/2, H/2) for COLMAP and Metashape."""
    h = pixel_centre_offset(convention)
    return (width - 1) / 2.0 + h, (height - 1) / 2.0 + h


def to_opencv_pixels(uv: np.ndarray, convention: str) -> np.ndarray:
    """Absolute pixel coordinates (…, 2) in ``convention`` → OpenCV pixels."""
    return np.asarray(uv, dtype=float) - pixel_centre_offset(convention)


def from_opencv_pixels(uv: np.ndarray, convention: str) -> np.ndarray:
    """OpenCV pixels (…, 2) → absolute pixel coordinates in ``convention``."""
    return np.asarray(uv, dtype=float) + pixel_centre_offset(convention)


def photo_mm_to_opencv_pixels(
    xy_mm: np.ndarray, width: int, height: int, pixel_size_mm: tuple[float, float]
) -> np.ndarray:
    """Photogrammetric image coordinates (mm, x right, y up, origin at the image centre) →
    OpenCV pixels."""
    p = np.asarray(xy_mm, dtype=float)
    cu, cv = image_centre(width, height, "opencv")
    out = np.empty_like(p)
    out[..., 0] = cu + p[..., 0] / pixel_size_mm[0]
    out[..., 1] = cv - p[..., 1] / pixel_size_mm[1]
    return out


def opencv_pixels_to_photo_mm(
    uv: np.ndarray, width: int, height: int, pixel_size_mm: tuple[float, float]
) -> np.ndarray:
    """OpenCV pixels → photogrammetric image coordinates (mm, x right, y up, origin at the
    image centre)."""
    q = np.asarray(uv, dtype=float)
    cu, cv = image_centre(width, height, "opencv")
    out = np.empty_like(q)
    out[..., 0] = (q[..., 0] - cu) * pixel_size_mm[0]
    out[..., 1] = -(q[..., 1] - cv) * pixel_size_mm[1]
    return out
