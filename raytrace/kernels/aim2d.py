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
2 × 2 system. The first Jacobian is the one carried from the neighbouring field the solve starts
from; where none is given, or where a step with a carried Jacobian does not at least halve |r|,
a forward-difference Jacobian is taken at the current point (steps ``1e-7 × max(|u_i|,
hscale)``; a backward step where the forward one cannot be traced), and its step is safeguarded
by a backtracking line search on |r|² (halved up to ``LINE_HALVINGS`` times until the trial ray
is traceable and |r| decreases). Every accepted step longer than a difference step updates the
Jacobian by Broyden's rule (the secant of the step). After the tolerance is met, one more
Newton step with the current Jacobian is taken when it lowers |r| (a polish toward round-off,
so that independently aimed rays agree far below the tolerance).

Continuation over the grid (:func:`_aim_fields_2d`): fields are solved in order of their distance
from the origin (|f|). Each starts from its nearest already-solved field j (found in a uniform
bucket grid of the fields, searched ring by ring), predicted as ``u = u_j + S_j·(f − f_j)`` with
that field's Jacobian; S is a 2 × 2 slope du/df, the paraxial slope0 at the origin, updated by
Broyden's rule along each field's step from its anchor (so that it follows the pupil
aberration). The first field starts from the solved origin field (0, 0) (aimed first). When
Newton fails from that guess, the field is approached along the straight path from f_j in steps
that halve on failure and double on success (as :mod:`.aim` does along the meridian),
extrapolating the solution along the path; after ``AIM_MAX_HALVINGS`` halvings or
``AIM_MAX_EVALS`` residual evaluations the field is AIM_FAILED. Traces to the stop per field:
about 5–7 on a 15 × 15 grid of a triplet or a Topogon, 10–13 with a difference Jacobian in
every Newton step (before 2026-11-28; ``grid21_traces`` of ``benchmarks/ab.py``: 10.5 → 5.9 on
the Topogon's 21 × 21 grid).

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
def newton_2d(residual, lens, stop, finite, z_obj, f1, f2, u1, u2, tol, hscale, backstep, j11,
              j12, j21, j22):  # fmt: skip
    """Safeguarded Newton solve of r(u) = ``residual(lens, stop, finite, z_obj, f1, f2, u1,
    u2)`` = 0 (a stop point (ok, x, y): :func:`stop_point`) from the guess (u1, u2) (module
    docstring). ``backstep``: where the forward-difference ray cannot be traced, try the
    backward step (True) or stop there (False). (j11, j12, j21, j22): a Jacobian dr/du (mm per
    unit of u, row-major) to begin with, such as a neighbouring field's; NaN: none, a forward
    difference is taken.

    Returns (converged, u1, u2, r1, r2, evaluations, j11, j12, j21, j22): on failure the best
    point found; the Jacobian last used (Broyden-updated by the last accepted step, for the
    next field)."""
    nev = 1
    ok, r1, r2 = residual(lens, stop, finite, z_obj, f1, f2, u1, u2)
    if not ok:
        return False, u1, u2, np.nan, np.nan, nev, j11, j12, j21, j22
    # have: a Jacobian to step with; fresh: it is a forward difference at the current point
    have = math.isfinite(j11 + j12 + j21 + j22)
    fresh = False
    # AIM2_MAXIT Newton steps; a carried Jacobian's refused trial is not one (the difference
    # Jacobian that follows it always ends in a step or a return)
    steps = 0
    while steps < AIM2_MAXIT:
        done = max(abs(r1), abs(r2)) <= tol
        if not have:
            # forward-difference Jacobian (backward where the forward ray cannot be traced)
            h1 = FD_STEP * max(abs(u1), hscale)
            ok, a1, a2 = residual(lens, stop, finite, z_obj, f1, f2, u1 + h1, u2)
            nev += 1
            if not ok and backstep:
                h1 = -h1
                ok, a1, a2 = residual(lens, stop, finite, z_obj, f1, f2, u1 + h1, u2)
                nev += 1
            if not ok:
                return done, u1, u2, r1, r2, nev, j11, j12, j21, j22
            h2 = FD_STEP * max(abs(u2), hscale)
            ok, b1, b2 = residual(lens, stop, finite, z_obj, f1, f2, u1, u2 + h2)
            nev += 1
            if not ok and backstep:
                h2 = -h2
                ok, b1, b2 = residual(lens, stop, finite, z_obj, f1, f2, u1, u2 + h2)
                nev += 1
            if not ok:
                return done, u1, u2, r1, r2, nev, j11, j12, j21, j22
            j11 = (a1 - r1) / h1
            j21 = (a2 - r2) / h1
            j12 = (b1 - r1) / h2
            j22 = (b2 - r2) / h2
            have = True
            fresh = True
        det = j11 * j22 - j12 * j21
        if det == 0.0 or not math.isfinite(det):
            if not fresh:  # a carried Jacobian that cannot be inverted: difference one here
                have = False
                continue
            return done, u1, u2, r1, r2, nev, j11, j12, j21, j22
        d1 = -(j22 * r1 - j12 * r2) / det
        d2 = -(-j21 * r1 + j11 * r2) / det
        rr = r1 * r1 + r2 * r2
        # a carried (not freshly differenced) Jacobian must at least halve |r| in one full step;
        # a fresh one gets the backtracking line search; the polish (done) one trial
        need = rr if (fresh or done) else 0.25 * rr
        lam = 1.0
        accepted = False
        for _h in range(LINE_HALVINGS if (fresh and not done) else 1):
            t1 = u1 + lam * d1
            t2 = u2 + lam * d2
            ok, s1, s2 = residual(lens, stop, finite, z_obj, f1, f2, t1, t2)
            nev += 1
            if ok and s1 * s1 + s2 * s2 < need:
                # Broyden's update of the Jacobian along the step (the secant of the step
                # taken); not from steps shorter than a difference step (the polish's and the
                # last ones before it), whose residual change is mostly round-off
                e1 = t1 - u1
                e2 = t2 - u2
                ee = e1 * e1 + e2 * e2
                hh = FD_STEP * max(abs(u1), abs(u2), hscale)
                if ee > hh * hh:
                    q1 = (s1 - r1 - (j11 * e1 + j12 * e2)) / ee
                    q2 = (s2 - r2 - (j21 * e1 + j22 * e2)) / ee
                    j11 += q1 * e1
                    j12 += q1 * e2
                    j21 += q2 * e1
                    j22 += q2 * e2
                u1, u2, r1, r2 = t1, t2, s1, s2
                accepted = True
                break
            lam *= 0.5
        if done:  # the polish step was taken or refused: either way finished
            return True, u1, u2, r1, r2, nev, j11, j12, j21, j22
        if not accepted:
            if not fresh:  # the carried Jacobian is too far off here: difference one
                have = False
                continue
            return max(abs(r1), abs(r2)) <= tol, u1, u2, r1, r2, nev, j11, j12, j21, j22
        fresh = False
        steps += 1
    return max(abs(r1), abs(r2)) <= tol, u1, u2, r1, r2, nev, j11, j12, j21, j22


@kernel(error_model="numpy")
def _stop_residual_2d(lens, stop, finite, z_obj, f1, f2, u1, u2):
    """:func:`stop_point` of the packed lens ``lens`` (:func:`_trace_lens`)."""
    return stop_point(_trace_lens, lens, stop, finite, z_obj, f1, f2, u1, u2)


@kernel(error_model="numpy")
def _newton2(lens, stop, finite, z_obj, f1, f2, u1, u2, tol, hscale, j11, j12, j21, j22):
    """:func:`newton_2d` on the packed lens ``lens`` (with backward finite-difference steps),
    from the Jacobian (j11, j12, j21, j22) (NaN: none)."""
    return newton_2d(_stop_residual_2d, lens, stop, finite, z_obj, f1, f2, u1, u2, tol, hscale,
                     True, j11, j12, j21, j22)  # fmt: skip


@kernel(error_model="numpy")
def _solve_from(lens, stop, finite, z_obj, f1, f2, g1, g2, ub1, ub2, jb, sb, tol, hscale):
    """Solve field (f1, f2) starting from the solved field (g1, g2) with solution (ub1, ub2),
    Jacobian ``jb`` (4,) (NaN: none) and slope du/df ``sb`` (4,), both row-major: Newton from the
    prediction ``ub + sb·(f − g)``, then continuation along the path from g to f.

    Returns (converged, u1, u2, r1, r2, evaluations, j11, j12, j21, j22)."""
    v1 = sb[0] * (f1 - g1) + sb[1] * (f2 - g2)
    v2 = sb[2] * (f1 - g1) + sb[3] * (f2 - g2)
    p1 = ub1 + v1
    p2 = ub2 + v2
    ok, u1, u2, r1, r2, nev, j11, j12, j21, j22 = _newton2(
        lens, stop, finite, z_obj, f1, f2, p1, p2, tol, hscale, jb[0], jb[1], jb[2], jb[3]
    )
    if ok:
        return True, u1, u2, r1, r2, nev, j11, j12, j21, j22
    # continuation along s in [0, 1]: field g + s (f − g); solution derivative du/ds; the
    # Jacobian of the last point reached on the path
    scur = 0.0
    c1 = ub1
    c2 = ub2
    k11, k12, k21, k22 = jb[0], jb[1], jb[2], jb[3]
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
        ok, u1, u2, r1, r2, ne, j11, j12, j21, j22 = _newton2(
            lens, stop, finite, z_obj, q1, q2, gu1, gu2, tol, hscale, k11, k12, k21, k22
        )
        nev += ne
        if ok:
            v1 = (u1 - c1) / (stry - scur)
            v2 = (u2 - c2) / (stry - scur)
            scur = stry
            c1 = u1
            c2 = u2
            k11, k12, k21, k22 = j11, j12, j21, j22
            if stry == 1.0:
                return True, u1, u2, r1, r2, nev, j11, j12, j21, j22
            step = min(2.0 * step, 1.0 - scur)
        else:
            halvings += 1
            if halvings > AIM_MAX_HALVINGS or nev > AIM_MAX_EVALS:
                return False, u1, u2, r1, r2, nev, k11, k12, k21, k22
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
    # the Jacobian dr/du of each solved field (row-major), carried to its neighbours
    J = np.full((n, 4), np.nan)
    # and its slope du/df (row-major): the paraxial slope at the origin, then Broyden-updated
    # along each field's step from its anchor
    S = np.zeros((n, 4))
    S0 = np.array([slope0, 0.0, 0.0, slope0])
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
    nan = np.nan
    J0 = np.empty(4)
    ok0, o1, o2, _r1, _r2, _ne, J0[0], J0[1], J0[2], J0[3] = _newton2(
        lens, stop, finite, z_obj, 0.0, 0.0, 0.0, 0.0, tol, hscale, nan, nan, nan, nan
    )
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
            g1, g2, b1, b2, jb, sb = f1[best], f2[best], U1[best], U2[best], J[best], S[best]
        elif ok0:
            g1, g2, b1, b2, jb, sb = 0.0, 0.0, o1, o2, J0, S0
        else:  # no anchor: the paraxial guess only
            g1, g2, b1, b2, jb, sb = 0.0, 0.0, 0.0, 0.0, J[i], S0
        conv, u1, u2, r1, r2, nev, j11, j12, j21, j22 = _solve_from(
            lens, stop, finite, z_obj, f1[i], f2[i], g1, g2, b1, b2, jb, sb, tol, hscale
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
        J[i, 0] = j11
        J[i, 1] = j12
        J[i, 2] = j21
        J[i, 3] = j22
        # this field's slope: the anchor's, Broyden-updated along the step from it (not from a
        # step so short that its secant is round-off, nor to a value that is not finite)
        e1 = f1[i] - g1
        e2 = f2[i] - g2
        ee = e1 * e1 + e2 * e2
        fs = FD_STEP * max(abs(f1[i]), abs(f2[i]), abs(g1), abs(g2))
        q1 = 0.0
        q2 = 0.0
        if ee > fs * fs and ee > 0.0:
            q1 = (u1 - b1 - (sb[0] * e1 + sb[1] * e2)) / ee
            q2 = (u2 - b2 - (sb[2] * e1 + sb[3] * e2)) / ee
            if not (math.isfinite(q1 * e1 + q1 * e2) and math.isfinite(q2 * e1 + q2 * e2)):
                q1 = 0.0
                q2 = 0.0
        S[i, 0] = sb[0] + q1 * e1
        S[i, 1] = sb[1] + q1 * e2
        S[i, 2] = sb[2] + q2 * e1
        S[i, 3] = sb[3] + q2 * e2
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
