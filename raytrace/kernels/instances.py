"""Many perturbed lenses in one kernel launch (tolerancing, :mod:`raytrace.tolerance`): arrays
over instances × surfaces (× fields), never a Python loop over lens objects.

Each instance ``i`` has its own rows of the lens arrays of :class:`raytrace.packing.PackedLens`
(``kind[i], c[i], k[i], asph[i], geo[i], n_in[i], n_out[i], sd[i]``) plus ``irr[i]`` (Zs, Za,
normalisation radius per surface) for irregular surfaces (kind :data:`KIND_IRREGULAR`: the
surface's quadric / even asphere plus ``Zs ρ⁴ + Za ρ_y²``, ρ = r/rn, ρ_y = y/rn, intersected by
Newton's method along the ray from the quadric root, normal ``(−∂z/∂x, −∂z/∂y, 1)``). Every other
surface goes through the shared :func:`raytrace.kernels.surface.surface_step` (compiled without
Q-type surfaces, ``qtype=False``: tolerancing refuses Q-type lenses,
:func:`raytrace.tolerance.check_against_lens`); frames as
:mod:`raytrace.kernels.surface` describes (``F_FRAME`` moves the ray into the surface's axis
frame; the last row of every instance is the image-frame row, ``F_SKIP | F_FRAME``).

Chief rays (:func:`aim_instances`): the real ray through the centre of the stop of each
instance, to the tolerance ``tol`` of docs/design.md ("Conventions"), for every field. The
unknowns and the residual are those of :mod:`.aim2d` (start point on z = z_obj for a fixed
direction; direction tangents from a fixed object point; the residual is the point where the ray
meets the stop, in the stop's own frame). Perturbed instances are near the nominal lens, so the
solve is a **chord Newton iteration** with the nominal lens's inverse Jacobian of the field
(``jinv``, computed once per run): from the guess ``u = u_nom + δ`` (δ the correction the
previous field of the same instance needed), ``u ← u − J_nom⁻¹ r(u)``, one trace to the stop
per step, until ``max|r| <= tol``; then one more step, kept when it lowers ``|r|`` (the polish of
:mod:`.aim2d`). When the chord iteration does not converge in ``CHORD_MAXIT`` steps, a full
Newton iteration with a forward-difference Jacobian and a backtracking line search takes over
(as :mod:`.aim2d`); a field that fails both is AIM_FAILED with NaN values.

Instance ``i``'s results depend only on its own rows and the nominal ``u_nom``, ``jinv``: the
same on every worker, whatever the chunk it is in.
"""

from __future__ import annotations

import numpy as np
from numba import prange

from .aim2d import newton_2d, put_segment, start_ray_2d, stop_point, trace_via_stop
from .codes import (
    G_ZV,
    STATUS_AIM_FAILED,
    STATUS_CLIPPED,
    STATUS_MISSED,
    STATUS_OK,
    STATUS_TIR,
)
from .jit import kernel
from .surface import (
    asphere_sag,
    enter,
    newton_intersect,
    refract,
    surface_step,
    vertex_plane_root,
)

#: kind code of an irregular surface (instance kernels only; :mod:`.codes` has 0..2)
KIND_IRREGULAR = 3
CHORD_MAXIT = 12


@kernel(error_model="numpy", inline="always")
def _irregular_sag(c, k, asph, j, zs, za, irn2, x, y):
    """Sag of an irregular surface at (x, y) (module docstring; irn2 = 1/rn²) and its slopes
    ∂z/∂x, ∂z/∂y: (ok, z, dzx, dzy), ok False outside the base conic's domain."""
    rho = x * x + y * y
    sag, dsag, ok = asphere_sag(c, k, asph, j, rho)
    sag += zs * rho * rho * irn2 * irn2 + za * y * y * irn2
    dr = dsag + 2.0 * zs * rho * irn2 * irn2
    return ok, sag, 2.0 * x * dr, 2.0 * y * dr + 2.0 * za * y * irn2


@kernel(error_model="numpy", inline="always")
def _irregular_sag_gp(params, x, y, L, M, N):
    """(ok, sag, gp) of the irregular surface ``params`` = (c, k, asph, j, zs, za, irn2) for
    :func:`.surface.newton_intersect`."""
    c, k, asph, j, zs, za, irn2 = params
    ok, sag, dzx, dzy = _irregular_sag(c, k, asph, j, zs, za, irn2, x, y)
    return ok, sag, N - (dzx * L + dzy * M)


@kernel(error_model="numpy", inline="always")
def _irregular_step(c, k, asph, j, zs, za, rn, mu, sdj, clip, zvj, x, y, z, L, M, N):
    """Intersect and refract at an irregular surface (module docstring); the ray is in the
    surface's axis frame. Returns (status, x, y, z, L, M, N) as ``surface_step``."""
    if not (N > 0.0):
        return STATUS_MISSED, x, y, z, L, M, N
    _t0, x, y, s, have = vertex_plane_root(c, k, zvj, x, y, z, L, M, N)
    if not have:
        s = 0.0
    x = x + s * L
    y = y + s * M
    zl = s * N
    irn2 = 1.0 / (rn * rn)
    ok, x, y, zl = newton_intersect(_irregular_sag_gp, (c, k, asph, j, zs, za, irn2), x, y, zl,
                                    L, M, N)  # fmt: skip
    if not ok:
        return STATUS_MISSED, x, y, z, L, M, N
    ok, sag, dzx, dzy = _irregular_sag(c, k, asph, j, zs, za, irn2, x, y)
    z = zvj + zl
    if clip and x * x + y * y > sdj * sdj:
        return STATUS_CLIPPED, x, y, z, L, M, N
    if mu != 1.0:
        tir, L, M, N = refract(L, M, N, -dzx, -dzy, 1.0, mu)
        if tir:
            return STATUS_TIR, x, y, z, L, M, N
    return STATUS_OK, x, y, z, L, M, N


@kernel(error_model="numpy")
def _span(lens, j0, j1, clip, x, y, z, L, M, N):
    """Trace surfaces j0 .. j1-1 of ONE instance ``lens`` (:func:`_instance`); as
    :func:`raytrace.kernels.surface.trace_span`, with irregular surfaces. Returns
    (status, surface_1based, x, y, z, L, M, N)."""
    kind, c, k, asph, geo, n_in, n_out, sd, irr = lens
    for j in range(j0, j1):
        skip, x, y, z, L, M, N = enter(geo, j, x, y, z, L, M, N)
        if skip:
            continue
        mu = n_in[j] / n_out[j]
        if kind[j] == KIND_IRREGULAR:
            st, x, y, z, L, M, N = _irregular_step(
                c[j], k[j], asph, j, irr[j, 0], irr[j, 1], irr[j, 2], mu, sd[j], clip,
                geo[j, G_ZV], x, y, z, L, M, N,
            )  # fmt: skip
        else:
            st, x, y, z, L, M, N = surface_step(
                kind[j], c[j], k[j], asph, geo, j, mu, sd[j], clip, x, y, z, L, M, N, qtype=False
            )
        if st != STATUS_OK:
            return st, j + 1, x, y, z, L, M, N
    return STATUS_OK, 0, x, y, z, L, M, N


@kernel(error_model="numpy", inline="always")
def _instance(lens, i):
    """The arrays of instance i: its rows of every array of ``lens`` (kind, c, k, asph, geo,
    n_in, n_out, sd, irr), the argument tuple of :func:`_span`."""
    kind, c, k, asph, geo, n_in, n_out, sd, irr = lens
    return kind[i], c[i], k[i], asph[i], geo[i], n_in[i], n_out[i], sd[i], irr[i]


@kernel(error_model="numpy")
def _stop_point(lens, stop, finite, z_obj, f1, f2, u1, u2):
    """(ok, x, y) where the ray (f, u) meets the stop surface of one instance ``lens``
    (:func:`_instance`), unclipped (:func:`.aim2d.stop_point`)."""
    return stop_point(_span, lens, stop, finite, z_obj, f1, f2, u1, u2)


@kernel(error_model="numpy")
def _newton(lens, stop, finite, z_obj, f1, f2, u1, u2, tol, hscale):
    """The full Newton solve of :mod:`.aim2d` (:func:`.aim2d.newton_2d`, without its backward
    finite-difference step), the fallback of the chord iteration. Returns (converged, u1, u2,
    r1, r2, evaluations)."""
    nan = np.nan
    return newton_2d(_stop_point, lens, stop, finite, z_obj, f1, f2, u1, u2, tol, hscale, False,
                     nan, nan, nan, nan)[:6]  # fmt: skip


@kernel(error_model="numpy")
def _aim_one(lens, stop, finite, z_obj, f1, f2, unom, jinv, tol, hscale, clip, last, status, evals,
             resid):  # fmt: skip
    """Every field of ONE instance ``lens`` (:func:`_instance`; module docstring); outputs its
    rows: last (6, F), status (F,), evals (F,), resid (2, F)."""
    nf = f1.shape[0]
    ns = lens[1].shape[0]
    d1 = 0.0
    d2 = 0.0
    for f in range(nf):
        u1 = unom[f, 0] + d1
        u2 = unom[f, 1] + d2
        a = jinv[f, 0]
        b = jinv[f, 1]
        cc = jinv[f, 2]
        dd = jinv[f, 3]
        nev = 0
        conv = False
        ok = True
        r1 = 0.0
        r2 = 0.0
        for _ in range(CHORD_MAXIT):
            ok, r1, r2 = _stop_point(lens, stop, finite, z_obj, f1[f], f2[f], u1, u2)
            nev += 1
            if not ok:
                break
            if max(abs(r1), abs(r2)) <= tol:
                conv = True
                break
            u1 = u1 - (a * r1 + b * r2)
            u2 = u2 - (cc * r1 + dd * r2)
        if conv:  # polish: one more chord step, kept when it lowers |r|
            t1 = u1 - (a * r1 + b * r2)
            t2 = u2 - (cc * r1 + dd * r2)
            ok2, s1, s2 = _stop_point(lens, stop, finite, z_obj, f1[f], f2[f], t1, t2)
            nev += 1
            if ok2 and s1 * s1 + s2 * s2 < r1 * r1 + r2 * r2:
                u1, u2 = t1, t2
        else:
            conv, u1, u2, _r1, _r2, _ne = _newton(lens, stop, finite, z_obj, f1[f], f2[f],
                                                  unom[f, 0] + d1, unom[f, 1] + d2, tol,
                                                  hscale)  # fmt: skip
            nev += 100
        evals[f] = nev
        if not conv:
            status[f] = STATUS_AIM_FAILED
            for r in range(6):
                last[r, f] = np.nan
            resid[0, f] = np.nan
            resid[1, f] = np.nan
            continue
        d1 = u1 - unom[f, 0]
        d2 = u2 - unom[f, 1]
        x0, y0, z0, L0, M0, N0 = start_ray_2d(finite, z_obj, f1[f], f2[f], u1, u2)
        st, sf, xs, ys, x, y, z, L, M, N = trace_via_stop(
            _span, lens, stop, ns, clip, x0, y0, z0, L0, M0, N0
        )
        ok = st == STATUS_OK
        status[f] = st
        put_segment(last, f, ok, x, y, z, L, M, N)
        resid[0, f] = xs if ok else np.nan
        resid[1, f] = ys if ok else np.nan


@kernel(error_model="numpy", parallel=True)
def aim_instances(lens, stop, finite, z_obj, f1, f2, unom, jinv, tol, hscale, clip, last, status,
                  evals, resid):  # fmt: skip
    """Chief rays of every instance × field in one launch (module docstring).

    lens: ``(kind, c, k, asph, geo, n_in, n_out, sd, irr)``, each with the instance as the first
    axis (:class:`raytrace.tolerance.model.InstanceArrays`). f1, f2 (F,): fields (direction
    tangents for ``finite == 0``, object point in mm for ``finite == 1``); unom (F, 2): the
    nominal lens's unknowns per field; jinv (F, 4): its inverse Jacobian (row-major); tol (mm);
    hscale: the scale of u for finite differences.

    Outputs (filled in place): ``last`` (I, 6, F) the final segment (x, y, z, L, M, N) in the
    image frame; ``status`` int8 (I, F); ``evals`` int32 (I, F) traces to the stop (+100 when the
    Newton fallback ran); ``resid`` (I, 2, F) the stop point of the aimed ray (mm).
    """
    for i in prange(lens[1].shape[0]):
        _aim_one(_instance(lens, i), stop, finite, z_obj, f1, f2, unom, jinv, tol, hscale, clip,
                 last[i], status[i], evals[i], resid[i])  # fmt: skip


@kernel(error_model="numpy")
def aim_instances_serial(lens, stop, finite, z_obj, f1, f2, unom, jinv, tol, hscale, clip, last,
                         status, evals, resid):  # fmt: skip
    """:func:`aim_instances` on one thread (for callers that run several launches at once, such
    as threads of a Dask worker: numba's parallel layer is not re-entrant)."""
    for i in range(lens[1].shape[0]):
        _aim_one(_instance(lens, i), stop, finite, z_obj, f1, f2, unom, jinv, tol, hscale, clip,
                 last[i], status[i], evals[i], resid[i])  # fmt: skip


@kernel(error_model="numpy")
def stop_points(lens, i, stop, finite, z_obj, f1, f2, u, out):
    """Where the rays (field f, unknowns u[f]) of instance ``i`` meet its stop: out (F, 2) mm
    (NaN when not traceable). For the nominal Jacobian of the chord iteration."""
    inst = _instance(lens, i)
    for f in range(f1.shape[0]):
        ok, x, y = _stop_point(inst, stop, finite, z_obj, f1[f], f2[f], u[f, 0], u[f, 1])
        out[f, 0] = x if ok else np.nan
        out[f, 1] = y if ok else np.nan


@kernel(error_model="numpy", inline="always")
def _trace_one(lens, i, start, clip, last, status):
    """The rays ``start`` through instance i: its rows of ``last`` and ``status``."""
    inst = _instance(lens, i)
    ns = lens[1].shape[1]
    out = last[i]
    for r in range(start.shape[1]):
        st, sf, x, y, z, L, M, N = _span(
            inst, np.int64(0), ns, clip, start[0, r], start[1, r], start[2, r], start[3, r],
            start[4, r], start[5, r],
        )  # fmt: skip
        status[i, r] = st
        put_segment(out, r, st == STATUS_OK, x, y, z, L, M, N)


@kernel(error_model="numpy", parallel=True)
def trace_instances(lens, start, clip, last, status):
    """The same rays through every instance: start (6, R) rows x, y, z, L, M, N (the object-space
    rays, before the first surface); outputs last (I, 6, R) the final segments in the image
    frame (NaN where failed) and status (I, R)."""
    for i in prange(lens[1].shape[0]):
        _trace_one(lens, i, start, clip, last, status)


@kernel(error_model="numpy")
def trace_instances_serial(lens, start, clip, last, status):
    """:func:`trace_instances` on one thread."""
    for i in range(lens[1].shape[0]):
        _trace_one(lens, i, start, clip, last, status)
