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

import math

import numpy as np
from numba import prange

from .codes import (
    F_FRAME,
    F_SKIP,
    G_FLAGS,
    G_ZV,
    STATUS_AIM_FAILED,
    STATUS_CLIPPED,
    STATUS_MISSED,
    STATUS_OK,
    STATUS_TIR,
)
from .jit import kernel
from .surface import NEWTON_MAX, NEWTON_TOL, asphere_sag, quadric_root, reframe, snell, surface_step

#: kind code of an irregular surface (instance kernels only; :mod:`.codes` has 0..2)
KIND_IRREGULAR = 3
CHORD_MAXIT = 12
NEWTON_MAXIT = 40
LINE_HALVINGS = 30
FD_STEP = 1e-7


@kernel(error_model="numpy", inline="always")
def _irregular_step(c, k, asph, j, zs, za, rn, mu, sdj, clip, zvj, x, y, z, L, M, N):
    """Intersect and refract at an irregular surface (module docstring); the ray is in the
    surface's axis frame. Returns (status, x, y, z, L, M, N) as ``surface_step``."""
    if not (N > 0.0):
        return STATUS_MISSED, x, y, z, L, M, N
    t0 = (zvj - z) / N
    x = x + t0 * L
    y = y + t0 * M
    s, have = quadric_root(c, k, x, y, L, M, N)
    if not have:
        s = 0.0
    x = x + s * L
    y = y + s * M
    zl = s * N
    irn2 = 1.0 / (rn * rn)
    converged = False
    dzx = 0.0
    dzy = 0.0
    for _ in range(NEWTON_MAX):
        rho = x * x + y * y
        sag, dsag, ok = asphere_sag(c, k, asph, j, rho)
        if not ok:
            return STATUS_MISSED, x, y, z, L, M, N
        sag += zs * rho * rho * irn2 * irn2 + za * y * y * irn2
        dr = dsag + 2.0 * zs * rho * irn2 * irn2
        dzx = 2.0 * x * dr
        dzy = 2.0 * y * dr + 2.0 * za * y * irn2
        gp = N - (dzx * L + dzy * M)
        if gp == 0.0 or not math.isfinite(gp):
            return STATUS_MISSED, x, y, z, L, M, N
        ds = -(zl - sag) / gp
        x += ds * L
        y += ds * M
        zl += ds * N
        if abs(ds) <= NEWTON_TOL * (1.0 + abs(x) + abs(y) + abs(zl)):
            converged = True
            break
    if not converged:
        return STATUS_MISSED, x, y, z, L, M, N
    rho = x * x + y * y
    sag, dsag, ok = asphere_sag(c, k, asph, j, rho)
    dr = dsag + 2.0 * zs * rho * irn2 * irn2
    dzx = 2.0 * x * dr
    dzy = 2.0 * y * dr + 2.0 * za * y * irn2
    z = zvj + zl
    if clip and rho > sdj * sdj:
        return STATUS_CLIPPED, x, y, z, L, M, N
    if mu != 1.0:
        nx = -dzx
        ny = -dzy
        nz = 1.0
        inv = 1.0 / math.sqrt(nx * nx + ny * ny + nz * nz)
        nx *= inv
        ny *= inv
        nz *= inv
        L2, M2, N2, sin2t = snell(L, M, N, nx, ny, nz, mu, mu * mu)
        if sin2t > 1.0:
            return STATUS_TIR, x, y, z, L, M, N
        inv = 1.0 / math.sqrt(L2 * L2 + M2 * M2 + N2 * N2)
        L, M, N = L2 * inv, M2 * inv, N2 * inv
    return STATUS_OK, x, y, z, L, M, N


@kernel(error_model="numpy")
def _span(kind, c, k, asph, geo, n_in, n_out, sd, irr, j0, j1, clip, x, y, z, L, M, N):
    """Trace surfaces j0 .. j1-1 of ONE instance (its rows); as
    :func:`raytrace.kernels.surface.trace_span`, with irregular surfaces. Returns
    (status, surface_1based, x, y, z, L, M, N)."""
    for j in range(j0, j1):
        fl = int(geo[j, G_FLAGS])
        if (fl & F_FRAME) != 0:
            x, y, z, L, M, N = reframe(geo, j, x, y, z, L, M, N)
        if (fl & F_SKIP) != 0:
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
def _start(finite, z_obj, f1, f2, u1, u2):
    """Object-space ray of field (f1, f2) and unknowns (u1, u2) (:mod:`.aim2d`'s convention)."""
    if finite == 0:
        nrm = 1.0 / math.sqrt(1.0 + f1 * f1 + f2 * f2)
        return u1, u2, z_obj, f1 * nrm, f2 * nrm, nrm
    nrm = 1.0 / math.sqrt(1.0 + u1 * u1 + u2 * u2)
    return f1, f2, z_obj, u1 * nrm, u2 * nrm, nrm


@kernel(error_model="numpy")
def _stop_point(kind, c, k, asph, geo, n_in, n_out, sd, irr, stop, finite, z_obj, f1, f2, u1, u2):
    """(ok, x, y) where the ray (f, u) meets the stop surface of one instance (unclipped)."""
    x0, y0, z0, L0, M0, N0 = _start(finite, z_obj, f1, f2, u1, u2)
    st, sf, x, y, z, L, M, N = _span(
        kind, c, k, asph, geo, n_in, n_out, sd, irr, 0, stop + 1, False, x0, y0, z0, L0, M0, N0
    )
    return st == STATUS_OK and math.isfinite(x) and math.isfinite(y), x, y


@kernel(error_model="numpy")
def _newton(kind, c, k, asph, geo, n_in, n_out, sd, irr, stop, finite, z_obj, f1, f2, u1, u2,
            tol, hscale):  # fmt: skip
    """Full Newton solve (forward-difference Jacobian, backtracking): the fallback of the chord
    iteration. Returns (converged, u1, u2)."""
    ok, r1, r2 = _stop_point(kind, c, k, asph, geo, n_in, n_out, sd, irr, stop, finite, z_obj,
                             f1, f2, u1, u2)  # fmt: skip
    if not ok:
        return False, u1, u2
    for _ in range(NEWTON_MAXIT):
        done = max(abs(r1), abs(r2)) <= tol
        h1 = FD_STEP * max(abs(u1), hscale)
        ok, a1, a2 = _stop_point(kind, c, k, asph, geo, n_in, n_out, sd, irr, stop, finite,
                                 z_obj, f1, f2, u1 + h1, u2)  # fmt: skip
        if not ok:
            return done, u1, u2
        h2 = FD_STEP * max(abs(u2), hscale)
        ok, b1, b2 = _stop_point(kind, c, k, asph, geo, n_in, n_out, sd, irr, stop, finite,
                                 z_obj, f1, f2, u1, u2 + h2)  # fmt: skip
        if not ok:
            return done, u1, u2
        j11 = (a1 - r1) / h1
        j21 = (a2 - r2) / h1
        j12 = (b1 - r1) / h2
        j22 = (b2 - r2) / h2
        det = j11 * j22 - j12 * j21
        if det == 0.0 or not math.isfinite(det):
            return done, u1, u2
        d1 = -(j22 * r1 - j12 * r2) / det
        d2 = -(-j21 * r1 + j11 * r2) / det
        rr = r1 * r1 + r2 * r2
        lam = 1.0
        accepted = False
        for _h in range(LINE_HALVINGS if not done else 1):
            t1 = u1 + lam * d1
            t2 = u2 + lam * d2
            ok, s1, s2 = _stop_point(kind, c, k, asph, geo, n_in, n_out, sd, irr, stop, finite,
                                     z_obj, f1, f2, t1, t2)  # fmt: skip
            if ok and s1 * s1 + s2 * s2 < rr:
                u1, u2, r1, r2 = t1, t2, s1, s2
                accepted = True
                break
            lam *= 0.5
        if done:
            return True, u1, u2
        if not accepted:
            return max(abs(r1), abs(r2)) <= tol, u1, u2
    return max(abs(r1), abs(r2)) <= tol, u1, u2


@kernel(error_model="numpy")
def _aim_one(kind, c, k, asph, geo, n_in, n_out, sd, irr, stop, finite, z_obj, f1, f2, unom, jinv,
             tol, hscale, clip, last, status, evals, resid):  # fmt: skip
    """Every field of ONE instance (module docstring); outputs its rows: last (6, F), status
    (F,), evals (F,), resid (2, F)."""
    nf = f1.shape[0]
    ns = c.shape[0]
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
            ok, r1, r2 = _stop_point(kind, c, k, asph, geo, n_in, n_out, sd, irr, stop, finite,
                                     z_obj, f1[f], f2[f], u1, u2)  # fmt: skip
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
            ok2, s1, s2 = _stop_point(kind, c, k, asph, geo, n_in, n_out, sd, irr, stop, finite,
                                      z_obj, f1[f], f2[f], t1, t2)  # fmt: skip
            nev += 1
            if ok2 and s1 * s1 + s2 * s2 < r1 * r1 + r2 * r2:
                u1, u2 = t1, t2
        else:
            conv, u1, u2 = _newton(kind, c, k, asph, geo, n_in, n_out, sd, irr, stop, finite,
                                   z_obj, f1[f], f2[f], unom[f, 0] + d1, unom[f, 1] + d2, tol,
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
        x0, y0, z0, L0, M0, N0 = _start(finite, z_obj, f1[f], f2[f], u1, u2)
        st, sf, x, y, z, L, M, N = _span(kind, c, k, asph, geo, n_in, n_out, sd, irr, 0,
                                         stop + 1, clip, x0, y0, z0, L0, M0, N0)  # fmt: skip
        xs = x
        ys = y
        if st == STATUS_OK:
            st, sf, x, y, z, L, M, N = _span(kind, c, k, asph, geo, n_in, n_out, sd, irr,
                                             stop + 1, ns, clip, x, y, z, L, M, N)  # fmt: skip
        status[f] = st
        if st == STATUS_OK:
            last[0, f] = x
            last[1, f] = y
            last[2, f] = z
            last[3, f] = L
            last[4, f] = M
            last[5, f] = N
            resid[0, f] = xs
            resid[1, f] = ys
        else:
            for r in range(6):
                last[r, f] = np.nan
            resid[0, f] = np.nan
            resid[1, f] = np.nan


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
    kind, c, k, asph, geo, n_in, n_out, sd, irr = lens
    for i in prange(c.shape[0]):
        _aim_one(kind[i], c[i], k[i], asph[i], geo[i], n_in[i], n_out[i], sd[i], irr[i], stop,
                 finite, z_obj, f1, f2, unom, jinv, tol, hscale, clip, last[i], status[i],
                 evals[i], resid[i])  # fmt: skip


@kernel(error_model="numpy")
def aim_instances_serial(lens, stop, finite, z_obj, f1, f2, unom, jinv, tol, hscale, clip, last,
                         status, evals, resid):  # fmt: skip
    """:func:`aim_instances` on one thread (for callers that run several launches at once, such
    as threads of a Dask worker: numba's parallel layer is not re-entrant)."""
    kind, c, k, asph, geo, n_in, n_out, sd, irr = lens
    for i in range(c.shape[0]):
        _aim_one(kind[i], c[i], k[i], asph[i], geo[i], n_in[i], n_out[i], sd[i], irr[i], stop,
                 finite, z_obj, f1, f2, unom, jinv, tol, hscale, clip, last[i], status[i],
                 evals[i], resid[i])  # fmt: skip


@kernel(error_model="numpy")
def stop_points(lens, i, stop, finite, z_obj, f1, f2, u, out):
    """Where the rays (field f, unknowns u[f]) of instance ``i`` meet its stop: out (F, 2) mm
    (NaN when not traceable). For the nominal Jacobian of the chord iteration."""
    kind, c, k, asph, geo, n_in, n_out, sd, irr = lens
    for f in range(f1.shape[0]):
        ok, x, y = _stop_point(
            kind[i], c[i], k[i], asph[i], geo[i], n_in[i], n_out[i], sd[i], irr[i], stop,
            finite, z_obj, f1[f], f2[f], u[f, 0], u[f, 1],
        )  # fmt: skip
        out[f, 0] = x if ok else np.nan
        out[f, 1] = y if ok else np.nan


@kernel(error_model="numpy", inline="always")
def _trace_one(kind, c, k, asph, geo, n_in, n_out, sd, irr, i, start, clip, last, status):
    ns = c.shape[1]
    nr = start.shape[1]
    for r in range(nr):
        st, sf, x, y, z, L, M, N = _span(kind[i], c[i], k[i], asph[i], geo[i], n_in[i],
                                         n_out[i], sd[i], irr[i], 0, ns, clip, start[0, r],
                                         start[1, r], start[2, r], start[3, r], start[4, r],
                                         start[5, r])  # fmt: skip
        status[i, r] = st
        if st == STATUS_OK:
            last[i, 0, r] = x
            last[i, 1, r] = y
            last[i, 2, r] = z
            last[i, 3, r] = L
            last[i, 4, r] = M
            last[i, 5, r] = N
        else:
            for q in range(6):
                last[i, q, r] = np.nan


@kernel(error_model="numpy", parallel=True)
def trace_instances(lens, start, clip, last, status):
    """The same rays through every instance: start (6, R) rows x, y, z, L, M, N (the object-space
    rays, before the first surface); outputs last (I, 6, R) the final segments in the image
    frame (NaN where failed) and status (I, R)."""
    kind, c, k, asph, geo, n_in, n_out, sd, irr = lens
    for i in prange(c.shape[0]):
        _trace_one(kind, c, k, asph, geo, n_in, n_out, sd, irr, i, start, clip, last, status)


@kernel(error_model="numpy")
def trace_instances_serial(lens, start, clip, last, status):
    """:func:`trace_instances` on one thread."""
    kind, c, k, asph, geo, n_in, n_out, sd, irr = lens
    for i in range(c.shape[0]):
        _trace_one(kind, c, k, asph, geo, n_in, n_out, sd, irr, i, start, clip, last, status)
