"""Distortion metrics of a rectangular picture: TV distortion (SMIA and traditional), keystone,
line straightness and the anamorphic ratio, from a 2-D distortion grid whose outer rows and
columns are the picture's edges (docs/design.md, "Sensor metrics and the calibration
certificate").

The picture
    The rectangle whose IDEAL image (Pestrecov's Eq. 8 in 2-D, :mod:`distortion.grid.field`) is
    the grid's outer boundary: for a grid made with ``sensor=`` that is the sensor, corner to
    corner. Its edges are the grid's first and last rows and columns (ordered by their ideal
    coordinates, so any orientation of the grid is read the same way); the picture's centre lines
    are the middle row and column, which exist when the counts are odd (an even count is refused:
    the edge centres must be traced points, not interpolated ones). Every length below is
    measured on the ACTUAL (traced) image points, as a chart photographed to fill the picture
    would be measured; the ratios are scale-free, so the constant of orthoscopy drops out.

TV distortion (negative = barrel, positive = pincushion)
    Heights of the imaged rectangle: A1, A2 at its left and right edges (between the imaged
    corners), B at its centre (between the imaged top- and bottom-edge centres); lengths are
    the distances between the two points.

    * SMIA (Standard Mobile Imaging Architecture, *SMIA 1.0 Part 5: Camera Characterisation
      Specification*, Nokia / STMicroelectronics 2004, section "TV distortion"; as documented
      in Imatest's "Distortion" manual, which states it is twice the traditional value)::

          D_SMIA = (A − B) / B,   A = (A1 + A2) / 2

    * Traditional (television-industry) TV distortion ``ΔH / H``: the bow ΔH of the picture's
      top (or bottom) edge relative to its corners over the picture height H. With
      ``ΔH = (A − B) / 2`` (the mean bow of the top and bottom edges) and ``H = B``::

          D_TV = (A − B) / (2 B) = D_SMIA / 2   (exactly)

      Because both edges bow, ``A − B = 2 ΔH``: that is the factor of two between the two
      definitions. A definition that divides by the corner height A instead of B differs from
      D_TV only in the second order of the distortion.

    The same with widths (top, bottom and centre-row widths of the imaged rectangle) gives the
    horizontal variants ``tv_distortion_smia_horizontal`` and ``..._traditional_horizontal``
    (SMIA's own definition is the vertical one above).

    Closed form (tested): a purely radial field ``r' = r (1 + K1 r²)`` about the picture centre,
    on a picture of half-width a and half-height b, has A = 2b (1 + K1 (a² + b²)),
    B = 2b (1 + K1 b²), so ``D_SMIA = K1 a² / (1 + K1 b²)``.

Keystone (trapezoid)
    ``keystone_vertical = (W_top − W_bottom) / ((W_top + W_bottom) / 2)`` from the widths of the
    imaged top and bottom edges (between their corners); ``keystone_horizontal`` the same with the
    heights of the right and left edges, ``(A2 − A1) / ((A1 + A2) / 2)``. Zero for a centred lens
    (by symmetry). A plane projective map ``(x, y) → (x, y) / (1 + ε y)`` gives
    ``keystone_vertical = −2 ε b`` exactly.

Line straightness (smile)
    For each imaged line of the picture — its four edges and its two centre lines — the chord
    through its two end points and the signed perpendicular distance of each point from it; the
    *sag* is the distance of largest magnitude (mm) and ``fraction`` = sag / chord length. Sign:
    for an edge, positive toward the picture's centre (pincushion bows the edges inward) and
    negative away from it (barrel), as TV distortion; for the centre row positive toward +y,
    for the centre column toward +x (a centred lens leaves both straight). For the pure-K1 field
    above the top edge's sag is ``K1 a² b`` at its centre and its fraction
    ``K1 a b / (2 (1 + K1 (a² + b²)))``.

Anamorphic ratio
    ``scale_x / scale_y``: the horizontal and vertical image scales at the picture's centre,
    ``dx'/dx`` along the centre row and ``dy'/dy`` along the centre column (x, y the ideal
    coordinates), each the derivative at the centre of the polynomial that interpolates the
    line's central min(n, 15) points (degree one less; its error falls like the grid step to that
    power: 1e-12 on a 21 x 15 grid of the Cooke triplet on 36 x 24 mm). 1 for a lens centred on
    the picture with rotational symmetry, whatever its distortion; a lens with different scales
    across and along (an anamorphic attachment) gives their ratio. ``mean_scale_ratio``
    = (W_c / W) / (H_c / H) uses the whole centre lines instead (W_c, H_c their imaged lengths,
    W, H the ideal ones): it also holds the radial distortion of a non-square picture
    ((1 + K1 a²) / (1 + K1 b²) for the pure-K1 field).

Frames: image points in mm, x right, y up (the lens frame of :mod:`distortion.grid.field`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .errors import DataError

#: the lines whose straightness is measured, in report order
LINES = ("top", "bottom", "left", "right", "centre_row", "centre_column")
#: points (about the centre) of the interpolating polynomial of the central scales
SCALE_POINTS = 15


@dataclass(frozen=True)
class LineStraightness:
    """The sag of one imaged straight line of the picture (module docstring).

    name: one of :data:`LINES`; sag_mm: signed largest distance from the chord (mm; positive
    toward the picture centre for the edges, toward +y / +x for the centre row / column);
    chord_mm: chord length (mm); fraction: sag / chord; index: the point of the largest sag
    (0-based along the line, from left or bottom)."""

    name: str
    sag_mm: float
    chord_mm: float
    fraction: float
    index: int


@dataclass(frozen=True)
class SensorMetrics:
    """TV distortion, keystone, straightness and anamorphic ratio of one picture in one plane.

    Attributes
    ----------
    name : str
        Lens name ("" for points given directly).
    plane : int
        The grid's image plane (0-based; -1 for points).
    plane_label : str
        How the plane was given (s', defocus), for reports.
    width_mm, height_mm : float
        The ideal picture (the grid's outer boundary), mm.
    shape : (int, int)
        (rows, columns) of the grid.
    height_left_mm, height_right_mm, height_centre_mm : float
        A1, A2, B of the module docstring (imaged heights, mm).
    width_top_mm, width_bottom_mm, width_centre_mm : float
        The imaged widths (mm).
    tv_distortion_smia, tv_distortion_traditional : float
        ``(A − B)/B`` and ``(A − B)/(2B)`` (fractions; negative = barrel).
    tv_distortion_smia_horizontal, tv_distortion_traditional_horizontal : float
        The same with the widths.
    keystone_vertical, keystone_horizontal : float
        Fractions (module docstring).
    straightness : tuple of LineStraightness
        One per line of :data:`LINES`.
    scale_x, scale_y : float
        Central image scales dx'/dx, dy'/dy (dimensionless).
    anamorphic_ratio : float
        ``scale_x / scale_y``.
    mean_scale_ratio : float
        ``(W_c / W) / (H_c / H)`` over the whole centre lines.
    sensor : object
        The grid's sensor (a Sensor or (w, h) mm), None for another grid.
    notes : tuple of str
        Points that could not be traced and what they left undetermined.
    """

    name: str
    plane: int
    plane_label: str
    width_mm: float
    height_mm: float
    shape: tuple[int, int]
    height_left_mm: float
    height_right_mm: float
    height_centre_mm: float
    width_top_mm: float
    width_bottom_mm: float
    width_centre_mm: float
    tv_distortion_smia: float
    tv_distortion_traditional: float
    tv_distortion_smia_horizontal: float
    tv_distortion_traditional_horizontal: float
    keystone_vertical: float
    keystone_horizontal: float
    straightness: tuple[LineStraightness, ...]
    scale_x: float
    scale_y: float
    anamorphic_ratio: float
    mean_scale_ratio: float
    sensor: object = None
    notes: tuple[str, ...] = ()

    def line(self, name: str) -> LineStraightness:
        """The straightness of line ``name`` (:data:`LINES`)."""
        for s in self.straightness:
            if s.name == name:
                return s
        raise DataError(f"unknown line {name!r}; use one of {', '.join(LINES)}")

    def __repr__(self) -> str:
        return (
            f"SensorMetrics({self.name!r}, {self.width_mm:g} x {self.height_mm:g} mm: TV "
            f"distortion SMIA {100 * self.tv_distortion_smia:+.4f} %, traditional "
            f"{100 * self.tv_distortion_traditional:+.4f} %, keystone "
            f"{100 * self.keystone_vertical:+.3g} % (vertical), anamorphic ratio "
            f"{self.anamorphic_ratio:.6f})"
        )


# ------------------------------------------------------------------------------------------------


def _order(values: np.ndarray, what: str, tol: float) -> tuple[np.ndarray, int]:
    """Indices sorting the rows (or columns) by ideal coordinate, and the index of the centre
    line in that order (DataError when there is none)."""
    idx = np.argsort(values, kind="stable")
    v = values[idx]
    if np.any(np.diff(v) <= tol):
        raise DataError(f"the grid's {what} are not distinct lines of a rectangle")
    n = v.size
    if n < 3 or n % 2 == 0:
        raise DataError(
            f"the grid has {n} {what}: the picture's centre line must be a traced line; give an "
            "odd number of points (at least 3) along each axis, e.g. 21x15"
        )
    mid = 0.5 * (v[0] + v[-1])
    if abs(v[n // 2] - mid) > tol:
        raise DataError(
            f"the grid's middle {what[:-1]} is not the picture's centre line: space the grid "
            "evenly (as a sensor grid is)"
        )
    return idx, n // 2


def _length(p: np.ndarray, q: np.ndarray) -> float:
    return float(math.hypot(q[0] - p[0], q[1] - p[1]))


def _ratio(num: float, den: float) -> float:
    return num / den if math.isfinite(num) and math.isfinite(den) and den != 0.0 else math.nan


def _sag(name: str, pts: np.ndarray, toward: np.ndarray) -> LineStraightness:
    """Signed largest distance of ``pts`` (n, 2) from the chord of its end points, positive on the
    side of the point ``toward``."""
    if not np.all(np.isfinite(pts)) or not np.all(np.isfinite(toward)):
        return LineStraightness(name, math.nan, math.nan, math.nan, -1)
    p, q = pts[0], pts[-1]
    chord = q - p
    L = float(math.hypot(chord[0], chord[1]))
    if L == 0.0:
        return LineStraightness(name, math.nan, 0.0, math.nan, -1)
    d = (chord[0] * (pts[:, 1] - p[1]) - chord[1] * (pts[:, 0] - p[0])) / L
    side = chord[0] * (toward[1] - p[1]) - chord[1] * (toward[0] - p[0])
    if side < 0:
        d = -d
    k = int(np.argmax(np.abs(d)))
    return LineStraightness(name, float(d[k]), L, float(d[k]) / L, k)


def _central_scale(u: np.ndarray, v: np.ndarray, c: int) -> float:
    """d v / d u at u[c] of the polynomial interpolating the min(n, SCALE_POINTS) points of
    (u, v) about index ``c`` (NaN when one of them is not finite)."""
    m = min(c, u.size - 1 - c, (SCALE_POINTS - 1) // 2)
    s = slice(c - m, c + m + 1)
    if m < 1 or not (np.all(np.isfinite(u[s])) and np.all(np.isfinite(v[s]))):
        return math.nan
    poly = np.polynomial.Polynomial.fit(u[s], v[s], 2 * m)
    return float(poly.deriv()(u[c]))


def sensor_metrics_from_points(
    ideal: npt.ArrayLike,
    actual: npt.ArrayLike,
    *,
    name: str = "",
    plane: int = -1,
    plane_label: str = "",
    sensor: object = None,
) -> SensorMetrics:
    """The picture metrics (module docstring) of a rectangular grid of image points.

    Parameters
    ----------
    ideal : array_like
        (rows, columns, 2) ideal image points (mm): a rectangular lattice, each row at one ideal
        y and each column at one ideal x, evenly spaced about a centre line (odd counts).
    actual : array_like
        (rows, columns, 2) the real image points (mm; NaN where not traced), same shape.
    name, plane, plane_label, sensor
        Carried into the result for reports.

    Returns
    -------
    SensorMetrics
    """
    I = np.asarray(ideal, dtype=float)
    P = np.asarray(actual, dtype=float)
    if I.shape != P.shape or I.ndim != 3 or I.shape[2] != 2:
        raise DataError("ideal and actual must be (rows, columns, 2) arrays of the same shape")
    if not np.all(np.isfinite(I)):
        raise DataError("the ideal grid holds non-finite points")
    span = float(np.max(np.abs(I))) or 1.0
    tol = 1e-9 * span
    if (
        np.max(np.abs(I[..., 1] - I[:, :1, 1])) > tol
        or np.max(np.abs(I[..., 0] - I[:1, :, 0])) > tol
    ):
        raise DataError(
            "the ideal points do not form a rectangular lattice (each row at one y, each column "
            "at one x): the picture metrics need a grid made like a sensor grid"
        )
    rows, rc = _order(I[:, 0, 1], "rows", tol)
    cols, cc = _order(I[0, :, 0], "columns", tol)
    I = I[rows][:, cols]
    P = P[rows][:, cols]
    ny, nx = I.shape[:2]
    W = float(I[0, -1, 0] - I[0, 0, 0])
    H = float(I[-1, 0, 1] - I[0, 0, 1])
    bl, br, tl, tr = P[0, 0], P[0, -1], P[-1, 0], P[-1, -1]
    A1 = _length(bl, tl)  # left edge height
    A2 = _length(br, tr)  # right edge height
    B = _length(P[0, cc], P[-1, cc])  # centre height
    Wt = _length(tl, tr)
    Wb = _length(bl, br)
    Wc = _length(P[rc, 0], P[rc, -1])
    A = 0.5 * (A1 + A2)
    Aw = 0.5 * (Wt + Wb)
    smia = _ratio(A - B, B)
    smia_h = _ratio(Aw - Wc, Wc)
    centre = P[rc, cc]
    up = P[rc, 0] + np.array([0.0, abs(W) + abs(H)])
    right = P[0, cc] + np.array([abs(W) + abs(H), 0.0])
    sag = (
        _sag("top", P[-1, :], centre),
        _sag("bottom", P[0, :], centre),
        _sag("left", P[:, 0], centre),
        _sag("right", P[:, -1], centre),
        _sag("centre_row", P[rc, :], up),
        _sag("centre_column", P[:, cc], right),
    )
    sx = _central_scale(I[rc, :, 0], P[rc, :, 0], cc)
    sy = _central_scale(I[:, cc, 1], P[:, cc, 1], rc)
    notes = []
    bad = int(np.count_nonzero(~np.all(np.isfinite(P), axis=-1)))
    if bad:
        notes.append(
            f"{bad} of {nx * ny} grid points could not be traced; metrics that need them are NaN"
        )
    return SensorMetrics(
        name=name,
        plane=int(plane),
        plane_label=plane_label,
        width_mm=W,
        height_mm=H,
        shape=(ny, nx),
        height_left_mm=A1,
        height_right_mm=A2,
        height_centre_mm=B,
        width_top_mm=Wt,
        width_bottom_mm=Wb,
        width_centre_mm=Wc,
        tv_distortion_smia=smia,
        tv_distortion_traditional=0.5 * smia,
        tv_distortion_smia_horizontal=smia_h,
        tv_distortion_traditional_horizontal=0.5 * smia_h,
        keystone_vertical=_ratio(Wt - Wb, Aw),
        keystone_horizontal=_ratio(A2 - A1, A),
        straightness=sag,
        scale_x=sx,
        scale_y=sy,
        anamorphic_ratio=_ratio(sx, sy),
        mean_scale_ratio=_ratio(Wc / W, B / H),
        sensor=sensor,
        notes=tuple(notes),
    )


def sensor_metrics(grid, plane: int = 0) -> SensorMetrics:
    """The picture metrics (module docstring) of a :class:`~distortion.grid.DistortionGrid` in
    ``plane`` (0-based): the picture is the rectangle its ideal points span — the sensor, for a
    grid made with ``sensor=`` (e.g. ``distortion_grid(lens, sensor="36x24", grid=(21, 15))``).

    The counts of the grid must be odd (the edge centres are traced points).

    Parameters
    ----------
    grid : DistortionGrid
        A 2-D grid of fields (rows × columns, odd counts) whose ideal points form a rectangular
        lattice.
    plane : int
        The grid's image plane, 0-based (default 0).

    Returns
    -------
    SensorMetrics
        TV distortion (SMIA and traditional, vertical and horizontal; fractions, negative =
        barrel), keystone, line straightness and the anamorphic ratio, measured on the traced
        points; the picture's size in mm.

    Raises
    ------
    DataError
        ``plane`` out of range, a grid that is not 2-D, ideal points that are not a rectangular
        lattice, fewer than 3 or an even number of rows or columns, a middle row or column that
        is not the picture's centre line.
    """
    p = grid.plane_index(plane)
    if len(grid.shape) != 2:
        raise DataError("the picture metrics need a 2-D grid of fields (rows x columns)")
    ref = np.asarray(grid.reference_xy[p], dtype=float)
    if not np.all(np.isfinite(ref)):  # the lattice's shape is all that matters here
        ref = np.zeros(2)
    ideal = ref + grid.constant[p] * grid.abscissa
    return sensor_metrics_from_points(
        ideal,
        grid.actual[p],
        name=grid.name,
        plane=p,
        plane_label=grid.plane_label(p),
        sensor=grid.sensor,
    )
