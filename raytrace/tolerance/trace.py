"""Chief rays and ray bundles of many perturbed instances, one kernel launch per chunk
(:mod:`raytrace.kernels.instances`).

:func:`nominal_aim` prepares, once per run, what the chord iteration of every instance starts
from: the nominal lens's chief rays (:func:`raytrace.trace.chief2d.aim_2d`) and the inverse of
its stop-point Jacobian per field (central differences through the instance kernel's own trace
of the unperturbed instance). :func:`aim_instances` then aims all instances × fields.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import TraceError
from ..lens import Lens
from ..trace.chief import transfer
from ..trace.chief2d import aim_2d
from ..trace.rays import PARALLEL_LOCK
from ..trace.results import RayStatus
from .model import InstanceArrays, pack_instances
from .spec import ToleranceSpec

#: the central-difference step of the nominal Jacobian, relative to max(|u|, hscale)
JACOBIAN_STEP = 1e-6


@dataclass(frozen=True, eq=False)
class NominalAim:
    """The nominal lens's chief rays for a set of 2-D fields, as the instance kernel reads them.

    fields_x, fields_y : (F,) the fields as given (degrees of the direction tangents' angles, or
        object coordinates in mm); f1, f2: the kernel's field values (direction tangents, or the
        object point in mm); finite, z_obj: the object (z_obj = 0 for infinity: the start plane);
    unom (F, 2), jinv (F, 4): unknowns and inverse stop Jacobian per field; tol, hscale: the aim
        tolerance (mm) and the scale of u; object_distance: mm (inf); wavelength: nm.
    """

    fields_x: np.ndarray
    fields_y: np.ndarray
    field_kind: str
    f1: np.ndarray
    f2: np.ndarray
    finite: int
    z_obj: float
    unom: np.ndarray
    jinv: np.ndarray
    tol: float
    hscale: float
    object_distance: float
    wavelength: float
    z_E0: float


def nominal_aim(
    lens: Lens,
    spec: ToleranceSpec,
    fields_x,
    fields_y,
    *,
    field_kind: str = "angle",
    object_distance: float | None = None,
    wavelength: float | None = None,
) -> NominalAim:
    """The :class:`NominalAim` of ``lens`` for fields (αx, αy) in degrees (``field_kind
    "angle"``; nominal angles with a finite object) or object coordinates in mm (``"height"``).
    Raises :class:`TraceError` when a nominal chief ray fails."""
    od = float(lens.object_distance if object_distance is None else object_distance)
    wl = float(lens.wavelength if wavelength is None else wavelength)
    fx = np.ascontiguousarray(np.asarray(fields_x, dtype=float).ravel())
    fy = np.ascontiguousarray(np.asarray(fields_y, dtype=float).ravel())
    cr = aim_2d(lens, fx, fy, field_kind, od, wl, clip=False)
    if not np.all(cr.ok):
        bad = np.nonzero(~cr.ok)[0]
        raise TraceError(
            f"{lens.name}: the nominal chief ray of field ({fx[bad[0]]:g}, {fy[bad[0]]:g}) "
            f"fails ({cr.status_names[bad[0]]}); choose fields inside the lens's field"
        )
    finite = math.isfinite(od)
    if finite:
        f1, f2 = cr.x_start.copy(), cr.y_start.copy()
        u = np.stack([cr.L_start / cr.N_start, cr.M_start / cr.N_start], axis=1)
        z_obj, hscale = -od, 1.0
    else:
        f1 = cr.L_start / cr.N_start
        f2 = cr.M_start / cr.N_start
        u = np.stack([cr.x_start, cr.y_start], axis=1)
        z_obj, hscale = 0.0, max(1.0, cr.stop_radius)
    f1 = np.ascontiguousarray(f1)
    f2 = np.ascontiguousarray(f2)
    u = np.ascontiguousarray(u)
    arr = pack_instances(lens, spec, np.zeros((1, spec.n_items)), wl)
    jinv = _inverse_jacobians(arr, 1 if finite else 0, z_obj, f1, f2, u, hscale)
    return NominalAim(fx, fy, field_kind, f1, f2, 1 if finite else 0, z_obj, u, jinv,
                      float(cr.tolerance), float(hscale), od, wl, float(cr.z_E0))  # fmt: skip


def _inverse_jacobians(arr, finite, z_obj, f1, f2, u, hscale) -> np.ndarray:
    from ..kernels.instances import stop_points

    nf = f1.size
    J = np.empty((nf, 2, 2))
    out_p = np.empty((nf, 2))
    out_m = np.empty((nf, 2))
    for q in range(2):
        h = JACOBIAN_STEP * np.maximum(np.abs(u[:, q]), hscale)
        du = np.zeros_like(u)
        du[:, q] = h
        stop_points(arr.lens_tuple, 0, arr.stop, finite, z_obj, f1, f2,
                    np.ascontiguousarray(u + du), out_p)  # fmt: skip
        stop_points(arr.lens_tuple, 0, arr.stop, finite, z_obj, f1, f2,
                    np.ascontiguousarray(u - du), out_m)  # fmt: skip
        J[:, :, q] = (out_p - out_m) / (2.0 * h[:, None])
    det = J[:, 0, 0] * J[:, 1, 1] - J[:, 0, 1] * J[:, 1, 0]
    if not np.all(np.isfinite(det)) or np.any(det == 0.0):
        raise TraceError("the nominal chief-ray Jacobian is singular at some field")
    inv = np.empty((nf, 4))
    inv[:, 0] = J[:, 1, 1] / det
    inv[:, 1] = -J[:, 0, 1] / det
    inv[:, 2] = -J[:, 1, 0] / det
    inv[:, 3] = J[:, 0, 0] / det
    return np.ascontiguousarray(inv)


@dataclass(frozen=True, eq=False)
class InstanceChiefRays(RayStatus):
    """Chief rays of I instances × F fields: ``last`` (I, 6, F) final segments (x, y, z, L, M,
    N) in the image frame (mm; NaN where failed), ``status`` (I, F) int8, ``evals`` (I, F)
    traces to the stop, ``stop_residual`` (I, 2, F) mm."""

    last: np.ndarray
    status: np.ndarray
    evals: np.ndarray
    stop_residual: np.ndarray

    def points_at(self, z_planes) -> np.ndarray:
        """(I, F, 2) points (x', y') in mm on the planes z = ``z_planes`` ((I,) or a scalar;
        absolute z in the image frame) by analytic transfer of the final segments."""
        zp = np.broadcast_to(np.asarray(z_planes, dtype=float), (self.last.shape[0],))
        s = self.last
        x = transfer(s[:, 0, :], s[:, 2, :], s[:, 3, :] / s[:, 5, :], zp[:, None])
        y = transfer(s[:, 1, :], s[:, 2, :], s[:, 4, :] / s[:, 5, :], zp[:, None])
        return np.stack([x, y], axis=-1)


def aim_instances(
    arrays: InstanceArrays, nominal: NominalAim, *, clip: bool = False, parallel: bool = True
) -> InstanceChiefRays:
    """Aim the chief rays of every instance in ``arrays`` at the fields of ``nominal`` (one
    kernel launch; module docstring). ``parallel`` uses numba's threads over instances (under
    :data:`raytrace.trace.rays.PARALLEL_LOCK`); ``False`` runs on the calling thread (Dask
    workers). Both give bit-identical results."""
    from ..kernels.instances import aim_instances as kpar
    from ..kernels.instances import aim_instances_serial as kser

    I = arrays.n_instances
    F = nominal.f1.size
    last = np.empty((I, 6, F))
    status = np.empty((I, F), dtype=np.int8)
    evals = np.empty((I, F), dtype=np.int32)
    resid = np.empty((I, 2, F))
    args = (arrays.lens_tuple, arrays.stop, nominal.finite, nominal.z_obj, nominal.f1,
            nominal.f2, nominal.unom, nominal.jinv, nominal.tol, nominal.hscale, bool(clip), last,
            status, evals, resid)  # fmt: skip
    if parallel:
        with PARALLEL_LOCK:
            kpar(*args)
    else:
        kser(*args)
    return InstanceChiefRays(last, status, evals, resid)


def trace_instances(
    arrays: InstanceArrays, start: np.ndarray, *, clip: bool = False, parallel: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """The rays ``start`` (6, R: x, y, z, L, M, N before the first surface) through every
    instance: (last (I, 6, R) final segments in the image frame, status (I, R))."""
    from ..kernels.instances import trace_instances as kpar
    from ..kernels.instances import trace_instances_serial as kser

    start = np.ascontiguousarray(start, dtype=float)
    I = arrays.n_instances
    R = start.shape[1]
    last = np.empty((I, 6, R))
    status = np.empty((I, R), dtype=np.int8)
    if parallel:
        with PARALLEL_LOCK:
            kpar(arrays.lens_tuple, start, bool(clip), last, status)
    else:
        kser(arrays.lens_tuple, start, bool(clip), last, status)
    return last, status
