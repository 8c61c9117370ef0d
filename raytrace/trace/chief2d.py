"""Real chief rays on a 2-D field grid, aimed at the centre of the real stop (docs/design.md,
"2-D distortion").

The chief ray of a field is the real ray through the centre of the real stop (Pestrecov 1958,
Fig. 1), found by a two-unknown Newton iteration in :func:`raytrace.kernels.aim2d.aim_chief_2d`:
the point where the ray meets the stop surface is (0, 0) to an absolute tolerance
``1e-12 × max(1 mm, R_stop)`` (the same rule as the meridional :func:`~raytrace.trace.chief_rays`;
``R_stop`` is the stop's semi-diameter when finite, else the paraxial marginal-ray height at the
stop), then polished by one more Newton step.

Field convention (the component-angle convention of optiland 0.6's ``AngleField``, which composes
the direction from ``tan(field_x)`` and ``tan(field_y)``):

- **angles** (αx, αy) in degrees are the object-space chief ray's *direction tangents*:
  ``tan αx = L/N``, ``tan αy = M/N`` with (L, M, N) its direction cosines (light toward +z). A
  meridional field α is (0, α); a positive αy gives a positive image y for an object at infinity,
  as the meridional convention (docs/design.md, "Conventions"). The total field angle θ and the
  azimuth φ of a field are ``tan θ = √(tan²αx + tan²αy)``, ``φ = atan2(tan αy, tan αx)``;
- with a finite object, angles are Pestrecov's **nominal** angles generalised: the object point
  is ``(x, y) = p0·(tan αx, tan αy)`` with ``p0 = z_object − z_E0`` (< 0), as in 1-D;
- **object heights** (x, y) in mm give the object point directly (finite objects only).

For an object at infinity the ray's direction is fixed and its start point on the plane z = 0
(the first vertex plane) is solved for; for a finite object the start point is the object point
and its direction is solved for.

Units: mm, degrees at the interface, first vertex at z = 0, light toward +z.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..errors import TraceError
from ..lens import Lens
from ..packing import PackedLens, pack
from ..paraxial.conjugates import checked_wavelength, resolve_object_distance
from ..paraxial.orthoscopy import nominal_heights
from .chief import (
    aim_outputs,
    aim_pupil_and_stop,
    aim_start,
    aim_tolerance,
    checked_aim_request,
    field_values,
    transfer,
)
from .results import RayStatus, field_unit, object_words, status_name


@dataclass(frozen=True, eq=False)
class _Setup2D:
    packed: PackedLens
    z_E0: float  # paraxial entrance pupil (absolute z, mm)
    r_stop: float  # stop radius used for the tolerance (mm)
    tol: float  # absolute aim tolerance (mm)


@functools.lru_cache(maxsize=128)
def _setup(lens: Lens, wavelength: float, object_distance: float) -> _Setup2D:
    p = pack(lens, wavelength=wavelength)
    z_E0, r = aim_pupil_and_stop(lens, p, object_distance, wavelength)
    return _Setup2D(p, float(z_E0), float(r), float(aim_tolerance(float(r))))


@dataclass(frozen=True, eq=False)
class ChiefRays2D(RayStatus):
    """Real chief rays of a 2-D set of fields. Every array has the broadcast ``shape`` of the
    fields given (e.g. (ny, nx) for a meshgrid).

    Attributes
    ----------
    field_x, field_y : ndarray
        The fields as given: degrees (``field_kind="angle"``) or object coordinates in mm
        (``"height"``).
    field_kind : str
        ``"angle"`` or ``"height"``; angles with a finite object are nominal angles.
    object_distance : float
        mm from the object plane to the first vertex (positive; inf for infinity).
    wavelength : float
        nm.
    x_start, y_start, z_start, L_start, M_start, N_start : ndarray
        Object-space ray: a point (mm; for an object at infinity on the plane z = 0, else the
        object point) and its direction cosines.
    x_last, y_last, z_last, L_last, M_last, N_last : ndarray
        Final segment: the point on the last surface (mm) and the direction after it.
    status : ndarray of int8
        Status code per field (``raytrace.kernels.codes``; words in :attr:`status_names`).
    surface : ndarray of int32
        1-based surface where the ray failed (0 when OK).
    iterations : ndarray of int32
        Residual evaluations (traces to the stop) the aim used.
    stop_residual_x, stop_residual_y : ndarray
        Where the aimed ray meets the stop surface (mm): the aiming error.
    z_E0 : float
        Paraxial entrance pupil (absolute z, mm) used for nominal angles and first guesses.
    stop_radius, tolerance : float
        Stop radius (mm) and the absolute aim tolerance (mm).
    """

    field_x: np.ndarray
    field_y: np.ndarray
    field_kind: str
    object_distance: float
    wavelength: float
    x_start: np.ndarray
    y_start: np.ndarray
    z_start: np.ndarray
    L_start: np.ndarray
    M_start: np.ndarray
    N_start: np.ndarray
    x_last: np.ndarray
    y_last: np.ndarray
    z_last: np.ndarray
    L_last: np.ndarray
    M_last: np.ndarray
    N_last: np.ndarray
    status: np.ndarray
    surface: np.ndarray
    iterations: np.ndarray
    stop_residual_x: np.ndarray
    stop_residual_y: np.ndarray
    z_E0: float
    stop_radius: float
    tolerance: float

    @property
    def shape(self) -> tuple[int, ...]:
        return self.status.shape

    @property
    def status_names(self) -> np.ndarray:
        """Status per field as words (``"ok"``, ``"aim_failed"``, ...), same shape."""
        names = [status_name(s) for s in self.status.ravel()]
        return np.array(names, dtype=object).reshape(self.shape)

    @property
    def tan_start(self) -> tuple[np.ndarray, np.ndarray]:
        """Direction tangents (L/N, M/N) of the object-space chief ray."""
        return self.L_start / self.N_start, self.M_start / self.N_start

    def positions_at(self, z_planes: float | npt.ArrayLike) -> np.ndarray:
        """Chief-ray points (x, y) in mm on the plane(s) z = ``z_planes`` (absolute z, mm), by
        analytic transfer of the final segment: shape (*shape, 2) for a scalar plane,
        (n_planes, *shape, 2) for an array. NaN only where status != OK."""
        zp = np.asarray(z_planes, dtype=np.float64)
        tx = self.L_last / self.N_last
        ty = self.M_last / self.N_last
        if zp.ndim == 0:
            z, z0 = float(zp), self.z_last
            return np.stack(
                [transfer(self.x_last, z0, tx, z), transfer(self.y_last, z0, ty, z)], -1
            )
        z = zp.reshape((-1,) + (1,) * len(self.shape))
        z0 = self.z_last[None]
        x = transfer(self.x_last[None], z0, tx[None], z)
        return np.stack([x, transfer(self.y_last[None], z0, ty[None], z)], -1)

    def __len__(self) -> int:
        return int(self.status.size)

    def __repr__(self) -> str:
        unit, obj = field_unit(self.field_kind), object_words(self.object_distance)
        return (
            f"ChiefRays2D({len(self)} fields {self.shape} ({unit}), object {obj}, "
            f"{self.wavelength:g} nm, {self.n_failed} failed)"
        )


def chief_rays_2d(
    lens: Lens,
    fields_x_deg: npt.ArrayLike | None = None,
    fields_y_deg: npt.ArrayLike | None = None,
    *,
    object_x_mm: npt.ArrayLike | None = None,
    object_y_mm: npt.ArrayLike | None = None,
    object_distance: float | str | None = None,
    object_s: float | None = None,
    object_scale: float | None = None,
    wavelength: float | str | None = None,
    clip: bool = True,
) -> ChiefRays2D:
    """Aim real chief rays through the centre of the real stop for 2-D fields (one kernel call).

    Parameters
    ----------
    lens : Lens
    fields_x_deg, fields_y_deg : array_like, optional
        Field angles αx, αy in degrees (module docstring: ``tan αx = L/N``, ``tan αy = M/N`` of
        the object-space chief ray; nominal angles with a finite object). Broadcast together
        (a missing one is 0): give ``np.meshgrid`` arrays for a grid.
    object_x_mm, object_y_mm : array_like, optional
        Object coordinates in mm instead of angles (finite objects only).
    object_distance, object_s, object_scale
        The object plane (at most one): mm from the first vertex (or ``inf`` / ``"12x"``),
        Pestrecov's signed s from H (mm), or an image scale N. Default: the lens's.
    wavelength : float or str, optional
        nm (``"0.5876um"`` with a unit); default the lens's reference wavelength.
    clip : bool
        Apply semi-diameters to the aimed ray (status CLIPPED); the aiming itself is unclipped.

    Returns
    -------
    ChiefRays2D
        Named arrays in the broadcast shape of the fields; a failed ray has a status and NaN.
    """
    wl = lens.wavelength if wavelength is None else checked_wavelength(wavelength)
    od = resolve_object_distance(
        lens,
        object_distance=object_distance,
        object_s=object_s,
        object_scale=object_scale,
        wavelength=wl,
    )
    given = requested_fields_2d(fields_x_deg, fields_y_deg, object_x_mm, object_y_mm)
    if given is None:
        raise TraceError("give fields_x_deg / fields_y_deg (degrees) or object_x_mm / object_y_mm")
    kind, fx, fy = given
    names = ("fields_x_deg", "fields_y_deg") if kind == "angle" else ("object_x_mm", "object_y_mm")
    for name, a in zip(names, (fx, fy), strict=True):
        if a.size == 0:  # as characteristic_distortion and distortion_grid
            raise TraceError(f"no fields given: {name} is empty")
    try:
        fx, fy = np.broadcast_arrays(fx, fy)
    except ValueError:
        raise TraceError(
            f"the x and y fields have shapes {fx.shape} and {fy.shape} that do not broadcast"
        ) from None
    return aim_2d(lens, fx, fy, kind, od, wl, clip)


def requested_fields_2d(
    fields_x_deg: npt.ArrayLike | None,
    fields_y_deg: npt.ArrayLike | None,
    object_x_mm: npt.ArrayLike | None,
    object_y_mm: npt.ArrayLike | None,
) -> tuple[str, np.ndarray, np.ndarray] | None:
    """The 2-D fields a caller gave, as ``(kind, x, y)``: angles or object coordinates.

    Parameters
    ----------
    fields_x_deg, fields_y_deg : array_like or None
        Field angles αx, αy in degrees (module docstring): kind ``"angle"``.
    object_x_mm, object_y_mm : array_like or None
        Object coordinates in mm: kind ``"height"``. Give angles or coordinates, not both.

    Returns
    -------
    (kind, x, y) or None
        ``kind`` ``"angle"`` or ``"height"``; ``x``, ``y`` float arrays as given (degrees or
        mm; a missing one of the pair is 0.0, not yet broadcast). None when nothing is given.

    Raises
    ------
    TraceError
        Both angles and object coordinates given.
    """
    angles = fields_x_deg is not None or fields_y_deg is not None
    heights = object_x_mm is not None or object_y_mm is not None
    if angles and heights:
        raise TraceError("give field angles (fields_x_deg, fields_y_deg) or object coordinates "
                         "(object_x_mm, object_y_mm), not both")  # fmt: skip
    if not (angles or heights):
        return None
    a, b = (fields_x_deg, fields_y_deg) if angles else (object_x_mm, object_y_mm)
    nx, ny = ("fields_x_deg", "fields_y_deg") if angles else ("object_x_mm", "object_y_mm")
    x = field_values(0.0 if a is None else a, nx)
    y = field_values(0.0 if b is None else b, ny)
    return ("angle" if angles else "height"), x, y


def aim_2d(
    lens: Lens,
    fields_x: np.ndarray,
    fields_y: np.ndarray,
    field_kind: str,
    object_distance: float,
    wavelength: float | None = None,
    clip: bool = True,
) -> ChiefRays2D:
    """:func:`chief_rays_2d` for fields already resolved: ``fields_x``, ``fields_y`` (same shape;
    degrees or mm) of ``field_kind`` ``"angle"`` | ``"height"``, ``object_distance`` mm from the
    first vertex (inf), ``wavelength`` nm."""
    from ..kernels.aim2d import aim_chief_2d

    fx = np.asarray(fields_x, dtype=np.float64)
    fy = np.asarray(fields_y, dtype=np.float64)
    if fx.shape != fy.shape:
        raise TraceError(f"fields_x and fields_y differ in shape: {fx.shape} vs {fy.shape}")
    od = checked_aim_request(field_kind, object_distance, fx, fy, heights="object coordinates")
    finite = math.isfinite(od)
    wl = float(lens.wavelength if wavelength is None else wavelength)
    su = _setup(lens, wl, od)
    z_obj = -od if finite else 0.0
    shape = fx.shape
    f1 = np.ascontiguousarray(fx.ravel())
    f2 = np.ascontiguousarray(fy.ravel())
    if field_kind == "angle" and finite:  # nominal angles → object point p0·(tan αx, tan αy)
        f1, f2 = nominal_heights(z_obj - su.z_E0, f1), nominal_heights(z_obj - su.z_E0, f2)
    elif field_kind == "angle":
        f1, f2 = np.tan(np.radians(f1)), np.tan(np.radians(f2))
    slope0, hscale = aim_start(np.array([su.z_E0]), od, np.array([su.r_stop]))
    outs = start, last, status, surface, evals, residual = aim_outputs(1, f1.size, 2)
    aim_chief_2d(
        su.packed.lens_arrays,
        su.packed.stop,
        1 if finite else 0,
        z_obj,
        np.ascontiguousarray(f1, dtype=np.float64),
        np.ascontiguousarray(f2, dtype=np.float64),
        slope0,
        np.array([su.tol]),
        hscale,
        bool(clip),
        *outs,
    )

    def r(a):
        return a.reshape(shape)

    s, e = start[0], last[0]
    return ChiefRays2D(
        field_x=fx.copy(),
        field_y=fy.copy(),
        field_kind=field_kind,
        object_distance=od,
        wavelength=wl,
        x_start=r(s[0]),
        y_start=r(s[1]),
        z_start=r(s[2]),
        L_start=r(s[3]),
        M_start=r(s[4]),
        N_start=r(s[5]),
        x_last=r(e[0]),
        y_last=r(e[1]),
        z_last=r(e[2]),
        L_last=r(e[3]),
        M_last=r(e[4]),
        N_last=r(e[5]),
        status=r(status[0]),
        surface=r(surface[0]),
        iterations=r(evals[0]),
        stop_residual_x=r(residual[0, 0]),
        stop_residual_y=r(residual[0, 1]),
        z_E0=su.z_E0,
        stop_radius=su.r_stop,
        tolerance=su.tol,
    )
