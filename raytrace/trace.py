"""Public real-ray trace API: bulk 3-D traces and chief-ray aiming (DESIGN.md §3, §5).

Units: millimetres, field angles in degrees; light travels toward +z with the first vertex at
z = 0. Every ray carries a status code (``STATUS_*``); a ray that failed has NaN coordinates and
the 1-based number of the surface where it failed.

Chief rays (Pestrecov 1958, Fig. 1: the principal ray through the centre of the real stop) are
found by iteration in :func:`raytrace.kernels.aim_chief`: the meridional real ray whose height at
the stop surface is zero to an absolute tolerance ``1e-12 × max(1 mm, R_stop)``, where ``R_stop``
is the stop's semi-diameter when finite, otherwise the paraxial marginal-ray height at the stop
for the lens's aperture.

Field parameters:
- object at infinity, angle α: ray height at z = 0 with fixed direction (0, sin α, cos α);
- finite object, height y: ray from (0, y, −object_distance), unknown slope;
- finite object, angle α: the nominal angle of Pestrecov's §3, y = p0·tan α with
  p0 = z_object − z_E0 (< 0 for a real object left of the paraxial entrance pupil E0), then aimed
  as a height field.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numba
import numpy as np

from . import kernels as _k
from .errors import TraceError
from .lens import Lens, PackedLens, pack

STATUS_OK = _k.STATUS_OK
STATUS_MISSED = _k.STATUS_MISSED
STATUS_TIR = _k.STATUS_TIR
STATUS_CLIPPED = _k.STATUS_CLIPPED
STATUS_AIM_FAILED = _k.STATUS_AIM_FAILED
STATUS_NAMES = {
    STATUS_OK: "ok",
    STATUS_MISSED: "missed",
    STATUS_TIR: "tir",
    STATUS_CLIPPED: "clipped",
    STATUS_AIM_FAILED: "aim_failed",
}

#: Batches of at least this many rays use the prange kernel (when more than one thread is
#: allowed). Measured on the 2-core development machine (benchmarks/bench_core.py crossover,
#: vectorised kernel: serial 1 µs per 20 rays): 2 threads win from ~4k rays when a second core is
#: free, but when it is busy (other processes) a parallel call waits one scheduler slice (~4 ms).
#: At 32768 rays the serial kernel takes ~1.6 ms, which bounds that penalty to ~2.5x and costs at
#: most ~0.8 ms on a quiet machine.
PARALLEL_THRESHOLD = 32768


# --------------------------------------------------------------------------------------------
# Bulk trace
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class RayBatch:
    """Result of :func:`trace_rays`: the final segment of each ray.

    x, y, z: point on the last surface (mm); L, M, N: direction cosines after it.
    status:  int8 status code per ray (``STATUS_*``); surface: int32 1-based surface where the ray
    failed (0 when OK). Failed rays have NaN coordinates.
    """

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    L: np.ndarray
    M: np.ndarray
    N: np.ndarray
    status: np.ndarray
    surface: np.ndarray

    @property
    def ok(self) -> np.ndarray:
        """Boolean mask of rays with status OK."""
        return self.status == STATUS_OK

    def at_plane(self, z_plane: float) -> tuple[np.ndarray, np.ndarray]:
        """(x, y) where each final segment meets the plane z = ``z_plane`` (mm), by analytic
        transfer; NaN for failed rays."""
        arrs = (self.x, self.y, self.z, self.L, self.M, self.N)
        if all(a.ndim == 1 and a.dtype == np.float64 and a.flags.c_contiguous for a in arrs) and (
            len({a.shape for a in arrs}) == 1
        ):
            return _k.transfer_to_plane(*arrs, float(z_plane))  # one pass, no temporaries
        t = (float(z_plane) - self.z) / self.N
        return self.x + t * self.L, self.y + t * self.M


def _f64(a: np.ndarray, n: int) -> np.ndarray:
    """Writeable contiguous float64 array of length n (one kernel specialisation only)."""
    if a.shape == (n,) and a.flags.c_contiguous and a.flags.writeable:
        return a
    return np.array(np.broadcast_to(a, (n,)), dtype=np.float64, order="C")


def _lens_arrays(p: PackedLens) -> tuple:
    return (p.kind, p.c, p.k, p.asph, p.zv, p.n_in, p.n_out, p.sd)


def trace_rays(
    packed: PackedLens,
    x: np.ndarray,
    y: np.ndarray,
    z: np.ndarray,
    L: np.ndarray,
    M: np.ndarray,
    N: np.ndarray,
    *,
    clip: bool = True,
    threads: int | None = None,
) -> RayBatch:
    """Trace a batch of rays (structure of arrays, broadcast to a common 1-D length) through
    ``packed``. Start points may lie anywhere before the first surface (a ray is a line; it is
    transferred to each vertex plane). Directions are normalised; rays must travel toward +z.

    clip:    apply semi-diameters (status CLIPPED outside them).
    threads: numba threads for this call (set temporarily); 1 forces the serial kernel. Batches
             of ``PARALLEL_THRESHOLD`` rays or more use the parallel kernel.
    """
    arrs = [np.asarray(a, dtype=np.float64) for a in (x, y, z, L, M, N)]
    try:
        shape = np.broadcast_shapes(*(a.shape for a in arrs))
    except ValueError as e:
        raise TraceError(f"ray arrays do not broadcast to a common shape: {e}") from None
    if len(shape) > 1:
        raise TraceError(f"ray arrays must be 1-D (got shape {shape})")
    n = int(shape[0]) if shape else 1
    xs = [_f64(a, n) for a in arrs]
    out = [np.empty(n) for _ in range(6)]
    st = np.empty(n, dtype=np.int8)
    sf = np.empty(n, dtype=np.int32)
    args = (*_lens_arrays(packed), bool(clip), *xs, *out, st, sf)
    nthreads_max = numba.config.NUMBA_NUM_THREADS
    if threads is not None and not (1 <= int(threads)):
        raise TraceError(f"threads must be >= 1, got {threads}")
    want = nthreads_max if threads is None else min(int(threads), nthreads_max)
    if n < PARALLEL_THRESHOLD or want == 1:
        _k.trace_batch_serial(*args)
    else:
        old = numba.get_num_threads()
        try:
            if threads is not None:
                numba.set_num_threads(want)
            _k.trace_batch_parallel(*args)
        finally:
            if threads is not None:
                numba.set_num_threads(old)
    return RayBatch(*out, st, sf)


@dataclass(frozen=True)
class RayPaths:
    """Intersection points of each ray with every surface: x, y, z of shape (n_rays, n_surfaces)
    (NaN after a failure), with status and failed surface per ray as in :class:`RayBatch`."""

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    status: np.ndarray
    surface: np.ndarray


def ray_paths(packed: PackedLens, x, y, z, L, M, N, *, clip: bool = False) -> RayPaths:
    """Trace a (small) batch and keep every surface intersection — for layout drawings."""
    arrs = [np.atleast_1d(np.asarray(a, dtype=np.float64)) for a in (x, y, z, L, M, N)]
    n = int(np.broadcast_shapes(*(a.shape for a in arrs))[0])
    xs = [_f64(a, n) for a in arrs]
    ns = packed.n_surfaces
    px, py, pz = (np.empty((n, ns)) for _ in range(3))
    st = np.empty(n, dtype=np.int8)
    sf = np.empty(n, dtype=np.int32)
    _k.trace_paths(*_lens_arrays(packed), bool(clip), *xs, px, py, pz, st, sf)
    return RayPaths(px, py, pz, st, sf)


# --------------------------------------------------------------------------------------------
# Small paraxial (y-nu) helper: entrance pupil and stop radius for aiming
# --------------------------------------------------------------------------------------------


def _ynu(p: PackedLens, y: float, u: float, upto: int) -> tuple[float, float]:
    """Paraxial y-nu trace of the ray (height y at z = 0 vertex plane, slope u in object space)
    through surfaces 0 .. upto-1; returns (height at vertex ``upto-1`` plane, slope after it)."""
    nu = p.n_in[0] * u
    yy = y
    for j in range(upto):
        if j > 0:
            yy += (p.zv[j] - p.zv[j - 1]) * nu / p.n_in[j]
        nu = nu - yy * p.c[j] * (p.n_out[j] - p.n_in[j])
    return yy, nu / p.n_out[upto - 1]


@dataclass(frozen=True)
class _AimSetup:
    packed: PackedLens
    arrays: tuple
    z_E0: float  # paraxial entrance pupil (absolute z)
    r_stop: float  # stop radius used for the tolerance
    tol: float
    z_obj: float  # -object_distance (or -inf)


@functools.lru_cache(maxsize=256)
def _packed(lens: Lens, wavelength: float | None) -> PackedLens:
    return pack(lens, wavelength)


@functools.lru_cache(maxsize=256)
def _aim_setup(lens: Lens, wavelength: float | None, object_distance: float) -> _AimSetup:
    p = _packed(lens, wavelength)
    s = p.stop
    yA, _ = _ynu(p, 1.0, 0.0, s + 1)  # y at stop per unit height at z=0 (parallel ray)
    yB, _ = _ynu(p, 0.0, 1.0, s + 1)  # y at stop per unit slope from the first vertex
    if yA == 0.0:
        raise TraceError(f"{lens.name}: the stop is at a paraxial image of the object space axis")
    z_E0 = yB / yA
    # paraxial EFL (1/power) for an f-number aperture
    _, u_out = _ynu(p, 1.0, 0.0, p.n_surfaces)
    efl = -1.0 / (p.n_out[-1] * u_out) if u_out != 0.0 else math.inf
    ap = lens.aperture
    finite = math.isfinite(object_distance)
    z_obj = -object_distance
    if ap.kind == "fnumber":
        epd = abs(efl) / ap.value if math.isfinite(efl) else 0.0
    elif ap.kind == "epd":
        epd = ap.value
    else:  # na: paraxial marginal slope NA/n at the object
        um = ap.value / p.n_in[0]
        epd = 2.0 * abs(um * (z_E0 - z_obj)) if finite else 0.0
    if finite:
        um = 0.5 * epd / (z_E0 - z_obj) if z_E0 != z_obj else 0.0
        y_stop = um * (object_distance * yA + yB)
    else:
        y_stop = 0.5 * epd * yA
    r_par = abs(y_stop) if math.isfinite(y_stop) else 0.0
    r_stop = float(p.sd[s]) if math.isfinite(p.sd[s]) else r_par
    tol = 1e-12 * max(1.0, r_stop)
    return _AimSetup(p, _lens_arrays(p), float(z_E0), r_stop, tol, z_obj)


# --------------------------------------------------------------------------------------------
# Chief rays
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ChiefRays:
    """Real chief rays (meridional plane x = 0), arrays over fields in the order given.

    fields:          the field values as given (degrees or mm); field_kind "angle" | "height".
    object_distance: positive magnitude from the object plane to the first vertex (inf).
    y_start, z_start, M_start, N_start: object-space ray (a point and direction cosines; for an
        object at infinity the point is on the plane z = 0, else the object point).
    y_last, z_last, M_last, N_last: final segment (point on the last surface, direction after it).
    status:          ``STATUS_*`` per field; surface: 1-based surface where it failed (0 ok).
    iterations:      residual evaluations (ray traces to the stop) the aim used.
    stop_residual:   height of the ray at the stop surface (mm) — the aiming error.
    entrance_pupil_z: real entrance pupil, where the object-space chief ray crosses the axis
        (absolute z, mm); the paraxial z_E0 for the zero field; inf when parallel to the axis.
    stop_radius, tolerance: the stop radius (mm) and absolute aim tolerance (mm) used.
    """

    fields: np.ndarray
    field_kind: str
    object_distance: float
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
        return self.status == STATUS_OK

    @property
    def tan_out(self) -> np.ndarray:
        """Image-space slope tan α' = M_last / N_last."""
        return self.M_last / self.N_last

    @property
    def landing_angle_deg(self) -> np.ndarray:
        """Image-space chief-ray angle with the axis (degrees, signed like M_last)."""
        return np.degrees(np.arctan2(self.M_last, self.N_last))

    def heights_at(self, z_planes: float | np.ndarray) -> np.ndarray:
        """Chief-ray heights (mm) on plane(s) z = z_planes (absolute z, mm) by analytic transfer of
        the final segment: shape (n_fields,) for a scalar, (n_planes, n_fields) for an array.
        NaN only where status != OK."""
        zp = np.asarray(z_planes, dtype=np.float64)
        t = self.M_last / self.N_last
        if zp.ndim == 0:
            return self.y_last + (float(zp) - self.z_last) * t
        return self.y_last[None, :] + (zp.reshape(-1)[:, None] - self.z_last[None, :]) * t


def chief_rays(
    lens: Lens,
    fields: float | np.ndarray,
    *,
    field_kind: str | None = None,
    object_distance: float | None = None,
    wavelength: float | None = None,
    clip: bool = True,
) -> ChiefRays:
    """Aim real chief rays for ``fields`` (one kernel call for all of them).

    fields:          angles α in degrees (object-space chief-ray slope angle; positive → positive
                     image height for an object at infinity) or object heights in mm (signed).
    field_kind:      "angle" | "height"; default the lens's field kind.
    object_distance: positive magnitude from the object plane to the first vertex; inf = infinity;
                     default the lens's.
    wavelength:      nm; default the lens's.
    clip:            apply semi-diameters to the aimed ray (status CLIPPED); aiming itself is
                     unclipped.
    """
    fk = lens.field.kind if field_kind is None else field_kind
    if fk not in ("angle", "height"):
        raise TraceError(f"field_kind must be 'angle' or 'height', got {fk!r}")
    od = lens.object_distance if object_distance is None else float(object_distance)
    if not (od > 0.0):
        raise TraceError(f"object distance must be a positive magnitude or inf, got {od}")
    finite = math.isfinite(od)
    f = np.atleast_1d(np.asarray(fields, dtype=np.float64))
    if f.ndim != 1:
        raise TraceError("fields must be a scalar or a 1-D array")
    if not np.all(np.isfinite(f)):
        raise TraceError("fields must be finite numbers")
    if fk == "height" and not finite:
        raise TraceError("object-height fields need a finite object distance")
    if fk == "angle" and np.any(np.abs(f) >= 90.0):
        raise TraceError("field angles must lie strictly between -90 and 90 degrees")
    su = _aim_setup(lens, wavelength, od)
    if finite:
        if fk == "angle":
            kf = (su.z_obj - su.z_E0) * np.tan(np.radians(f))
        else:
            kf = f
        den = su.z_E0 - su.z_obj
        slope0 = -1.0 / den if den != 0.0 else 0.0
        hscale = 1.0
    else:
        kf = np.radians(f)
        slope0 = -su.z_E0
        hscale = max(1.0, su.r_stop)
    out = _k.aim_chief(
        *su.arrays,
        su.packed.stop,
        1 if finite else 0,
        su.z_obj if finite else 0.0,
        np.ascontiguousarray(kf),
        float(slope0),
        su.tol,
        float(hscale),
        bool(clip),
    )
    y0, z0, M0, N0 = out[1], out[2], out[3], out[4]
    with np.errstate(divide="ignore", invalid="ignore"):
        zE = np.where(M0 != 0.0, z0 - y0 * N0 / M0, np.inf)
    zE = np.where(kf == 0.0, su.z_E0, zE)
    return ChiefRays(
        fields=f,
        field_kind=fk,
        object_distance=od,
        y_start=y0,
        z_start=z0,
        M_start=M0,
        N_start=N0,
        y_last=out[5],
        z_last=out[6],
        M_last=out[7],
        N_last=out[8],
        status=out[9].astype(np.int8),
        surface=out[10].astype(np.int32),
        iterations=out[11].astype(np.int32),
        stop_residual=out[12],
        entrance_pupil_z=zE,
        stop_radius=su.r_stop,
        tolerance=su.tol,
    )
