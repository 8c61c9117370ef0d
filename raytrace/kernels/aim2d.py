"""Chief-ray aiming on a 2-D field grid in one kernel call: for every field (x, y), the real ray
through the centre of the real stop, solved for TWO unknowns (Pestrecov 1958, Fig. 1: the
principal ray through the centre of the real stop; docs/design.md, "2-D distortion").

Field parameters and unknowns (``finite`` flag, as :mod:`.aim` for the meridional case):

- ``finite == 0`` (object at infinity, or any fixed direction): the field is the pair of
  direction tangents ``(f1, f2) = (L/N, M/N)`` of the object-space ray, fixed; the unknowns are
  the start point ``(u1, u2)`` of the ray on the plane ``z = z_obj`` (the caller passes 0: the
  first vertex plane).
- ``finite == 1``: the field is the object point ``(f1, f2, z_obj)`` (mm), fixed; the unknowns
  are the direction tangents ``(u1, u2) = (L/N, M/N)`` of the ray leaving it.

The residual is the point ``(x, y)`` where the ray meets the stop surface (traced unclipped with
:func:`raytrace.kernels.surface.trace_span`, the shared 3-D surface step); the chief ray has
``(x, y) = (0, 0)`` there to an absolute tolerance ``tol`` (mm).

Solver (per field, :func:`newton_2d`, shared with :mod:`.instances`): Newton's method on the
2 × 2 system with a forward-difference Jacobian (steps ``1e-7 × max(|u_i|, hscale)``; a
backward step where the forward one cannot be traced), safeguarded by a backtracking line
search on |r|² (step halved up to ``LINE_HALVINGS`` times until the trial ray is traceable and
|r| decreases). After the tolerance is met, one more Newton step with the last Jacobian is
taken when it lowers |r| (a polish to round-off, so that independently aimed rays agree far
below the tolerance).

Continuation over the grid (:func:`_aim_fields_2d`): fields are solved in order of their distance
from the origin (|f|). Each starts from its nearest already-solved field j (found in a uniform
bucket grid of the fields, searched ring by ring), predicted as
``u = u_j + slope0·(f − f_j)`` (slope0 = the paraxial du/df); the first field starts from the
solved origin field (0, 0) (aimed first). When Newton fails from that guess, the field is
approached along the straight path from f_j in steps that halve on failure and double on success
(as :mod:`.aim` does along the meridian), extrapolating the solution along the path; after
``AIM_MAX_HALVINGS`` halvings or ``AIM_MAX_EVALS`` residual evaluations the field is AIM_FAILED.

Outputs per wavelength × field: the object-space ray (x, y, z, L, M, N), the final segment (point
on the last surface, direction after it), status and failed surface (codes of :mod:`.codes`),
residual evaluations, and the stop residual (x, y) in mm.
"""

from __future__ import annotations

import math

import numpy as np

from .codes import STATUS_AIM_FAILED, STATUS_OK
from .jit import kernel
from .surface import trace_span

# per-field limits: Newton iterations per solve, step halvings of the line search, step halvings
# of the continuation path, total residual evaluations
AIM2_MAXIT = 40
LINE_HALVINGS = 30
AIM_MAX_HALVINGS = 40
AIM_MAX_EVALS = 3000
FD_STEP = 1e-7


@kernel(error_model="numpy", inline="always")
def start_ray_2d(finite, z_obj, f1, f2, u1, u2):
    """Object-space ray (x, y, z, L, M, N) of field (f1, f2) and unknowns (u1, u2) (module
    docstring)."""
    if finite == 0:
        nrm = 1.0 / math.sqrt(1.0 + f1 * f1 + f2 * f2)
        return u1, u2, z_obj, f1 * nrm, f2 * nrm, nrm
    nrm = 1.0 / math.sqrt(1.0 + u1 * u1 + u2 * u2)
    return f1, f2, z_obj, u1 * nrm, u2 * nrm, nrm


@kernel(error_model="numpy")
def _trace_lens(lens, j0, j1, clip, x, y, z, L, M, N):
    """:func:`trace_span` of the packed lens ``lens`` = (kind, c, k, asph, geo, n_in, n_out, sd)
    at one wavelength. Not inlined: the span is compiled once, and every caller (the stop
    residual, the two spans of the final trace) calls it (inlining it into each tripled the
    surface step's code and made the cold compile about 1.5x slower)."""
    kind, c, k, asph, geo, n_in, n_out, sd = lens
    return trace_span(kind, c, k, asph, geo, n_in, n_out, sd, j0, j1, clip, x, y, z, L, M, N)


@kernel(error_model="numpy", inline="always")
def stop_point(span, lens, stop, finite, z_obj, f1, f2, u1, u2):
    """(ok, x, y): where the ray (f, u) meets the stop surface, traced unclipped by ``span(lens,
    j0, j1, clip, x, y, z, L, M, N)`` (:func:`_trace_lens`, or the instance kernels' trace of
    one instance) with the results of :func:`raytrace.kernels.surface.trace_span`."""
    x0, y0, z0, L0, M0, N0 = start_ray_2d(finite, z_obj, f1, f2, u1, u2)
    # np.int64(0), np.bool_(False): typed arguments, not literals; a literal would compile
    # ``span`` (a called kernel) once more for each literal value
    st, sf, x, y, z, L, M, N = span(
        lens, np.int64(0), stop + 1, np.bool_(False), x0, y0, z0, L0, M0, N0
    )
    return st == STATUS_OK and math.isfinite(x) and math.isfinite(y), x, y


@kernel(error_model="numpy", inline="always")
def trace_via_stop(span, lens, stop, ns, clip, x, y, z, L, M, N):
    """The ray traced through all ns surfaces with ``span`` (:func:`stop_point`), in two spans
    so that the point on the stop is kept: (status, surface_1based, x_stop, y_stop, x, y, z, L,
    M, N), the last six the final segment."""
    st, sf, x, y, z, L, M, N = span(lens, np.int64(0), stop + 1, clip, x, y, z, L, M, N)
    xs = x
    ys = y
    if st == STATUS_OK:
        st, sf, x, y, z, L, M, N = span(lens, stop + 1, ns, clip, x, y, z, L, M, N)
    return st, sf, xs, ys, x, y, z, L, M, N


@kernel(error_model="numpy", inline="always")
def put_segment(out, i, ok, x, y, z, L, M, N):
    """Column i of ``out`` (rows x, y, z, L, M, N) set to the segment, or to NaN where not ok."""
    out[0, i] = x if ok else np.nan
    out[1, i] = y if ok else np.nan
    out[2, i] = z if ok else np.nan
    out[3, i] = L if ok else np.nan
    out[4, i] = M if ok else np.nan
    out[5, i] = N if ok else np.nan


@kernel(error_model="numpy", inline="always")
def newton_2d(residual, lens, stop, finite, z_obj, f1, f2, u1, u2, tol, hscale, backstep):
    """Safeguarded Newton solve of r(u) = ``residual(lens, stop, finite, z_obj, f1, f2, u1,
    u2)`` = 0 (a stop point (ok, x, y): :func:`stop_point`) from the guess (u1, u2) (module
    docstring). ``backstep``: where the forward-difference ray cannot be traced, try the
    backward step (True) or stop there (False).

    Returns (converged, u1, u2, r1, r2, evaluations); on failure the best point found."""
    nev = 1
    ok, r1, r2 = residual(lens, stop, finite, z_obj, f1, f2, u1, u2)
    if not ok:
        return False, u1, u2, np.nan, np.nan, nev
    for _ in range(AIM2_MAXIT):
        done = max(abs(r1), abs(r2)) <= tol
        # forward-difference Jacobian (backward where the forward ray cannot be traced)
        h1 = FD_STEP * max(abs(u1), hscale)
        ok, a1, a2 = residual(lens, stop, finite, z_obj, f1, f2, u1 + h1, u2)
        nev += 1
        if not ok and backstep:
            h1 = -h1
            ok, a1, a2 = residual(lens, stop, finite, z_obj, f1, f2, u1 + h1, u2)
            nev += 1
        if not ok:
            return done, u1, u2, r1, r2, nev
        h2 = FD_STEP * max(abs(u2), hscale)
        ok, b1, b2 = residual(lens, stop, finite, z_obj, f1, f2, u1, u2 + h2)
        nev += 1
        if not ok and backstep:
            h2 = -h2
            ok, b1, b2 = residual(lens, stop, finite, z_obj, f1, f2, u1, u2 + h2)
            nev += 1
        if not ok:
            return done, u1, u2, r1, r2, nev
        j11 = (a1 - r1) / h1
        j21 = (a2 - r2) / h1
        j12 = (b1 - r1) / h2
        j22 = (b2 - r2) / h2
        det = j11 * j22 - j12 * j21
        if det == 0.0 or not math.isfinite(det):
            return done, u1, u2, r1, r2, nev
        d1 = -(j22 * r1 - j12 * r2) / det
        d2 = -(-j21 * r1 + j11 * r2) / det
        rr = r1 * r1 + r2 * r2
        lam = 1.0
        accepted = False
        for _h in range(LINE_HALVINGS if not done else 1):
            t1 = u1 + lam * d1
            t2 = u2 + lam * d2
            ok, s1, s2 = residual(lens, stop, finite, z_obj, f1, f2, t1, t2)
            nev += 1
            if ok and s1 * s1 + s2 * s2 < rr:
                u1, u2, r1, r2 = t1, t2, s1, s2
                accepted = True
                break
            lam *= 0.5
        if done:  # the polish step was taken or refused: either way finished
            return True, u1, u2, r1, r2, nev
        if not accepted:
            return max(abs(r1), abs(r2)) <= tol, u1, u2, r1, r2, nev
    return max(abs(r1), abs(r2)) <= tol, u1, u2, r1, r2, nev


@kernel(error_model="numpy")
def _stop_residual_2d(lens, stop, finite, z_obj, f1, f2, u1, u2):
    """:func:`stop_point` of the packed lens ``lens`` (:func:`_trace_lens`)."""
    return stop_point(_trace_lens, lens, stop, finite, z_obj, f1, f2, u1, u2)


@kernel(error_model="numpy")
def _newton2(lens, stop, finite, z_obj, f1, f2, u1, u2, tol, hscale):
    """:func:`newton_2d` on the packed lens ``lens`` (with backward finite-difference steps)."""
    return newton_2d(_stop_residual_2d, lens, stop, finite, z_obj, f1, f2, u1, u2, tol, hscale,
                     True)  # fmt: skip


@kernel(error_model="numpy")
def _solve_from(lens, stop, finite, z_obj, f1, f2, g1, g2, ub1, ub2, slope0, tol, hscale):
    """Solve field (f1, f2) starting from the solved field (g1, g2) with solution (ub1, ub2):
    Newton from the paraxial prediction, then continuation along the path from g to f.

    Returns (converged, u1, u2, r1, r2, evaluations)."""
    p1 = ub1 + slope0 * (f1 - g1)
    p2 = ub2 + slope0 * (f2 - g2)
    ok, u1, u2, r1, r2, nev = _newton2(lens, stop, finite, z_obj, f1, f2, p1, p2, tol, hscale)
    if ok:
        return True, u1, u2, r1, r2, nev
    # continuation along s in [0, 1]: field g + s (f − g); solution derivative du/ds
    scur = 0.0
    c1 = ub1
    c2 = ub2
    v1 = slope0 * (f1 - g1)
    v2 = slope0 * (f2 - g2)
    step = 0.5
    halvings = 0
    while True:
        stry = min(1.0, scur + step)
        q1 = g1 + stry * (f1 - g1)
        q2 = g2 + stry * (f2 - g2)
        if stry == 1.0:
            q1 = f1
            q2 = f2
        gu1 = c1 + v1 * (stry - scur)
        gu2 = c2 + v2 * (stry - scur)
        ok, u1, u2, r1, r2, ne = _newton2(lens, stop, finite, z_obj, q1, q2, gu1, gu2, tol, hscale)
        nev += ne
        if ok:
            v1 = (u1 - c1) / (stry - scur)
            v2 = (u2 - c2) / (stry - scur)
            scur = stry
            c1 = u1
            c2 = u2
            if stry == 1.0:
                return True, u1, u2, r1, r2, nev
            step = min(2.0 * step, 1.0 - scur)
        else:
            halvings += 1
            if halvings > AIM_MAX_HALVINGS or nev > AIM_MAX_EVALS:
                return False, u1, u2, r1, r2, nev
            step *= 0.5


@kernel(error_model="numpy")
def aim_chief_2d(lens, stop, finite, z_obj, f1, f2, slope0, tol, hscale, clip, start, last,
                 status, surface, evals, residual):  # fmt: skip
    """Aim the chief ray (through the centre of the stop) for every wavelength × 2-D field; one
    call.

    lens: the tuple :attr:`raytrace.packing.PackedLens.lens_arrays` — kind, c, k, asph, zv,
    n_in_w, n_out_w, sd (indices as (n_wavelengths, n_surfaces) arrays). f1, f2 (n,): the field
    pairs (module docstring: direction tangents for ``finite == 0``, object point in mm for
    ``finite == 1``), the same for every wavelength. Per wavelength (arrays of n_wavelengths):
    slope0, the paraxial du/df at f = 0 (−(z_E0 − z_obj) for a fixed direction; −1/(z_E0 −
    z_obj) for an object point); tol, the absolute stop tolerance (mm); hscale, the scale of u
    for the finite-difference steps.

    Outputs (filled in place): ``start`` and ``last`` (n_wavelengths, 6, n) float64 — rows x, y,
    z, L, M, N of the object-space ray and of the final segment; ``status`` int8, ``surface``
    int32, ``evals`` int32 (n_wavelengths, n); ``residual`` (n_wavelengths, 2, n) float64 — the
    stop point (x, y) of the aimed ray (mm).
    """
    kind, c, k, asph, zv, n_in_w, n_out_w, sd = lens
    for iw in range(n_in_w.shape[0]):
        _aim_fields_2d((kind, c, k, asph, zv, n_in_w[iw], n_out_w[iw], sd), stop, finite, z_obj,
                       f1, f2, slope0[iw], tol[iw], hscale[iw], clip, start[iw], last[iw],
                       status[iw], surface[iw], evals[iw], residual[iw])  # fmt: skip


@kernel(error_model="numpy")
def _aim_fields_2d(lens, stop, finite, z_obj, f1, f2, slope0, tol, hscale, clip, start, last,
                   status, surface, evals, residual):  # fmt: skip
    """:func:`aim_chief_2d` at one wavelength: ``lens`` the packed arrays with the indices
    ``n_in``, ``n_out`` of that wavelength (the argument tuple of :func:`trace_span`); outputs
    (6, n), (6, n), (n,), (n,), (n,), (2, n)."""
    n = f1.shape[0]
    ns = lens[1].shape[0]
    order = np.argsort(f1 * f1 + f2 * f2)
    U1 = np.zeros(n)
    U2 = np.zeros(n)
    # solved fields in a uniform bucket grid (nearest-neighbour queries in ~O(1))
    nb = max(1, int(math.sqrt(n)))
    lo1 = min(0.0, np.min(f1)) if n else 0.0
    lo2 = min(0.0, np.min(f2)) if n else 0.0
    h1 = (max(0.0, np.max(f1)) - lo1) / nb if n else 1.0
    h2 = (max(0.0, np.max(f2)) - lo2) / nb if n else 1.0
    h1 = h1 if h1 > 0.0 else 1.0
    h2 = h2 if h2 > 0.0 else 1.0
    head = np.full(nb * nb, -1, dtype=np.int64)
    nxt = np.full(n, -1, dtype=np.int64)
    # the origin field (0, 0) anchors the continuation
    ok0, o1, o2, _r1, _r2, _ne = _newton2(lens, stop, finite, z_obj, 0.0, 0.0, 0.0, 0.0, tol,
                                          hscale)  # fmt: skip
    for ii in range(n):
        i = order[ii]
        # nearest solved field (the origin when none is nearer or none is solved)
        best = -1
        dbest = f1[i] * f1[i] + f2[i] * f2[i] if ok0 else np.inf
        c1 = min(nb - 1, int((f1[i] - lo1) / h1))
        c2 = min(nb - 1, int((f2[i] - lo2) / h2))
        for ring in range(nb):
            reach = (ring - 1) * min(h1, h2)
            if ring > 0 and reach > 0.0 and reach * reach >= dbest:
                break
            for a in range(c1 - ring, c1 + ring + 1):
                if a < 0 or a >= nb:
                    continue
                for b in range(c2 - ring, c2 + ring + 1):
                    if b < 0 or b >= nb:
                        continue
                    if max(abs(a - c1), abs(b - c2)) != ring:
                        continue
                    j = head[a * nb + b]
                    while j >= 0:
                        d = (f1[i] - f1[j]) ** 2 + (f2[i] - f2[j]) ** 2
                        if d < dbest:
                            dbest = d
                            best = j
                        j = nxt[j]
        if best >= 0:
            g1, g2, b1, b2 = f1[best], f2[best], U1[best], U2[best]
        elif ok0:
            g1, g2, b1, b2 = 0.0, 0.0, o1, o2
        else:  # no anchor: the paraxial guess only
            g1, g2, b1, b2 = 0.0, 0.0, 0.0, 0.0
        conv, u1, u2, r1, r2, nev = _solve_from(
            lens, stop, finite, z_obj, f1[i], f2[i], g1, g2, b1, b2, slope0, tol, hscale
        )
        evals[i] = nev
        x0, y0, z0, L0, M0, N0 = start_ray_2d(finite, z_obj, f1[i], f2[i], u1, u2)
        if not conv:
            start[0, i] = np.nan if finite == 0 else x0
            start[1, i] = np.nan if finite == 0 else y0
            start[2, i] = z0
            start[3, i] = np.nan if finite == 1 else L0
            start[4, i] = np.nan if finite == 1 else M0
            start[5, i] = np.nan if finite == 1 else N0
            put_segment(last, i, False, x0, y0, z0, L0, M0, N0)
            status[i] = STATUS_AIM_FAILED
            surface[i] = 0
            residual[0, i] = np.nan
            residual[1, i] = np.nan
            continue
        U1[i] = u1
        U2[i] = u2
        cell = c1 * nb + c2
        nxt[i] = head[cell]
        head[cell] = i
        put_segment(start, i, True, x0, y0, z0, L0, M0, N0)
        st, sf, xs, ys, x, y, z, L, M, N = trace_via_stop(
            _trace_lens, lens, stop, ns, clip, x0, y0, z0, L0, M0, N0
        )
        ok = st == STATUS_OK
        status[i] = st
        surface[i] = sf
        put_segment(last, i, ok, x, y, z, L, M, N)
        residual[0, i] = xs if ok else r1
        residual[1, i] = ys if ok else r2
