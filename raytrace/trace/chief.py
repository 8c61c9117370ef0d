"""Real chief rays, aimed at the centre of the real stop (docs/design.md, "Conventions").

Chief rays (Pestrecov 1958, Fig. 1: the principal ray through the centre of the real stop) are
found by iteration in :func:`raytrace.kernels.aim.aim_chief`: the meridional real ray whose
height at the stop surface is zero to an absolute tolerance ``1e-12 × max(1 mm, R_stop)``, where
``R_stop`` is the stop's semi-diameter when finite, otherwise the paraxial marginal-ray height at
the stop for the lens's aperture.

Field parameters:

- object at infinity, angle α: ray height at z = 0 with fixed direction (0, sin α, cos α);
- finite object, height y: ray from (0, y, −object_distance), unknown slope;
- finite object, angle α: the nominal angle of Pestrecov's §3, y = p0·tan α with
  p0 = z_object − z_E0 (< 0 for a real object left of the paraxial entrance pupil E0), then aimed
  as a height field.

Units: millimetres, field angles in degrees, first vertex at z = 0, light toward +z.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..errors import LensError, TraceError
from ..kernels.codes import STATUS_NAMES, STATUS_OK
from ..lens import Lens
from ..packing import PackedLens, pack
from ..paraxial.conjugates import resolve_object_distance
from ..paraxial.firstorder import aim_geometry


@dataclass(frozen=True, eq=False)
class _AimSetup:
    packed: PackedLens
    z_E0: float  # paraxial entrance pupil (absolute z)
    r_stop: float  # stop radius used for the tolerance
    tol: float


@functools.lru_cache(maxsize=256)
def _aim_setup(lens: Lens, wavelength: float | None, object_distance: float) -> _AimSetup:
    p = pack(lens, wavelength)
    try:
        z_E0, r_par = aim_geometry(lens, object_distance, wavelength)
    except LensError as e:
        raise TraceError(str(e)) from None
    r_stop = float(p.sd[p.stop]) if math.isfinite(p.sd[p.stop]) else r_par
    return _AimSetup(p, float(z_E0), r_stop, 1e-12 * max(1.0, r_stop))


@dataclass(frozen=True, eq=False)
class ChiefRays:
    """Real chief rays (meridional plane x = 0), arrays over fields in the order given.

    Attributes
    ----------
    fields : ndarray
        The field values as given: degrees (``field_kind="angle"``) or object heights in mm
        (``"height"``).
    field_kind : str
        ``"angle"`` or ``"height"``; angles with a finite object are nominal angles.
    object_distance : float
        mm from the object plane to the first vertex (positive; inf for infinity).
    wavelength : float
        nm.
    y_start, z_start, M_start, N_start : ndarray
        Object-space ray: a point (mm) and direction cosines; for an object at infinity the point
        is on the plane z = 0, else the object point.
    y_last, z_last, M_last, N_last : ndarray
        Final segment: point on the last surface (mm) and direction after it.
    status : ndarray of int8
        Status code per field (``raytrace.kernels.codes``; names in :attr:`status_names`).
    surface : ndarray of int32
        1-based surface where the ray failed (0 when OK).
    iterations : ndarray of int32
        Residual evaluations (traces to the stop) the aim used.
    stop_residual : ndarray
        Height of the ray at the stop surface (mm): the aiming error.
    entrance_pupil_z : ndarray
        Real entrance pupil: where the object-space chief ray crosses the axis (absolute z, mm);
        the paraxial z_E0 for the zero field; inf when parallel to the axis.
    stop_radius, tolerance : float
        The stop radius (mm) and the absolute aim tolerance (mm) used.
    """

    fields: np.ndarray
    field_kind: str
    object_distance: float
    wavelength: float
    y_start: np.ndarray
    z_start: np.ndarray
    M_start: np.ndarray
    N_start: np.ndarray
    y_last: np.ndarray
    z_last: np.ndarray
    M_last: np.ndarray
    N_last: np.ndarray
    status: np.ndarray
    surface: np.ndarray
    iterations: np.ndarray
    stop_residual: np.ndarray
    entrance_pupil_z: np.ndarray
    stop_radius: float
    tolerance: float

    @property
    def ok(self) -> np.ndarray:
        """Boolean mask of fields whose chief ray reached the last surface."""
        return self.status == STATUS_OK

    @property
    def status_names(self) -> list[str]:
        """Status per field as words (``"ok"``, ``"aim_failed"``, ...)."""
        return [STATUS_NAMES.get(int(s), str(int(s))) for s in self.status]

    @property
    def tan_out(self) -> np.ndarray:
        """Image-space slope tan α' = M_last / N_last."""
        return self.M_last / self.N_last

    @property
    def landing_angle_deg(self) -> np.ndarray:
        """Image-space chief-ray angle with the axis (degrees, signed like M_last)."""
        return np.degrees(np.arctan2(self.M_last, self.N_last))

    def heights_at(self, z_planes: float | npt.ArrayLike) -> np.ndarray:
        """Chief-ray heights (mm) on plane(s) z = z_planes (absolute z, mm) by analytic transfer of
        the final segment: shape (n_fields,) for a scalar, (n_planes, n_fields) for an array.
        NaN only where status != OK."""
        zp = np.asarray(z_planes, dtype=np.float64)
        t = self.M_last / self.N_last
        if zp.ndim == 0:
            return self.y_last + (float(zp) - self.z_last) * t
        return self.y_last[None, :] + (zp.reshape(-1)[:, None] - self.z_last[None, :]) * t

    def __len__(self) -> int:
        return int(self.fields.size)

    def __repr__(self) -> str:
        unit = "deg" if self.field_kind == "angle" else "mm"
        obj = "inf" if math.isinf(self.object_distance) else f"{self.object_distance:g} mm"
        bad = int(np.count_nonzero(self.status != STATUS_OK))
        fl = ", ".join(f"{v:g}" for v in self.fields[:6]) + (", ..." if len(self) > 6 else "")
        return (
            f"ChiefRays({len(self)} fields [{fl}] {unit}, object {obj}, "
            f"{self.wavelength:g} nm, {bad} failed)"
        )


def chief_rays(
    lens: Lens,
    fields_deg: npt.ArrayLike | None = None,
    *,
    object_heights_mm: npt.ArrayLike | None = None,
    object_distance: float | str | None = None,
    object_s: float | None = None,
    object_scale: float | None = None,
    wavelength: float | None = None,
    clip: bool = True,
) -> ChiefRays:
    """Aim real chief rays through the centre of the real stop (one kernel call for all fields).

    Parameters
    ----------
    lens : Lens
    fields_deg : array_like, optional
        Field angles α in degrees: the object-space chief-ray slope angle (a positive α gives a
        positive image height for an object at infinity). With a finite object these are
        Pestrecov's nominal angles, object height ``y = p0 tan α``.
    object_heights_mm : array_like, optional
        Object heights in mm (signed; finite objects). Give this or ``fields_deg``; neither →
        the lens file's field as 0 and its maximum.
    object_distance, object_s, object_scale
        The object plane (at most one): mm from the first vertex (or ``inf`` / ``"12x"``),
        Pestrecov's signed s from H (mm), or an image scale N ("N×"). Default: the lens's.
    wavelength : float, optional
        nm; default the lens's.
    clip : bool
        Apply semi-diameters to the aimed ray (status CLIPPED); aiming itself is unclipped.

    Returns
    -------
    ChiefRays
        Named arrays per field, with a status per field; a failed field has NaN coordinates.
    """
    od = resolve_object_distance(
        lens,
        object_distance=object_distance,
        object_s=object_s,
        object_scale=object_scale,
        wavelength=wavelength,
    )
    if fields_deg is not None and object_heights_mm is not None:
        raise TraceError("give fields_deg or object_heights_mm, not both")
    if fields_deg is None and object_heights_mm is None:
        fk = lens.field.kind
        f = np.array([0.0, lens.field.value])
    else:
        fk = "angle" if fields_deg is not None else "height"
        f = np.atleast_1d(np.asarray(fields_deg if fk == "angle" else object_heights_mm, float))
    return aim(lens, f, fk, od, wavelength, clip)


def aim(
    lens: Lens,
    fields: np.ndarray,
    field_kind: str,
    object_distance: float,
    wavelength: float | None = None,
    clip: bool = True,
) -> ChiefRays:
    """:func:`chief_rays` for fields already resolved: ``fields`` (deg or mm) of ``field_kind``
    ``"angle"`` | ``"height"``, ``object_distance`` mm from the first vertex (inf)."""
    from ..kernels.aim import aim_chief

    fk = field_kind
    if fk not in ("angle", "height"):
        raise TraceError(f"field kind must be 'angle' or 'height', got {fk!r}")
    od = float(object_distance)
    if not (od > 0.0):
        raise TraceError(f"object distance must be a positive magnitude or inf, got {od}")
    finite = math.isfinite(od)
    f = np.atleast_1d(np.asarray(fields, dtype=np.float64))
    if f.ndim != 1:
        raise TraceError("fields must be a scalar or a 1-D array")
    if not np.all(np.isfinite(f)):
        raise TraceError("fields must be finite numbers")
    if fk == "height" and not finite:
        raise TraceError("object heights need a finite object distance")
    if fk == "angle" and np.any(np.abs(f) >= 90.0):
        raise TraceError("field angles must lie strictly between -90 and 90 degrees")
    wl = None if wavelength is None else float(wavelength)
    su = _aim_setup(lens, wl, od)
    z_obj = -od if finite else 0.0
    if finite:
        kf = (z_obj - su.z_E0) * np.tan(np.radians(f)) if fk == "angle" else f
        den = su.z_E0 - z_obj
        slope0 = -1.0 / den if den != 0.0 else 0.0
        hscale = 1.0
    else:
        kf = np.radians(f)
        slope0 = -su.z_E0
        hscale = max(1.0, su.r_stop)
    n = f.size
    start = np.empty((4, n))
    last = np.empty((4, n))
    status = np.empty(n, dtype=np.int8)
    surface = np.empty(n, dtype=np.int32)
    evals = np.empty(n, dtype=np.int32)
    residual = np.empty(n)
    aim_chief(
        *su.packed.arrays,
        su.packed.stop,
        1 if finite else 0,
        z_obj,
        np.ascontiguousarray(kf, dtype=np.float64),
        float(slope0),
        su.tol,
        float(hscale),
        bool(clip),
        start,
        last,
        status,
        surface,
        evals,
        residual,
    )
    y0, z0, M0, N0 = start
    with np.errstate(divide="ignore", invalid="ignore"):
        zE = np.where(M0 != 0.0, z0 - y0 * N0 / M0, np.inf)
    zE = np.where(kf == 0.0, su.z_E0, zE)
    return ChiefRays(
        fields=f,
        field_kind=fk,
        object_distance=od,
        wavelength=su.packed.wavelength,
        y_start=y0,
        z_start=z0,
        M_start=M0,
        N_start=N0,
        y_last=last[0],
        z_last=last[1],
        M_last=last[2],
        N_last=last[3],
        status=status,
        surface=surface,
        iterations=evals,
        stop_residual=residual,
        entrance_pupil_z=zE,
        stop_radius=su.r_stop,
        tolerance=su.tol,
    )
