"""Chief-ray aiming in one kernel call: for every field, the meridional real ray through the
centre of the stop (height zero at the stop surface), by field continuation and a safeguarded
secant solve (Pestrecov 1958, Fig. 1: the principal ray through the centre of the real stop).

The stop height is measured in the stop surface's own frame (:mod:`raytrace.frames`), so a
decentered or tilted stop is aimed at its centre. A rotationally symmetric lens (lens flag
``L_SYMMETRIC``) aims |field| and mirrors negative fields, with the zero field on the axis; any
other lens aims each signed field by continuation from the zero field, which is solved too. A
meridional ray can only reach the stop centre of a lens symmetric about the y-z plane (decenters
in y, tilts about x) up to the stop: where the aimed ray meets the stop off the y axis by more
than the tolerance, the field is AIM_FAILED (use the 2-D aim of :mod:`.aim2d`). The outputs keep
y, z, M, N of the rays; behind the stop of a lens that is not symmetric about its y-z plane the
ray also has x and L components, which the 2-D aim reports.
"""

from __future__ import annotations

import math

import numpy as np

from .codes import G_LENS, L_SYMMETRIC, STATUS_AIM_FAILED, STATUS_OK
from .jit import kernel
from .surface import trace_span

# Chief-ray aiming limits (per field): secant/bisection iterations per solve, step halvings of
# the field continuation, total residual evaluations.
AIM_MAXIT = 60
AIM_MAX_HALVINGS = 40
AIM_MAX_EVALS = 1500


@kernel(error_model="numpy", inline="always")
def _start_ray(finite, z_obj, f, u):
    """Object-space meridional ray for field value f and unknown u.

    finite == 0 (object at infinity): f = α (rad), start (0, u, 0), direction (0, sin α, cos α).
    finite == 1: f = object height (mm), start (0, f, z_obj), direction ∝ (0, u, 1) (u = tan θ).
    """
    if finite == 0:
        return u, 0.0, math.sin(f), math.cos(f)
    nrm = math.sqrt(1.0 + u * u)
    return f, z_obj, u / nrm, 1.0 / nrm


@kernel(error_model="numpy")
def _stop_residual(kind, c, k, asph, geo, n_in, n_out, sd, stop, finite, z_obj, f, u):
    """Meridional height at the stop surface of the ray (f, u) (unclipped); (status, y)."""
    y0, z0, M0, N0 = _start_ray(finite, z_obj, f, u)
    st, sf, x, y, z, L, M, N = trace_span(
        kind, c, k, asph, geo, n_in, n_out, sd, 0, stop + 1, False, 0.0, y0, z0, 0.0, M0, N0
    )
    return st, y


@kernel(error_model="numpy", inline="always")
def _bracket(ua, ra, ub, rb):
    """The bracket (lo, hi, r(lo)) of two points ua, ub whose residuals ra, rb differ in sign."""
    if ua < ub:
        return ua, ub, ra
    return ub, ua, rb


@kernel(error_model="numpy")
def _solve_field(
    kind, c, k, asph, geo, n_in, n_out, sd, stop, finite, z_obj, f, u0, g0, tol, hscale
):  # fmt: skip
    """Safeguarded secant solve of y_stop(u) = 0 from the guess u0.

    ``g0``: the slope dy_stop/du to start from, when known (finite and non-zero: the last slope
    of the previous field's solve, which the continuation passes on); otherwise (NaN) the first
    slope is a forward difference (a backward one where that point cannot be traced), one more
    trace.

    Returns (converged, u, residual, evaluations, slope): ``slope`` the last secant slope (``g0``
    when the guess needed no step; NaN when none was formed). A sign change between two
    traceable points keeps a bracket; secant steps outside it are replaced by bisection; an
    untraceable trial point is pulled halfway back toward the last good point (up to 20
    times)."""
    nev = 1
    st, r0 = _stop_residual(kind, c, k, asph, geo, n_in, n_out, sd, stop, finite, z_obj, f, u0)
    if st != STATUS_OK or not math.isfinite(r0):
        return False, u0, np.nan, nev, np.nan
    if abs(r0) <= tol:
        return True, u0, r0, nev, g0
    h = 1e-7 * max(abs(u0), hscale)
    # best point (ub, rb) and bracket [lo, hi] (valid when have_br)
    ub, rb = u0, r0
    have_br = False
    lo = 0.0
    hi = 0.0
    rlo = 0.0
    g = g0
    if not (g0 != 0.0 and math.isfinite(g0)):
        u1 = u0 + h
        st, r1 = _stop_residual(kind, c, k, asph, geo, n_in, n_out, sd, stop, finite, z_obj, f, u1)
        nev += 1
        if st != STATUS_OK:
            u1 = u0 - h
            st, r1 = _stop_residual(
                kind, c, k, asph, geo, n_in, n_out, sd, stop, finite, z_obj, f, u1
            )
            nev += 1
            if st != STATUS_OK:
                return False, u0, r0, nev, np.nan
        g = (r1 - r0) / (u1 - u0)
        if abs(r1) <= tol:
            return True, u1, r1, nev, g
        if abs(r1) < abs(r0):
            ub, rb = u1, r1
        if r0 * r1 < 0.0:
            have_br = True
            lo, hi, rlo = _bracket(u0, r0, u1, r1)
    for _ in range(AIM_MAXIT):
        if g != 0.0 and math.isfinite(g):
            un = ub - rb / g
        else:
            un = 0.5 * (lo + hi) if have_br else ub + h
        if have_br and not (lo < un < hi):
            un = 0.5 * (lo + hi)
        ok = False
        rn = 0.0
        for _k in range(20):
            st, rn = _stop_residual(
                kind, c, k, asph, geo, n_in, n_out, sd, stop, finite, z_obj, f, un
            )
            nev += 1
            if st == STATUS_OK and math.isfinite(rn):
                ok = True
                break
            un = ub + 0.5 * (un - ub)
        if not ok:
            return False, ub, rb, nev, g
        if abs(rn) <= tol:
            return True, un, rn, nev, g
        if un != ub:
            g = (rn - rb) / (un - ub)
        # update bracket
        if have_br:
            if (rn < 0.0) == (rlo < 0.0):
                lo, rlo = un, rn
            else:
                hi = un
        elif rn * rb < 0.0:
            have_br = True
            lo, hi, rlo = _bracket(un, rn, ub, rb)
        if abs(rn) < abs(rb) or have_br:
            ub, rb = un, rn
        if have_br and hi - lo <= 4e-16 * max(abs(lo), abs(hi)):
            return False, ub, rb, nev, g
    return False, ub, rb, nev, g


@kernel(error_model="numpy")
def aim_chief(lens, stop, finite, z_obj, fields, order, slope0, tol, hscale, clip, start, last,
              status, surface, evals, residual):  # fmt: skip
    """Aim the meridional chief ray (through the stop vertex) for every wavelength × field; one
    call.

    lens: the tuple :attr:`raytrace.packing.PackedLens.lens_arrays` — kind, c, k, asph, geo,
    n_in_w, n_out_w, sd, with the indices as (n_wavelengths, n_surfaces) arrays (row i =
    wavelength i). fields: field values (α in rad for ``finite == 0``; object height in mm for
    ``finite == 1``), the same for every wavelength, any order and sign (negative fields are
    mirror images of positive ones); order: the indices that sort them by |field| (int64; the
    caller sorts, so that no sort is compiled into the kernel). Per wavelength (arrays of
    n_wavelengths): slope0, the paraxial du/df at f = 0 (−z_E0 for infinity; −1/(z_E0 − z_obj)
    for a finite object); tol, the absolute stop-height tolerance (mm); hscale, the scale of u
    for finite-difference steps.

    Outputs (filled in place): ``start`` and ``last`` (n_wavelengths, 4, n) float64 — rows y, z,
    M, N of the object-space ray and of the final segment (see :func:`_aim_fields`);
    ``status`` int8, ``surface`` int32, ``evals`` int32 and ``residual`` float64, each
    (n_wavelengths, n).
    """
    kind, c, k, asph, geo, n_in_w, n_out_w, sd = lens
    for iw in range(n_in_w.shape[0]):
        _aim_fields(kind, c, k, asph, geo, n_in_w[iw], n_out_w[iw], sd, stop, finite, z_obj, fields,
                    order, slope0[iw], tol[iw], hscale[iw], clip, start[iw], last[iw], status[iw],
                    surface[iw], evals[iw], residual[iw])  # fmt: skip


@kernel(error_model="numpy")
def _aim_fields(kind, c, k, asph, geo, n_in, n_out, sd, stop, finite, z_obj, fields, order,
                slope0, tol, hscale, clip, start, last, status, surface, evals,
                residual):  # fmt: skip
    """Aim the meridional chief ray (through the stop vertex) for every field at one wavelength
    (indices ``n_in``, ``n_out``).

    fields: field values (α in rad for ``finite == 0``; object height in mm for ``finite == 1``),
    any order and sign (negative fields are mirror images of positive ones); order: the indices
    that sort them by |f|. slope0: paraxial du/df at f = 0 (−z_E0 for infinity; −1/(z_E0 − z_obj)
    for a finite object). tol: absolute stop-height tolerance (mm). hscale: scale of u for
    finite-difference steps.

    Fields are solved in order of |f| by continuation: each starts from the quadratic
    extrapolation of the last three solutions (linear through the last two, or from the
    paraxial slope at f = 0, while there are fewer; the quadratic term is dropped where it is
    not a small correction, and a failed solve forgets it) and from the last solve's slope
    dy_stop/du; a failed solve halves the field step (intermediate fields) until it succeeds or
    AIM_MAX_HALVINGS / AIM_MAX_EVALS is exhausted (→ AIM_FAILED).

    Outputs (filled in place, one column / entry per field): ``start`` (4, n) float64 rows y, z,
    M, N of the object-space ray (a point and direction cosines, meridional plane x = 0);
    ``last`` (4, n) rows y, z, M, N of the final segment (point on the last surface, direction
    after it); ``status`` int8 and ``surface`` int32 (1-based failed surface, 0 when OK);
    ``evals`` int32 residual evaluations used; ``residual`` float64 height at the stop (mm).
    Fields that failed have NaN rays (z of the start point kept).
    """
    n = fields.shape[0]
    ns = c.shape[0]
    symmetric = (int(geo[0, G_LENS]) & L_SYMMETRIC) != 0
    # continuation state per side (0: f >= 0, 1: f < 0; a symmetric lens uses side 0 for |f|):
    # last solved field fb, its solution ub, the divided difference du/df over [fs, fb] of the
    # last two solutions (at the start the paraxial slope, which off the axis of a lens that is
    # not symmetric can be far off) and the second divided difference curv over the last three
    # (0 until there are three): the guess is the quadratic through them
    fb = np.zeros(2)
    ub = np.zeros(2)
    fs = np.zeros(2)
    slope = np.array([slope0, slope0])
    curv = np.zeros(2)
    secant = np.zeros(2, dtype=np.bool_)  # slope is a divided difference of two solutions
    # and the last slope dy_stop/du of its solve, the next solve's first slope (NaN: none yet,
    # or the last solve failed; the solve then forms one by a forward difference)
    gb = np.full(2, np.nan)
    ok0 = True
    u0 = 0.0
    r0 = 0.0
    ne0 = 0
    if not symmetric:  # the zero field is not on the axis: solve it first
        ok0, u0, r0, ne0, g0 = _solve_field(
            kind, c, k, asph, geo, n_in, n_out, sd, stop, finite, z_obj, 0.0, 0.0, np.nan, tol,
            hscale,
        )  # fmt: skip
        ub[0] = u0
        ub[1] = u0
        if ok0:
            gb[0] = g0
            gb[1] = g0
    for ii in range(n):
        i = order[ii]
        if symmetric:
            ftarget = abs(fields[i])
            sign = 1.0 if fields[i] >= 0.0 else -1.0
            side = 0
        else:
            ftarget = fields[i]
            sign = 1.0
            side = 0 if fields[i] >= 0.0 else 1
        nev = 0
        conv = False
        u = 0.0
        res = 0.0
        if ftarget == 0.0:
            conv = ok0
            u = u0
            res = r0
            nev = ne0
        elif not ok0:
            conv = False
        else:
            fcur = fb[side]
            ucur = ub[side]
            step = ftarget - fcur
            halvings = 0
            while True:
                ftry = fcur + step
                if step == ftarget - fcur:
                    ftry = ftarget
                # the quadratic term only while it is a correction: a curvature formed over
                # steps that halved toward the edge of the traceable fields, or over fields a
                # rounding error apart, is noise (one guess was 3e9 mm off)
                dq = curv[side] * (ftry - fs[side])
                if not (abs(dq) <= 0.5 * abs(slope[side])):
                    dq = 0.0
                guess = ucur + (ftry - fcur) * (slope[side] + dq)
                ok, usol, rsol, ne, gsol = _solve_field(
                    kind, c, k, asph, geo, n_in, n_out, sd, stop, finite, z_obj, ftry, guess,
                    gb[side], tol, hscale,
                )  # fmt: skip
                nev += ne
                gb[side] = gsol if ok else np.nan
                if ok:
                    if ftry != fcur:
                        snew = (usol - ucur) / (ftry - fcur)
                        if secant[side]:
                            curv[side] = (snew - slope[side]) / (ftry - fs[side])
                        slope[side] = snew
                        fs[side] = fcur
                        secant[side] = True
                    fcur, ucur = ftry, usol
                    fb[side], ub[side] = fcur, ucur
                    if ftry == ftarget:
                        conv = True
                        u = usol
                        res = rsol
                        break
                    step = 2.0 * step
                    if abs(step) > abs(ftarget - fcur):
                        step = ftarget - fcur
                else:
                    # a failed solve: the curvature starts again from the next three solutions
                    curv[side] = 0.0
                    secant[side] = False
                    halvings += 1
                    if halvings > AIM_MAX_HALVINGS or nev > AIM_MAX_EVALS:
                        u = usol
                        res = rsol
                        break
                    step *= 0.5
        y0, z0, M0, N0 = _start_ray(finite, z_obj, abs(ftarget) if symmetric else ftarget, u)
        start[0, i] = sign * y0
        start[1, i] = z0
        start[2, i] = sign * M0
        start[3, i] = N0
        evals[i] = nev
        st = STATUS_OK
        sf = 0
        x = 0.0
        y = 0.0
        z = 0.0
        L = 0.0
        M = 0.0
        N = 0.0
        ystop = 0.0
        if conv:
            # the final trace in two spans, to the stop (its point is kept) and on to the image,
            # through ONE inlined copy of trace_span: two copies made this kernel's cold compile
            # about 1.5x as long
            y = y0
            z = z0
            M = M0
            N = N0
            j0 = 0
            j1 = stop + 1
            for part in range(2):
                st, sf, x, y, z, L, M, N = trace_span(
                    kind, c, k, asph, geo, n_in, n_out, sd, j0, j1, clip, x, y, z, L, M, N
                )
                if part == 0:
                    ystop = y
                    if st == STATUS_OK and not (abs(x) <= tol):
                        conv = False  # the stop centre is off the meridional plane: unreachable
                if st != STATUS_OK or not conv:
                    break
                j0 = stop + 1
                j1 = ns
        if not conv:
            start[0, i] = np.nan
            start[2, i] = np.nan
            start[3, i] = np.nan
            for r in range(4):
                last[r, i] = np.nan
            status[i] = STATUS_AIM_FAILED
            surface[i] = 0
            residual[i] = np.nan
            continue
        status[i] = st
        surface[i] = sf
        if st == STATUS_OK:
            last[0, i] = sign * y
            last[1, i] = z
            last[2, i] = sign * M
            last[3, i] = N
            residual[i] = sign * ystop
        else:
            for r in range(4):
                last[r, i] = np.nan
            residual[i] = sign * res
