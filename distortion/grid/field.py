"""The 2-D distortion field of a traced lens: real chief rays over a grid of fields, moved to any
image plane, against the ideal image of Pestrecov's Eq. (8) generalised to two dimensions
(docs/design.md, "2-D distortion").

Ideal image (Pestrecov 1958, Eq. 8 in 2-D)
    For a field with Pestrecov's abscissa X = (Xx, Xy) — the direction tangents
    (tan αx, tan αy) of the object-space chief ray for an object at infinity, the object
    coordinates (x, y) in mm for a finite object (a nominal angle stands for p0·tan α) — the
    ideal image point in a plane is ::

        P0' = R + K0 · X

    with K0 the constant of orthoscopy of THAT plane (F0 = p0'/m_e in mm, or M0 = p0'/(m_e p0);
    :func:`raytrace.paraxial.pestrecov_constants`) and R the named reference point of the plane.
    The distortion vector is D = P' − P0' (mm), P' the real chief ray's point. Along any azimuth
    of a centred lens, with R on the axis, the radial component of D is Pestrecov's D0 of the 1-D
    curve (:func:`distortion.characteristic.characteristic_distortion`) and the tangential one is
    zero.

    Normalised ideal coordinates: t = X (infinity) or t = X / p0 (finite; the direction tangents
    of the paraxial chief ray toward the entrance pupil E0), with the camera constant
    c = K0 (infinity) or c = K0·p0 (finite; = p0'/m_e, mm), so that K0·X = c·t: the form of the
    camera models (:mod:`distortion.camera`).

Frames
    Image points are (x', y') in the lens frame (mm), looking along −z (from the image toward the
    lens): x right, y up. The photogrammetric image frame of the camera models (Australis mm: x
    right, y up, origin at the image centre) is this frame with its origin on the lens axis (or
    at the sensor centre when a sensor with a principal-point offset is given); the OpenCV ideal
    direction of a field is (tx, −ty) (OpenCV's y points down). With this choice lens +y is
    *down* in the world of the camera (Y_cam = y_lens, X_cam = −x_lens, Z_cam = −z_lens: a
    rotation by 180° about the lens y axis), and the picture is upright.

Reference points (each named; all computed for every plane)
    ``axial``
        The image of the axial object point: the chief ray of the field t = 0 (the object point
        on the lens axis, or the object at infinity in the axis direction).
    ``ppa``
        Principal point of autocollimation: the image of an object at infinity in the direction
        normal to the image plane (the collimator direction in autocollimation; ASPRS *Manual of
        Photogrammetry*, 4th ed. 1980, ch. 4 "Camera calibration" and its glossary; Clarke &
        Fryer 1998, *The development of camera calibration methods and models*, Photogramm. Rec.
        16(91)). The image planes here are normal to z, so it is the chief ray of the direction
        (0, 0, 1); for an object at infinity it coincides with ``axial``.
    ``ppbs``
        Principal point of best symmetry: the point about which the radial distortion is most
        nearly symmetric (same sources; the "point of symmetry" of USGS calibration reports):
        the principal point (x0, y0) of a least-squares fit of a purely radial model
        P' = (x0, y0) + (c + Σ a_i |t|^2i) t (c, a_i free) to the grid
        (:func:`distortion.grid.decompose.solve_linear` with ``asymmetric=False``). On a grid
        symmetric under t → −t it is exactly the centroid of the real image points.

Sensor
    ``sensor=`` (a :class:`~distortion.camera.Sensor` or a size "36x24" in mm) makes the grid of
    fields whose IDEAL image points (axis as reference, K0 of the first plane) fill the sensor
    from corner to corner: rows and columns of the grid are the sensor's lines, the first and
    last row and column its edges (what the rectangular-sensor metrics of TV distortion and
    keystone read).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from raytrace.errors import TraceError
from raytrace.lens import Lens, require_lens
from raytrace.limits import MAX_FIELDS
from raytrace.paraxial import ImagePlane, ParaxialResult
from raytrace.units import is_whole, real_array

from ..curve import FieldKindMixin, curve_field_kind, plane_label, requested_fields
from ..errors import DataError
from .decompose import UndeterminedFit, distinct_radii, solve_linear

REFERENCE_POINTS = ("axial", "ppa", "ppbs")
DEFAULT_GRID = (21, 21)
#: fields a grid may have without ``allow_large=True``: the command line's limit
#: (:data:`raytrace.limits.MAX_FIELDS`, lifted there by --allow-large); a field costs about
#: 400 bytes of arrays per image plane
MAX_GRID_FIELDS = MAX_FIELDS
#: radial terms of the radially symmetric fit that defines the PPBS
PPBS_RADIAL_TERMS = 3


@dataclass(frozen=True, eq=False)
class DistortionGrid(FieldKindMixin):
    """Distortion of one lens and object over a 2-D set of fields in one or more image planes.

    Arrays over fields have the grid's ``shape`` ((rows, columns) = (ny, nx) for a grid);
    arrays over planes lead with the plane index; points end with (x, y).

    Attributes
    ----------
    name : str
        Lens name.
    field_kind : str
        ``"angle"`` (object at infinity), ``"height"`` or ``"nominal-angle"`` (finite object).
    field_x, field_y : ndarray
        The fields as traced: degrees (angles, nominal angles) or object coordinates in mm.
    object_distance : float
        mm from the object plane to the first vertex (inf for infinity).
    abscissa : ndarray
        (*shape, 2) Pestrecov's abscissa X: (tan αx, tan αy), or the object point (mm).
    tx, ty : ndarray
        Normalised ideal coordinates t (module docstring).
    z_planes, s_prime, from_last_vertex, defocus : ndarray
        (p,) the planes: absolute z, from H', from the last vertex, from the Gaussian plane (mm).
    constant : ndarray
        (p,) K0 of Eq. (8) per plane (F0 mm or M0).
    camera_constant : ndarray
        (p,) c = K0 (infinity) or K0·p0 (finite), mm.
    reference_point : str
        The named point ``R`` the ideal image is placed about (``REFERENCE_POINTS``).
    axial_xy, ppa_xy, ppbs_xy : ndarray
        (p, 2) the three named points in each plane (mm; NaN where not traceable).
    actual, ideal : ndarray
        (p, *shape, 2) real chief-ray points and ideal points (mm).
    status : ndarray
        Trace status per field (``raytrace.trace.STATUS_*``); NaN points where not OK.
    paraxial : ParaxialResult
    lens : Lens
    clip : bool
    wavelength : float
        nm.
    sensor : Sensor or None
        The sensor the grid fills, when one was given.
    """

    name: str
    field_kind: str
    field_x: np.ndarray
    field_y: np.ndarray
    object_distance: float
    abscissa: np.ndarray
    tx: np.ndarray
    ty: np.ndarray
    z_planes: np.ndarray
    s_prime: np.ndarray
    from_last_vertex: np.ndarray
    defocus: np.ndarray
    constant: np.ndarray
    camera_constant: np.ndarray
    reference_point: str
    axial_xy: np.ndarray
    ppa_xy: np.ndarray
    ppbs_xy: np.ndarray
    actual: np.ndarray
    ideal: np.ndarray
    status: np.ndarray
    paraxial: ParaxialResult
    lens: Lens | None = None
    clip: bool = True
    wavelength: float = math.nan
    sensor: object = None

    # ---- shape and planes ---------------------------------------------------------------
    @property
    def shape(self) -> tuple[int, ...]:
        return self.status.shape

    @property
    def n_planes(self) -> int:
        return int(self.z_planes.size)

    @property
    def ok(self) -> np.ndarray:
        return self.status == 0

    def plane_index(self, plane: int) -> int:
        """``plane`` as a 0-based index of the grid's image planes; DataError when out of
        range."""
        if not 0 <= int(plane) < self.n_planes:
            raise DataError(f"plane={plane}: the grid has {self.n_planes} image plane(s) (0-based)")
        return int(plane)

    def plane_label(self, i: int) -> str:
        return plane_label(self.s_prime[i], self.defocus[i])

    def named_point(self, name: str) -> np.ndarray:
        """(p, 2) the reference point ``name`` (``REFERENCE_POINTS``) in every plane."""
        if name not in REFERENCE_POINTS:
            raise DataError(f"unknown reference point {name!r}; use {', '.join(REFERENCE_POINTS)}")
        return {"axial": self.axial_xy, "ppa": self.ppa_xy, "ppbs": self.ppbs_xy}[name]

    @property
    def reference_xy(self) -> np.ndarray:
        """(p, 2) the grid's reference point R in every plane."""
        return self.named_point(self.reference_point)

    # ---- distortion vectors and their components ------------------------------------------
    @property
    def D(self) -> np.ndarray:
        """(p, *shape, 2) distortion vectors P' − P0' (mm)."""
        return self.actual - self.ideal

    @property
    def azimuth_deg(self) -> np.ndarray:
        """Azimuth φ of each field (degrees, atan2(ty, tx); 0 at the centre)."""
        return np.degrees(np.arctan2(self.ty, self.tx))

    def _unit(self):
        phi = np.arctan2(self.ty, self.tx)
        return np.cos(phi), np.sin(phi)

    @property
    def radial(self) -> np.ndarray:
        """(p, *shape) radial component D·ê_r (mm), ê_r along the field's azimuth (the ideal
        point's direction from R); at the centre ê_r = +x."""
        cx, sx = self._unit()
        d = self.D
        return d[..., 0] * cx + d[..., 1] * sx

    @property
    def tangential(self) -> np.ndarray:
        """(p, *shape) tangential component D·ê_t (mm), ê_t = ê_r turned by +90°."""
        cx, sx = self._unit()
        d = self.D
        return -d[..., 0] * sx + d[..., 1] * cx

    @property
    def ideal_radius(self) -> np.ndarray:
        """(p, *shape) |P0' − R| = c·|t| (mm)."""
        c = self.camera_constant.reshape((-1,) + (1,) * len(self.shape))
        return c * np.hypot(self.tx, self.ty)[None]

    def max_distortion(self, plane: int = 0) -> float:
        """Largest |D| (mm) in ``plane`` over the traced fields."""
        d = np.hypot(self.D[plane, ..., 0], self.D[plane, ..., 1])
        return float(np.nanmax(d)) if np.isfinite(d).any() else math.nan

    def __repr__(self) -> str:
        obj = "inf" if math.isinf(self.object_distance) else f"{self.object_distance:g} mm"
        planes = ", ".join(f"{v:.4g}" for v in self.s_prime[:4]) + (
            ", ..." if self.n_planes > 4 else ""
        )
        bad = int(np.count_nonzero(self.status != 0))
        return (
            f"DistortionGrid({self.name!r}, {self.shape} fields ({self.field_kind}), object "
            f"{obj}, s' = [{planes}] mm, reference {self.reference_point}, max |D| = "
            f"{self.max_distortion(0):.6g} mm" + (f", {bad} fields failed" if bad else "") + ")"
        )


# ------------------------------------------------------------------------------------------------


def distortion_grid(
    lens: Lens,
    fields_x_deg: npt.ArrayLike | None = None,
    fields_y_deg: npt.ArrayLike | None = None,
    *,
    object_x_mm: npt.ArrayLike | None = None,
    object_y_mm: npt.ArrayLike | None = None,
    grid: int | tuple[int, int] | None = None,
    sensor=None,
    plane: ImagePlane | Sequence[ImagePlane] | str | None = None,
    s_prime: npt.ArrayLike | None = None,
    from_last_vertex: npt.ArrayLike | None = None,
    defocus: npt.ArrayLike | None = None,
    object_distance: float | str | None = None,
    object_s: float | None = None,
    object_scale: float | None = None,
    reference_point: str = "axial",
    wavelength: float | str | None = None,
    clip: bool = True,
    allow_large: bool = False,
) -> DistortionGrid:
    """The 2-D distortion field of ``lens`` on a grid of fields, in one or more image planes.

    Parameters
    ----------
    lens : Lens
    fields_x_deg, fields_y_deg : array_like, optional
        The field angles (degrees; :func:`raytrace.trace.chief_rays_2d` convention: tan αx = L/N,
        tan αy = M/N; nominal angles with a finite object) of the grid's columns and rows: the
        grid is their outer product, shape (len(y), len(x)).
    object_x_mm, object_y_mm : array_like, optional
        Object coordinates (mm) of the columns and rows instead (finite objects).
    grid : int or (nx, ny), optional
        With no fields and no sensor: an nx × ny grid (default 21 × 21) equally spaced in
        tan α (or object coordinate) whose corners lie at the lens's field (a square inscribed in
        the field circle). Whole numbers of at least 2.
    sensor : Sensor, str or (w, h), optional
        Fill a sensor: the grid of fields whose ideal images span it corner to corner (module
        docstring); ``grid`` sets the number of points (default 21 × 21). Width and height are
        positive, finite mm.
    plane, s_prime, from_last_vertex, defocus
        The image plane(s) (docs/design.md, "Vocabulary"); default the Gaussian plane. All planes
        come from one trace. Distances in mm, or strings with a length unit as the command line
        takes them (``"50.5mm"``).
    object_distance, object_s, object_scale
        The object plane (at most one); default the lens's.
    reference_point : {"axial", "ppa", "ppbs"}
        The point the ideal image is placed about (module docstring).
    wavelength : float, optional
        nm; default the lens's reference wavelength.
    clip : bool
        Apply the lens's semi-diameters to the chief rays.
    allow_large : bool
        Allow more than ``MAX_GRID_FIELDS`` fields (the command line's ``--allow-large``); a
        larger grid is refused before anything is allocated.

    Returns
    -------
    DistortionGrid
    """
    require_lens(lens)
    from raytrace.paraxial import resolve_paraxial
    from raytrace.trace.chief2d import requested_fields_2d

    if reference_point not in REFERENCE_POINTS:
        raise TraceError(
            f"reference_point={reference_point!r}; use one of {', '.join(REFERENCE_POINTS)}"
        )
    nx, ny = grid_points(grid)
    s = sensor_size(sensor) if sensor is not None else None
    given = requested_fields_2d(fields_x_deg, fields_y_deg, object_x_mm, object_y_mm)
    if given is not None and sensor is not None:
        raise TraceError("give fields or a sensor, not both")
    if given is not None:
        kind, ax, ay = given
        ax, ay = np.atleast_1d(ax).ravel(), np.atleast_1d(ay).ravel()
        names = (
            ("fields_x_deg", "fields_y_deg") if kind == "angle" else ("object_x_mm", "object_y_mm")
        )
        for name, a in zip(names, (ax, ay), strict=True):
            if a.size == 0:  # as characteristic_distortion: an empty grid has no distortion
                raise TraceError(f"no fields given: {name} is empty")
        check_field_count(ax.size, ay.size, allow_large, "the fields")
    else:
        check_field_count(nx, ny, allow_large, f"grid={grid!r}" if grid is not None else "the grid")
    # a decentered or tilted lens: the first-order data (ideal image, camera constant) of its
    # centred lens (raytrace.paraxial refuses a lens that is not centred)
    par = resolve_paraxial(lens, object_distance, object_s, object_scale, wavelength, nominal=True)
    if given is not None:
        FX, FY = np.meshgrid(ax, ay)
    else:
        FX, FY, kind = _default_fields(lens, par, nx, ny, s)
    return grid_from_fields(
        lens,
        FX,
        FY,
        kind,
        par,
        plane=plane,
        s_prime=s_prime,
        from_last_vertex=from_last_vertex,
        defocus=defocus,
        reference_point=reference_point,
        clip=clip,
        sensor=s,
    )


def grid_points(grid) -> tuple[int, int]:
    """(nx, ny) of ``grid`` (n or (nx, ny), whole numbers >= 2); DataError naming the fix."""
    if grid is None:
        return DEFAULT_GRID
    fix = "give n or (nx, ny) as whole numbers of points, at least 2 each, e.g. grid=(21, 21)"
    if is_whole(grid):
        vals = (grid, grid)
    elif isinstance(grid, str | bytes) or not hasattr(grid, "__len__"):
        raise DataError(f"grid={grid!r}: {fix}")
    else:
        vals = tuple(grid)
        if len(vals) != 2 or not all(is_whole(v) for v in vals):
            raise DataError(f"grid={grid!r}: {fix}")
    if min(vals) < 2:
        raise DataError(f"grid={grid!r}: at least 2 points along each axis, e.g. grid=(21, 21)")
    return int(vals[0]), int(vals[1])


def check_field_count(nx: int, ny: int, allow_large: bool, what: str) -> None:
    """Refuse more than ``MAX_GRID_FIELDS`` fields without ``allow_large``, before any work."""
    n = int(nx) * int(ny)
    if n > MAX_GRID_FIELDS and not allow_large:
        raise DataError(
            f"{what}: {n} fields, more than {MAX_GRID_FIELDS} (about {n * 400 / 1e9:.3g} GB per "
            "image plane and a long run); give allow_large=True to run it anyway"
        )


def sensor_size(sensor):
    """The sensor of a grid or certificate, checked where it enters: a
    :class:`~distortion.camera.Sensor` as it is, or (width, height) in mm from a size "36x24" or
    (36, 24). DataError, naming the sensor, for a width or height that is not a positive finite
    number of mm (a negative width would mirror the grid; a zero one make no grid)."""
    from ..camera.sensor import Sensor, parse_size_mm

    if isinstance(sensor, Sensor):
        return sensor
    if isinstance(sensor, bool | np.bool_) or not (
        isinstance(sensor, str) or hasattr(sensor, "__len__")
    ):
        raise DataError(f"sensor={sensor!r}: give a Sensor, a size 'WxH' in mm or (w, h) in mm")
    try:
        return parse_size_mm(sensor)  # refuses a width or height that is not positive
    except (TypeError, ValueError) as e:
        if isinstance(e, DataError):
            raise
        raise DataError(
            f"sensor={sensor!r}: give a Sensor, a size 'WxH' in mm or (w, h) in mm"
        ) from None


def _default_fields(lens, par, nx, ny, sensor):
    """(FX, FY, kind) of the default grid: the lens's field square, or a sensor's fill
    (``sensor`` checked by :func:`sensor_size`)."""
    finite = not par.infinite
    if sensor is not None:
        from ..camera.sensor import Sensor

        s = sensor
        if isinstance(s, Sensor):
            w, h = s.width_mm, s.height_mm
            dx, dy = s.principal_point_offset_mm
        else:
            (w, h), (dx, dy) = s, (0.0, 0.0)
        from raytrace.paraxial import pestrecov_constants

        K0 = pestrecov_constants(par, par.s_prime_gauss).scale
        # sensor centre in the lens frame: the axis lies at (dx, dy) from the centre
        xs = np.linspace(-w / 2, w / 2, nx) - dx
        ys = np.linspace(-h / 2, h / 2, ny) - dy
        X, Y = np.meshgrid(xs / K0, ys / K0)  # Pestrecov's abscissa of the ideal points
        if not finite:
            return np.degrees(np.arctan(X)), np.degrees(np.arctan(Y)), "angle"
        return X, Y, "height"
    fk, fv = lens.field.kind, float(lens.field.value)
    if fk == "angle":
        T = math.tan(math.radians(fv)) / math.sqrt(2.0)
        tx = np.linspace(-T, T, nx)
        ty = np.linspace(-T, T, ny)
        X, Y = np.meshgrid(np.degrees(np.arctan(tx)), np.degrees(np.arctan(ty)))
        return X, Y, "angle"
    if not finite:
        raise TraceError("the lens's field is an object height but the object is at infinity")
    H = fv / math.sqrt(2.0)
    X, Y = np.meshgrid(np.linspace(-H, H, nx), np.linspace(-H, H, ny))
    return X, Y, "height"


def grid_from_fields(
    lens: Lens,
    fields_x: np.ndarray,
    fields_y: np.ndarray,
    field_kind: str,
    par: ParaxialResult,
    *,
    plane=None,
    s_prime=None,
    from_last_vertex=None,
    defocus=None,
    reference_point: str = "axial",
    clip: bool = True,
    sensor=None,
) -> DistortionGrid:
    """:func:`distortion_grid` for fields already resolved: ``fields_x``, ``fields_y`` (same
    shape, any set of points: degrees or mm) of ``field_kind`` "angle" | "height", for the
    object and wavelength of ``par``."""
    from raytrace.paraxial import image_planes, orthoscopy_abscissa, orthoscopy_constants, plane_z
    from raytrace.trace.chief2d import aim_2d

    if reference_point not in REFERENCE_POINTS:
        raise TraceError(
            f"reference_point={reference_point!r}; use one of {', '.join(REFERENCE_POINTS)}"
        )
    FX = np.asarray(fields_x, dtype=float)
    FY = np.asarray(fields_y, dtype=float)
    infinite = par.infinite
    kind = curve_field_kind(field_kind, infinite)
    planes = image_planes(
        plane, s_prime=s_prime, from_last_vertex=from_last_vertex, defocus=defocus
    )
    z = plane_z(par, planes)
    sp = np.asarray(par.s_prime_of(z), dtype=float)
    K0 = orthoscopy_constants(par, sp)
    cc = K0 if infinite else K0 * par.p0
    X = orthoscopy_abscissa(par, FX, field_kind)
    Y = orthoscopy_abscissa(par, FY, field_kind)
    tx, ty = (X, Y) if infinite else (X / par.p0, Y / par.p0)

    od, wl = par.object_distance, par.wavelength
    cr = aim_2d(lens, FX, FY, field_kind, od, wl, clip)
    P = cr.positions_at(z)  # (p, *shape, 2)
    P = np.where(cr.ok[None, ..., None], P, np.nan)
    # the named points: the chief rays of t = 0 (axial) and of the direction (0, 0, 1) (PPA)
    zero = np.zeros(1)
    axial = aim_2d(lens, zero, zero, "height" if not infinite else "angle", od, wl, False)
    axial_xy = axial.positions_at(z)[:, 0, :]
    if infinite:
        ppa_xy = axial_xy.copy()
    else:
        try:
            ppa = aim_2d(lens, zero, zero, "angle", math.inf, wl, False)
            ppa_xy = ppa.positions_at(z)[:, 0, :]
        except TraceError:  # e.g. an aperture given as object-space NA: no infinite object
            ppa_xy = np.full((z.size, 2), np.nan)
    t = np.stack([tx.ravel(), ty.ravel()], axis=1)
    ppbs_xy = np.full((z.size, 2), np.nan)
    for i in range(z.size):
        ppbs_xy[i] = _ppbs(t, P[i].reshape(-1, 2))
    ref = {"axial": axial_xy, "ppa": ppa_xy, "ppbs": ppbs_xy}[reference_point]
    XY = np.stack([X, Y], axis=-1)
    extra = (1,) * X.ndim
    ideal = ref.reshape((-1, *extra, 2)) + K0.reshape((-1, *extra, 1)) * XY[None]
    ideal = np.where(np.isfinite(P), ideal, np.nan)
    return DistortionGrid(
        name=lens.name,
        field_kind=kind,
        field_x=FX.copy(),
        field_y=FY.copy(),
        object_distance=od,
        abscissa=XY,
        tx=tx,
        ty=ty,
        z_planes=z,
        s_prime=sp,
        from_last_vertex=z - par.z_last,
        defocus=z - par.z_gauss,
        constant=K0,
        camera_constant=cc,
        reference_point=reference_point,
        axial_xy=axial_xy,
        ppa_xy=ppa_xy,
        ppbs_xy=ppbs_xy,
        actual=P,
        ideal=ideal,
        status=cr.status.copy(),
        paraxial=par,
        lens=lens,
        clip=bool(clip),
        wavelength=float(wl),
        sensor=sensor,
    )


def _ppbs(t: np.ndarray, img: np.ndarray) -> tuple[float, float]:
    """The PPBS (module docstring) of the points ``img`` (N, 2) at ``t``: the principal point of
    the radial fit with ``PPBS_RADIAL_TERMS`` terms, or as many as the distinct field radii of
    the traced points determine (c takes one); NaN where the points do not determine it."""
    ok = np.all(np.isfinite(img), axis=1) & np.all(np.isfinite(t), axis=1)
    terms = min(PPBS_RADIAL_TERMS, distinct_radii(t[ok]) - 1)
    if terms < 0:
        return math.nan, math.nan
    try:
        fit = solve_linear(t, img, radial_terms=terms, asymmetric=False)
    except (UndeterminedFit, DataError):
        return math.nan, math.nan
    return fit.values["x0"], fit.values["y0"]


# ------------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class RadialByAzimuth:
    """Radial (and tangential) distortion along several azimuths: Pestrecov's characteristic
    curve generalised per azimuth.

    Attributes
    ----------
    azimuths_deg : ndarray
        (m,) the azimuths φ of the ideal image points (degrees from +x toward +y).
    fields : ndarray
        (n,) the radial field values: total field angles θ in degrees (tan θ = |t|; nominal with
        a finite object) or object radii in mm.
    x : ndarray
        (n,) Pestrecov's abscissa |X|: tan θ or the object radius (mm).
    radial, tangential : ndarray
        (p, m, n) D·ê_r and D·ê_t (mm).
    ideal_radius : ndarray
        (p, n) |P0' − R| = K0·|X| (mm).
    grid : DistortionGrid
        The traced polar grid (shape (m, n)) the curves come from.
    """

    azimuths_deg: np.ndarray
    fields: np.ndarray
    x: np.ndarray
    radial: np.ndarray
    tangential: np.ndarray
    ideal_radius: np.ndarray
    grid: DistortionGrid

    @property
    def field_kind(self) -> str:
        return self.grid.field_kind

    def __repr__(self) -> str:
        az = ", ".join(f"{a:g}" for a in self.azimuths_deg)
        return (
            f"RadialByAzimuth({self.grid.name!r}, azimuths [{az}] deg, {self.fields.size} "
            f"fields {self.fields.min():g}..{self.fields.max():g}, reference "
            f"{self.grid.reference_point})"
        )


def radial_by_azimuth(
    lens: Lens,
    azimuths_deg: npt.ArrayLike = (0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0),
    fields_deg: npt.ArrayLike | None = None,
    *,
    object_radii_mm: npt.ArrayLike | None = None,
    plane: ImagePlane | Sequence[ImagePlane] | str | None = None,
    s_prime: npt.ArrayLike | None = None,
    from_last_vertex: npt.ArrayLike | None = None,
    defocus: npt.ArrayLike | None = None,
    object_distance: float | str | None = None,
    object_s: float | None = None,
    object_scale: float | None = None,
    reference_point: str = "axial",
    wavelength: float | str | None = None,
    clip: bool = True,
    allow_large: bool = False,
) -> RadialByAzimuth:
    """Radial and tangential distortion along rays of azimuth φ from the reference point: the
    fields whose ideal image points lie at azimuth φ, (tan αx, tan αy) = tan θ (cos φ, sin φ)
    (or, finite object, the object points −r (cos φ, sin φ), whose inverted images lie at φ).
    Radial is outward (positive = pincushion), tangential counter-clockwise.

    Parameters
    ----------
    lens : Lens
    azimuths_deg : array_like
        Azimuths φ in degrees (default every 45°).
    fields_deg : array_like, optional
        Total field angles θ ≥ 0 in degrees (nominal with a finite object); default 11 from 0 to
        the lens's field.
    object_radii_mm : array_like, optional
        Object radii (mm, finite object) instead.
    plane, s_prime, from_last_vertex, defocus, object_distance, object_s, object_scale,
    reference_point, wavelength, clip, allow_large
        As :func:`distortion_grid` (the limit is on azimuths × fields).

    Returns
    -------
    RadialByAzimuth
        For a centred lens and ``reference_point="axial"`` its radial curves equal the 1-D
        characteristic distortion D0 at the same fields (tangential zero).
    """
    require_lens(lens)
    from raytrace.paraxial import resolve_paraxial
    from raytrace.trace.chief import checked_aim_request

    # a decentered or tilted lens: the first-order data (ideal image, camera constant) of its
    # centred lens (raytrace.paraxial refuses a lens that is not centred)
    par = resolve_paraxial(lens, object_distance, object_s, object_scale, wavelength, nominal=True)
    kind, r = requested_fields(
        lens, par.infinite, fields_deg, object_radii_mm, heights_name="object_radii_mm"
    )
    if r.size == 0:  # as characteristic_distortion
        name = "object_radii_mm" if object_radii_mm is not None else "fields_deg"
        raise TraceError(f"no fields given: {name} is empty")
    if np.any(r < 0):
        raise TraceError("radial fields are total field angles or radii: give values >= 0")
    # the range check of every aim (finite; angles strictly within ±90°) on the total field: a
    # field of 100° would otherwise wrap through tan into one within ±90° and be traced
    checked_aim_request(kind, par.object_distance, r, heights="object radii")
    what = "azimuths_deg must be finite angles in degrees (from +x toward +y)"
    try:  # numbers only: a bool or a complex number is refused (raytrace.units.real_array)
        az = np.atleast_1d(real_array(azimuths_deg, "azimuths_deg", error=ValueError)).ravel()
    except ValueError:
        raise TraceError(f"{what}, got {azimuths_deg!r}") from None
    if az.size == 0:
        raise TraceError("no azimuths given: azimuths_deg is empty")
    if not np.all(np.isfinite(az)):
        raise TraceError(f"{what}, got {az[~np.isfinite(az)][0]:g}")
    check_field_count(az.size, r.size, allow_large, "azimuths x fields")
    phi = np.radians(az)[:, None]
    if kind == "angle":
        T = np.tan(np.radians(r))[None, :]
        FX = np.degrees(np.arctan(T * np.cos(phi)))
        FY = np.degrees(np.arctan(T * np.sin(phi)))
    else:  # object points opposite: their (inverted) images lie at azimuth φ
        FX = -r[None, :] * np.cos(phi)
        FY = -r[None, :] * np.sin(phi)
    g = grid_from_fields(
        lens,
        FX,
        FY,
        kind,
        par,
        plane=plane,
        s_prime=s_prime,
        from_last_vertex=from_last_vertex,
        defocus=defocus,
        reference_point=reference_point,
        clip=clip,
    )
    # the unit vectors of the azimuths themselves (exact on the axis row too)
    cphi, sphi = np.cos(phi), np.sin(phi)
    D = g.D
    rad = D[..., 0] * cphi[None] + D[..., 1] * sphi[None]
    tan = -D[..., 0] * sphi[None] + D[..., 1] * cphi[None]
    from raytrace.paraxial import orthoscopy_abscissa

    x = np.abs(orthoscopy_abscissa(par, r, kind))
    return RadialByAzimuth(
        azimuths_deg=az,
        fields=r,
        x=x,
        radial=rad,
        tangential=tan,
        ideal_radius=np.abs(g.constant)[:, None] * x[None, :],
        grid=g,
    )
