"""Numba real-ray kernels: surface intersection, vector refraction, bulk trace, chief-ray aiming.

Everything here sees only contiguous float64 / int64 arrays and scalars (DESIGN.md §5); the Python
layer in :mod:`raytrace.trace` owns objects, validation and errors.

Geometry (DESIGN.md §3): millimetres, light toward +z, first vertex at z = 0. A ray is a point
(x, y, z) and unit direction cosines (L, M, N). The lens arrays are those of
:class:`raytrace.lens.PackedLens`: ``kind, c, k, asph, zv, n_in, n_out, sd``.

Intersection (cancellation-free curvature form)
    The ray is first transferred to the vertex tangent plane of the surface (local z = 0) at
    (x1, y1). The quadric ``c (x² + y² + (1 + k) z²) − 2 z = 0`` then gives, along the ray
    parameter s (mm), ``A s² − 2 B s + C = 0`` with ``A = c (1 + k N²)``,
    ``B = N − c (x1 L + y1 M)``, ``C = c (x1² + y1²)``; the root continuous with the vertex is
    ``s = C / (B + sqrt(B² − A C))`` — no subtraction of nearly equal numbers, exact for c → 0
    (plane). Negative discriminant → MISSED; a root on the far sheet of the quadric
    (``1 − c (1 + k) z <= 0``) → MISSED. Even aspheres: Newton iteration on
    ``z − sag(x² + y²) = 0`` along the ray, started at the conic solution, stopped when the step
    is below 1e-14 mm × (1 + |x| + |y| + |z|); more than ``NEWTON_MAX`` steps → MISSED.

Refraction (vector Snell)
    With the unit normal n̂ oriented along the ray (cos I = d·n̂ >= 0) and μ = n/n':
    ``sin² I' = μ² (1 − cos² I)``; > 1 → TIR; ``d' = μ d + (cos I' − μ cos I) n̂``. The scalar
    path (chief rays, ray paths) and the asphere surfaces renormalise d'; the vectorised bulk path
    for planes and quadrics does not (|d'| = 1 exactly in exact arithmetic; on a sphere the
    normal (−c x, −c y, 1 − c z) is unit without normalisation): the direction cosines stay unit
    length to <= 2e-15 over 11 surfaces.

Status codes: OK 0, MISSED 1, TIR 2, CLIPPED 3 (outside the semi-diameter, when clipping is on),
AIM_FAILED 4. A failed ray carries the 1-based number of the surface where it failed and NaN
coordinates; every ray gets a status.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

STATUS_OK = 0
STATUS_MISSED = 1
STATUS_TIR = 2
STATUS_CLIPPED = 3
STATUS_AIM_FAILED = 4

KIND_PLANE = 0
KIND_QUADRIC = 1
KIND_ASPHERE = 2

NEWTON_MAX = 60
NEWTON_TOL = 1e-14

# Chief-ray aiming limits (per field): secant/bisection iterations per solve, step halvings of
# the field continuation, total residual evaluations.
AIM_MAXIT = 60
AIM_MAX_HALVINGS = 40
AIM_MAX_EVALS = 1500


@njit(cache=True, error_model="numpy", inline="always")
def _asphere_sag(c, k, asph, j, rho):
    """Even-asphere sag z(ρ) and dz/dρ at ρ = x² + y²; ok False outside the conic's domain."""
    arg = 1.0 - (1.0 + k) * c * c * rho
    if not (arg > 0.0):
        return 0.0, 0.0, False
    q = math.sqrt(arg)
    z = c * rho / (1.0 + q)
    dz = 0.5 * c / q
    pw = rho  # ρ^(j+1)
    for m in range(asph.shape[1]):
        a = asph[j, m]
        z += a * pw * rho
        dz += (m + 2) * a * pw
        pw *= rho
    return z, dz, True


@njit(cache=True, error_model="numpy", inline="always")
def _snell(LL, MM, NN, nx, ny, nz, mu, mu2):
    """Vector Snell refraction of the unit direction (LL, MM, NN) at the unit normal (nx, ny,
    nz), either orientation, with mu = n/n' and mu2 = mu². Returns (L', M', N', sin²θ'); the
    caller flags TIR where sin²θ' > 1 (the direction is then meaningless)."""
    cosi = LL * nx + MM * ny + NN * nz
    sgn = 1.0 if cosi >= 0.0 else -1.0
    cosi *= sgn
    sin2t = mu2 * (1.0 - cosi * cosi)
    g = (math.sqrt(max(1.0 - sin2t, 0.0)) - mu * cosi) * sgn
    return mu * LL + g * nx, mu * MM + g * ny, mu * NN + g * nz, sin2t


@njit(cache=True, error_model="numpy", inline="always")
def _quadric_root(c, k, x, y, L, M, N):
    """Distance s along the unit direction (L, M, N) from the point (x, y) on a surface's vertex
    tangent plane to the quadric of curvature c and conic k, in the cancellation-free form
    s = C / (B + sqrt(B² − A C)) (exact as c → 0). Returns (s, hit); hit is False where the ray
    misses the quadric or meets only its far branch, and s is then meaningless."""
    A = c * (1.0 + k * N * N)
    B = N - c * (x * L + y * M)
    C = c * (x * x + y * y)
    D = B * B - A * C
    den = B + math.sqrt(max(D, 0.0))
    return C / den, D >= 0.0 and den > 0.0


@njit(cache=True, error_model="numpy", inline="always")
def surface_step(kind, c, k, asph, j, zvj, mu, sdj, clip, x, y, z, L, M, N):
    """Intersect one surface and refract. Returns (status, x, y, z, L, M, N) with the point on the
    surface (global z) and the direction after it; status != 0 leaves the values meaningless."""
    if not (N > 0.0):
        return STATUS_MISSED, x, y, z, L, M, N
    t0 = (zvj - z) / N
    x = x + t0 * L
    y = y + t0 * M
    zl = 0.0
    nx = 0.0
    ny = 0.0
    nz = 1.0
    if kind != KIND_PLANE:
        s, have = _quadric_root(c, k, x, y, L, M, N)
        if not have:
            s = 0.0
        if kind == KIND_QUADRIC:
            if not have:
                return STATUS_MISSED, x, y, z, L, M, N
            x = x + s * L
            y = y + s * M
            zl = s * N
            w = 1.0 - c * (1.0 + k) * zl
            if not (w > 0.0):
                return STATUS_MISSED, x, y, z, L, M, N
            nx = -c * x
            ny = -c * y
            nz = w
        else:
            x = x + s * L
            y = y + s * M
            zl = s * N
            converged = False
            for _ in range(NEWTON_MAX):
                sag, dsag, ok = _asphere_sag(c, k, asph, j, x * x + y * y)
                if not ok:
                    return STATUS_MISSED, x, y, z, L, M, N
                gp = N - 2.0 * dsag * (x * L + y * M)
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
            sag, dsag, ok = _asphere_sag(c, k, asph, j, x * x + y * y)
            if not ok:
                return STATUS_MISSED, x, y, z, L, M, N
            nx = -2.0 * x * dsag
            ny = -2.0 * y * dsag
            nz = 1.0
    z = zvj + zl
    if clip and x * x + y * y > sdj * sdj:
        return STATUS_CLIPPED, x, y, z, L, M, N
    if mu != 1.0:
        inv = 1.0 / math.sqrt(nx * nx + ny * ny + nz * nz)
        nx *= inv
        ny *= inv
        nz *= inv
        L2, M2, N2, sin2t = _snell(L, M, N, nx, ny, nz, mu, mu * mu)
        if sin2t > 1.0:
            return STATUS_TIR, x, y, z, L, M, N
        L, M, N = L2, M2, N2
        inv = 1.0 / math.sqrt(L * L + M * M + N * N)
        L *= inv
        M *= inv
        N *= inv
    return STATUS_OK, x, y, z, L, M, N


@njit(cache=True, error_model="numpy", inline="always")
def trace_span(kind, c, k, asph, zv, n_in, n_out, sd, j0, j1, clip, x, y, z, L, M, N):
    """Trace surfaces j0 .. j1-1 (0-based). Returns (status, surface_1based, x, y, z, L, M, N)."""
    for j in range(j0, j1):
        st, x, y, z, L, M, N = surface_step(
            kind[j], c[j], k[j], asph, j, zv[j], n_in[j] / n_out[j], sd[j], clip, x, y, z, L, M, N
        )
        if st != STATUS_OK:
            return st, j + 1, x, y, z, L, M, N
    return STATUS_OK, 0, x, y, z, L, M, N


@njit(cache=True, error_model="numpy", inline="always")
def _trace_one(kind, c, k, asph, zv, n_in, n_out, sd, clip, x, y, z, L, M, N):
    nrm = math.sqrt(L * L + M * M + N * N)
    if not (nrm > 0.0 and math.isfinite(nrm) and math.isfinite(x + y + z)):
        return STATUS_MISSED, 1, x, y, z, L, M, N
    L /= nrm
    M /= nrm
    N /= nrm
    return trace_span(kind, c, k, asph, zv, n_in, n_out, sd, 0, c.shape[0], clip, x, y, z, L, M, N)


@njit(cache=True, error_model="numpy", inline="always")
def _store(i, st, sf, x, y, z, L, M, N, ox, oy, oz, oL, oM, oN, ost, osf):
    ost[i] = st
    osf[i] = sf
    if st == STATUS_OK:
        ox[i] = x
        oy[i] = y
        oz[i] = z
        oL[i] = L
        oM[i] = M
        oN[i] = N
    else:
        ox[i] = np.nan
        oy[i] = np.nan
        oz[i] = np.nan
        oL[i] = np.nan
        oM[i] = np.nan
        oN[i] = np.nan


BLOCK = 256
#: Blocks per parallel work item (one scratch buffer per item): 16 x 256 = 4096 rays.
CHUNK_BLOCKS = 16

# Row offsets of the per-block scratch buffer ``buf`` (one flat float64 array of NROWS * BLOCK):
# x, y, z, L, M, N, status, failed surface. One flat buffer with compile-time row offsets lets
# LLVM prove that the rows do not overlap (dependence distance >= BLOCK), so the surface loop
# below is vectorised (AVX2: 4 rays per instruction). With the eight separate output arrays the
# runtime alias checks exceed LLVM's limit and the loop stayed scalar (profiled: 3.7x slower).
_RX = 0
_RY = BLOCK
_RZ = 2 * BLOCK
_RL = 3 * BLOCK
_RM = 4 * BLOCK
_RN = 5 * BLOCK
_RS = 6 * BLOCK
_RF = 7 * BLOCK
# extra rows used by the even-asphere surfaces: local z, Newton "still iterating" flag, ρ = x² + y²,
# conic sag and slope, polynomial parts of sag and slope
_RZL = 8 * BLOCK
_RA = 9 * BLOCK
_RRHO = 10 * BLOCK
_RZC = 11 * BLOCK
_RDC = 12 * BLOCK
_RP = 13 * BLOCK
_RDP = 14 * BLOCK
NROWS = 15


@njit(cache=True, error_model="numpy", inline="always")
def _quadric_rows(buf, nb, cj, kj, zvj, sd2, mu, jp1, sphere):
    """One plane / quadric surface for the nb rays of the scratch buffer, branch-free (selects
    only) so that it vectorises. Failed rays keep computing on meaningless values; their status
    row records the first failure and they are replaced by NaN when the block is written out."""
    ck = cj * (1.0 + kj)
    mu2 = mu * mu
    for i in range(nb):
        LL = buf[_RL + i]
        MM = buf[_RM + i]
        NN = buf[_RN + i]
        t0 = (zvj - buf[_RZ + i]) / NN
        xx = buf[_RX + i] + t0 * LL
        yy = buf[_RY + i] + t0 * MM
        s, hit = _quadric_root(cj, kj, xx, yy, LL, MM, NN)
        xx += s * LL
        yy += s * MM
        zl = s * NN
        w = 1.0 - ck * zl
        nx = -cj * xx
        ny = -cj * yy
        if sphere:
            # on a sphere |(−c x, −c y, 1 − c z)| = 1 identically: no normalisation needed
            nz = w
        else:
            inv = 1.0 / math.sqrt(nx * nx + ny * ny + w * w)
            nx *= inv
            ny *= inv
            nz = w * inv
        L2, M2, N2, sin2t = _snell(LL, MM, NN, nx, ny, nz, mu, mu2)
        # |d'| = 1 exactly for unit d and n̂: no renormalisation here (it cost 17 % of the bulk
        # time); the drift measured over 11 surfaces is <= 2e-15 (tests check <= 1e-14).
        missed = (not (NN > 0.0)) or not hit or not (w > 0.0)
        clipped = xx * xx + yy * yy > sd2
        code = float(STATUS_TIR) if sin2t > 1.0 else 0.0
        code = float(STATUS_CLIPPED) if clipped else code
        code = float(STATUS_MISSED) if missed else code
        buf[_RX + i] = xx
        buf[_RY + i] = yy
        buf[_RZ + i] = zvj + zl
        buf[_RL + i] = L2
        buf[_RM + i] = M2
        buf[_RN + i] = N2
        old = buf[_RS + i]
        fresh = old == 0.0 and code != 0.0
        buf[_RS + i] = code if old == 0.0 else old
        buf[_RF + i] = jp1 if fresh else buf[_RF + i]


@njit(cache=True, error_model="numpy", inline="always")
def _asphere_sag_rows(buf, nb, c, k, asph, j):
    """Sag and slope dz/dρ of an even asphere at ρ = row _RRHO, in rows _RZC (+ polynomial) and
    _RDC; Horner passes over the rays, one per coefficient, so every loop vectorises. Where the
    conic's square root is not real the slope row gets NaN (→ MISSED by the caller)."""
    cc = (1.0 + k) * c * c
    for i in range(nb):
        rho = buf[_RRHO + i]
        arg = 1.0 - cc * rho
        q = math.sqrt(max(arg, 0.0))
        buf[_RZC + i] = c * rho / (1.0 + q)
        buf[_RDC + i] = 0.5 * c / q if arg > 0.0 else np.nan
        buf[_RP + i] = 0.0
        buf[_RDP + i] = 0.0
    for m in range(asph.shape[1] - 1, -1, -1):
        a = asph[j, m]
        da = (m + 2) * a
        for i in range(nb):
            rho = buf[_RRHO + i]
            buf[_RP + i] = buf[_RP + i] * rho + a
            buf[_RDP + i] = buf[_RDP + i] * rho + da
    for i in range(nb):
        rho = buf[_RRHO + i]
        buf[_RZC + i] += buf[_RP + i] * rho * rho
        buf[_RDC + i] += buf[_RDP + i] * rho


@njit(cache=True, error_model="numpy", inline="always")
def _asphere_rows(buf, nb, cj, kj, asph, j, zvj, sd2, mu, jp1):
    """One even-asphere surface for the nb rays of the scratch buffer, vectorised: the conic
    start point (as in :func:`surface_step`), then Newton passes over all rays still iterating
    (same step and stopping rule as :func:`surface_step`, at most ``NEWTON_MAX``), then the
    normal, clipping and vector refraction as in :func:`_quadric_rows`."""
    live = 0
    for i in range(nb):
        LL = buf[_RL + i]
        MM = buf[_RM + i]
        NN = buf[_RN + i]
        t0 = (zvj - buf[_RZ + i]) / NN
        xx = buf[_RX + i] + t0 * LL
        yy = buf[_RY + i] + t0 * MM
        s, have = _quadric_root(cj, kj, xx, yy, LL, MM, NN)
        s = s if have else 0.0
        xx += s * LL
        yy += s * MM
        buf[_RX + i] = xx
        buf[_RY + i] = yy
        buf[_RZL + i] = s * NN
        buf[_RRHO + i] = xx * xx + yy * yy
        ok = buf[_RS + i] == 0.0
        missed = ok and not (NN > 0.0)
        buf[_RS + i] = float(STATUS_MISSED) if missed else buf[_RS + i]
        buf[_RF + i] = jp1 if missed else buf[_RF + i]
        act = ok and not missed
        buf[_RA + i] = 1.0 if act else 0.0
        live += 1 if act else 0
    for _ in range(NEWTON_MAX):
        if live == 0:
            break
        _asphere_sag_rows(buf, nb, cj, kj, asph, j)
        live = 0
        for i in range(nb):
            act = buf[_RA + i] != 0.0
            LL = buf[_RL + i]
            MM = buf[_RM + i]
            NN = buf[_RN + i]
            xx = buf[_RX + i]
            yy = buf[_RY + i]
            zl = buf[_RZL + i]
            dsag = buf[_RDC + i]
            gp = NN - 2.0 * dsag * (xx * LL + yy * MM)
            bad = not (math.isfinite(gp) and gp != 0.0)
            ds = -(zl - buf[_RZC + i]) / gp
            ds = 0.0 if (bad or not act) else ds
            xx += ds * LL
            yy += ds * MM
            zl += ds * NN
            conv = abs(ds) <= NEWTON_TOL * (1.0 + abs(xx) + abs(yy) + abs(zl))
            fail = act and bad
            buf[_RX + i] = xx
            buf[_RY + i] = yy
            buf[_RZL + i] = zl
            buf[_RRHO + i] = xx * xx + yy * yy
            buf[_RS + i] = float(STATUS_MISSED) if fail else buf[_RS + i]
            buf[_RF + i] = jp1 if fail else buf[_RF + i]
            still = act and not bad and not conv
            buf[_RA + i] = 1.0 if still else 0.0
            live += 1 if still else 0
    if live > 0:  # not converged in NEWTON_MAX steps
        for i in range(nb):
            nc = buf[_RA + i] != 0.0
            buf[_RS + i] = float(STATUS_MISSED) if nc else buf[_RS + i]
            buf[_RF + i] = jp1 if nc else buf[_RF + i]
    _asphere_sag_rows(buf, nb, cj, kj, asph, j)
    mu2 = mu * mu
    for i in range(nb):
        LL = buf[_RL + i]
        MM = buf[_RM + i]
        NN = buf[_RN + i]
        xx = buf[_RX + i]
        yy = buf[_RY + i]
        dsag = buf[_RDC + i]
        nx = -2.0 * xx * dsag
        ny = -2.0 * yy * dsag
        inv = 1.0 / math.sqrt(nx * nx + ny * ny + 1.0)
        nx *= inv
        ny *= inv
        nz = inv
        L2, M2, N2, sin2t = _snell(LL, MM, NN, nx, ny, nz, mu, mu2)
        inv = 1.0 / math.sqrt(L2 * L2 + M2 * M2 + N2 * N2)
        refract = mu != 1.0
        missed = not math.isfinite(dsag)
        clipped = xx * xx + yy * yy > sd2
        code = float(STATUS_TIR) if (refract and sin2t > 1.0) else 0.0
        code = float(STATUS_CLIPPED) if clipped else code
        code = float(STATUS_MISSED) if missed else code
        buf[_RZ + i] = zvj + buf[_RZL + i]
        buf[_RL + i] = L2 * inv if refract else LL
        buf[_RM + i] = M2 * inv if refract else MM
        buf[_RN + i] = N2 * inv if refract else NN
        old = buf[_RS + i]
        fresh = old == 0.0 and code != 0.0
        buf[_RS + i] = code if old == 0.0 else old
        buf[_RF + i] = jp1 if fresh else buf[_RF + i]


@njit(cache=True, error_model="numpy", inline="always")
def _trace_block(kind, c, k, asph, zv, n_in, n_out, sd, clip, i0, i1, x, y, z, L, M, N,
                 ox, oy, oz, oL, oM, oN, ost, osf, buf):  # fmt: skip
    """Trace rays i0..i1-1 (i1 - i0 <= BLOCK) surface by surface in the scratch buffer ``buf``
    (NROWS * BLOCK float64, rows ``_RX`` ... ``_RDP``), then write them to the output arrays.

    Plane / quadric surfaces run the vectorised branch-free loop :func:`_quadric_rows`, even
    aspheres the vectorised Newton passes of :func:`_asphere_rows`."""
    nb = i1 - i0
    for i in range(nb):
        ii = i0 + i
        nrm = math.sqrt(L[ii] * L[ii] + M[ii] * M[ii] + N[ii] * N[ii])
        good = nrm > 0.0 and math.isfinite(nrm) and math.isfinite(x[ii] + y[ii] + z[ii])
        buf[_RX + i] = x[ii]
        buf[_RY + i] = y[ii]
        buf[_RZ + i] = z[ii]
        buf[_RL + i] = L[ii] / nrm
        buf[_RM + i] = M[ii] / nrm
        buf[_RN + i] = N[ii] / nrm
        buf[_RS + i] = 0.0 if good else float(STATUS_MISSED)
        buf[_RF + i] = 0.0 if good else 1.0
    for j in range(c.shape[0]):
        mu = n_in[j] / n_out[j]
        if kind[j] == KIND_ASPHERE:
            sd2 = sd[j] * sd[j] if clip else np.inf
            _asphere_rows(buf, nb, c[j], k[j], asph, j, zv[j], sd2, mu, float(j + 1))
            continue
        sd2 = sd[j] * sd[j] if clip else np.inf
        if k[j] == 0.0:
            _quadric_rows(buf, nb, c[j], 0.0, zv[j], sd2, mu, float(j + 1), True)
        else:
            _quadric_rows(buf, nb, c[j], k[j], zv[j], sd2, mu, float(j + 1), False)
    for i in range(nb):
        ii = i0 + i
        s = buf[_RS + i]
        ost[ii] = np.int8(s)
        osf[ii] = np.int32(buf[_RF + i])
        good = s == 0.0
        ox[ii] = buf[_RX + i] if good else np.nan
        oy[ii] = buf[_RY + i] if good else np.nan
        oz[ii] = buf[_RZ + i] if good else np.nan
        oL[ii] = buf[_RL + i] if good else np.nan
        oM[ii] = buf[_RM + i] if good else np.nan
        oN[ii] = buf[_RN + i] if good else np.nan


@njit(cache=True, error_model="numpy", fastmath={"contract"})
def trace_batch_serial(
    kind, c, k, asph, zv, n_in, n_out, sd, clip, x, y, z, L, M, N, ox, oy, oz, oL, oM, oN, ost, osf
):
    """Bulk trace, one thread. Inputs/outputs are 1-D arrays of equal length (structure of
    arrays); outputs hold the final segment (point on the last surface, direction after it),
    status (int8) and failed surface (int32, 1-based, 0 when OK). Rays are processed in blocks
    of ``BLOCK``, surface by surface within a block."""
    n = x.shape[0]
    buf = np.empty(NROWS * BLOCK)
    for b in range((n + BLOCK - 1) // BLOCK):
        i0 = b * BLOCK
        _trace_block(kind, c, k, asph, zv, n_in, n_out, sd, clip, i0, min(i0 + BLOCK, n),
                     x, y, z, L, M, N, ox, oy, oz, oL, oM, oN, ost, osf, buf)  # fmt: skip


@njit(cache=True, error_model="numpy", parallel=True, fastmath={"contract"})
def trace_batch_parallel(
    kind, c, k, asph, zv, n_in, n_out, sd, clip, x, y, z, L, M, N, ox, oy, oz, oL, oM, oN, ost, osf
):
    """Same as :func:`trace_batch_serial`; chunks of ``CHUNK_BLOCKS`` blocks are split over
    numba's threads (prange), each with its own scratch buffer."""
    n = x.shape[0]
    nblk = (n + BLOCK - 1) // BLOCK
    nch = (nblk + CHUNK_BLOCKS - 1) // CHUNK_BLOCKS
    for ch in prange(nch):
        buf = np.empty(NROWS * BLOCK)
        for b in range(ch * CHUNK_BLOCKS, min(ch * CHUNK_BLOCKS + CHUNK_BLOCKS, nblk)):
            i0 = b * BLOCK
            _trace_block(kind, c, k, asph, zv, n_in, n_out, sd, clip, i0, min(i0 + BLOCK, n),
                         x, y, z, L, M, N, ox, oy, oz, oL, oM, oN, ost, osf, buf)  # fmt: skip


@njit(cache=True, error_model="numpy")
def transfer_to_plane(x, y, z, L, M, N, z_plane):
    """(x, y) where the lines (x, y, z) + t (L, M, N) meet the plane z = z_plane (mm); one pass,
    NaN in → NaN out."""
    n = x.shape[0]
    ox = np.empty(n)
    oy = np.empty(n)
    for i in range(n):
        t = (z_plane - z[i]) / N[i]
        ox[i] = x[i] + t * L[i]
        oy[i] = y[i] + t * M[i]
    return ox, oy


# --------------------------------------------------------------------------------------------
# Chief-ray aiming
# --------------------------------------------------------------------------------------------


@njit(cache=True, error_model="numpy", inline="always")
def _start_ray(finite, z_obj, f, u):
    """Object-space meridional ray for field value f and unknown u.

    finite == 0 (object at infinity): f = α (rad), start (0, u, 0), direction (0, sin α, cos α).
    finite == 1: f = object height (mm), start (0, f, z_obj), direction ∝ (0, u, 1) (u = tan θ).
    """
    if finite == 0:
        return u, 0.0, math.sin(f), math.cos(f)
    nrm = math.sqrt(1.0 + u * u)
    return f, z_obj, u / nrm, 1.0 / nrm


@njit(cache=True, error_model="numpy")
def _stop_residual(kind, c, k, asph, zv, n_in, n_out, sd, stop, finite, z_obj, f, u):
    """Meridional height at the stop surface of the ray (f, u) (unclipped); (status, y)."""
    y0, z0, M0, N0 = _start_ray(finite, z_obj, f, u)
    st, sf, x, y, z, L, M, N = trace_span(
        kind, c, k, asph, zv, n_in, n_out, sd, 0, stop + 1, False, 0.0, y0, z0, 0.0, M0, N0
    )
    return st, y


@njit(cache=True, error_model="numpy")
def _solve_field(kind, c, k, asph, zv, n_in, n_out, sd, stop, finite, z_obj, f, u0, tol, hscale):
    """Safeguarded secant solve of y_stop(u) = 0 from the guess u0.

    Returns (converged, u, residual, evaluations). A sign change between two traceable points
    keeps a bracket; secant steps outside it are replaced by bisection; an untraceable trial
    point is pulled halfway back toward the last good point (up to 20 times)."""
    nev = 1
    st, r0 = _stop_residual(kind, c, k, asph, zv, n_in, n_out, sd, stop, finite, z_obj, f, u0)
    if st != STATUS_OK or not math.isfinite(r0):
        return False, u0, np.nan, nev
    if abs(r0) <= tol:
        return True, u0, r0, nev
    h = 1e-7 * max(abs(u0), hscale)
    u1 = u0 + h
    st, r1 = _stop_residual(kind, c, k, asph, zv, n_in, n_out, sd, stop, finite, z_obj, f, u1)
    nev += 1
    if st != STATUS_OK:
        u1 = u0 - h
        st, r1 = _stop_residual(kind, c, k, asph, zv, n_in, n_out, sd, stop, finite, z_obj, f, u1)
        nev += 1
        if st != STATUS_OK:
            return False, u0, r0, nev
    if abs(r1) <= tol:
        return True, u1, r1, nev
    # best point (ub, rb) and bracket [lo, hi] (valid when have_br)
    g = (r1 - r0) / (u1 - u0)
    ub, rb = u0, r0
    if abs(r1) < abs(r0):
        ub, rb = u1, r1
    have_br = False
    lo = 0.0
    hi = 0.0
    rlo = 0.0
    if r0 * r1 < 0.0:
        have_br = True
        if u0 < u1:
            lo, hi, rlo = u0, u1, r0
        else:
            lo, hi, rlo = u1, u0, r1
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
                kind, c, k, asph, zv, n_in, n_out, sd, stop, finite, z_obj, f, un
            )
            nev += 1
            if st == STATUS_OK and math.isfinite(rn):
                ok = True
                break
            un = ub + 0.5 * (un - ub)
        if not ok:
            return False, ub, rb, nev
        if abs(rn) <= tol:
            return True, un, rn, nev
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
            if un < ub:
                lo, hi, rlo = un, ub, rn
            else:
                lo, hi, rlo = ub, un, rb
        if abs(rn) < abs(rb) or have_br:
            ub, rb = un, rn
        if have_br and hi - lo <= 4e-16 * max(abs(lo), abs(hi)):
            return False, ub, rb, nev
    return False, ub, rb, nev


@njit(cache=True, error_model="numpy")
def aim_chief(kind, c, k, asph, zv, n_in, n_out, sd, stop, finite, z_obj, fields, slope0, tol,
              hscale, clip):  # fmt: skip
    """Aim the meridional chief ray (through the stop vertex) for every field; one call.

    fields: field values (α in rad for ``finite == 0``; object height in mm for ``finite == 1``),
    any order and sign (negative fields are mirror images of positive ones). slope0: paraxial
    du/df at f = 0 (−z_E0 for infinity; −1/(z_E0 − z_obj) for a finite object). tol: absolute
    stop-height tolerance (mm). hscale: scale of u for finite-difference steps.

    Fields are solved in order of |f| by continuation: each starts from the extrapolation of the
    last two solutions; a failed solve halves the field step (intermediate fields) until it
    succeeds or AIM_MAX_HALVINGS / AIM_MAX_EVALS is exhausted (→ AIM_FAILED).

    Returns a (13, n) float64 array with rows: u, y_start, z_start, M_start, N_start, y_last,
    z_last, M_last, N_last, status, surface, evaluations, stop residual. Rays of fields that
    failed have NaN rows (except z_start, status, surface, evaluations).
    """
    n = fields.shape[0]
    ns = c.shape[0]
    out = np.empty((13, n))
    order = np.argsort(np.abs(fields))
    # continuation state: last solved field (fb, ub) and the secant slope du/df there
    fb = 0.0
    ub = 0.0
    slope = slope0
    for ii in range(n):
        i = order[ii]
        ftarget = abs(fields[i])
        sign = 1.0 if fields[i] >= 0.0 else -1.0
        nev = 0
        conv = False
        u = 0.0
        res = 0.0
        if ftarget == 0.0:
            conv = True
            u = 0.0
            res = 0.0
        else:
            fcur = fb
            ucur = ub
            step = ftarget - fcur
            halvings = 0
            while True:
                ftry = fcur + step
                if step == ftarget - fcur:
                    ftry = ftarget
                guess = ucur + slope * (ftry - fcur)
                ok, usol, rsol, ne = _solve_field(
                    kind, c, k, asph, zv, n_in, n_out, sd, stop, finite, z_obj, ftry, guess, tol,
                    hscale,
                )  # fmt: skip
                nev += ne
                if ok:
                    if ftry != fcur:
                        slope = (usol - ucur) / (ftry - fcur)
                    fcur, ucur = ftry, usol
                    fb, ub = fcur, ucur
                    if ftry == ftarget:
                        conv = True
                        u = usol
                        res = rsol
                        break
                    step = min(2.0 * step, ftarget - fcur)
                else:
                    halvings += 1
                    if halvings > AIM_MAX_HALVINGS or nev > AIM_MAX_EVALS:
                        u = usol
                        res = rsol
                        break
                    step *= 0.5
        y0, z0, M0, N0 = _start_ray(finite, z_obj, ftarget, u)
        out[0, i] = sign * u
        out[1, i] = sign * y0
        out[2, i] = z0
        out[3, i] = sign * M0
        out[4, i] = N0
        out[11, i] = nev
        if not conv:
            for r in range(0, 9):
                if r != 2:
                    out[r, i] = np.nan
            out[9, i] = STATUS_AIM_FAILED
            out[10, i] = 0
            out[12, i] = np.nan
            continue
        st, sf, x, y, z, L, M, N = trace_span(
            kind, c, k, asph, zv, n_in, n_out, sd, 0, stop + 1, clip, 0.0, y0, z0, 0.0, M0, N0
        )
        ystop = y
        if st == STATUS_OK:
            st, sf, x, y, z, L, M, N = trace_span(
                kind, c, k, asph, zv, n_in, n_out, sd, stop + 1, ns, clip, x, y, z, L, M, N
            )
        out[9, i] = st
        out[10, i] = sf
        if st == STATUS_OK:
            out[5, i] = sign * y
            out[6, i] = z
            out[7, i] = sign * M
            out[8, i] = N
            out[12, i] = sign * ystop
        else:
            for r in range(5, 9):
                out[r, i] = np.nan
            out[12, i] = sign * res
    return out


@njit(cache=True, error_model="numpy")
def trace_paths(kind, c, k, asph, zv, n_in, n_out, sd, clip, x, y, z, L, M, N, px, py, pz, st, sf):
    """Trace rays and record the intersection point on every surface (for drawings and checks).

    px, py, pz: (n_rays, n_surfaces) outputs; entries after a failure are NaN. st / sf: status and
    1-based failed surface per ray. Serial: this is for tens of rays, not for throughput."""
    ns = c.shape[0]
    for i in range(x.shape[0]):
        xi, yi, zi = x[i], y[i], z[i]
        nrm = math.sqrt(L[i] * L[i] + M[i] * M[i] + N[i] * N[i])
        Li, Mi, Ni = L[i] / nrm, M[i] / nrm, N[i] / nrm
        st[i] = STATUS_OK
        sf[i] = 0
        for j in range(ns):
            px[i, j] = np.nan
            py[i, j] = np.nan
            pz[i, j] = np.nan
        for j in range(ns):
            s, xi, yi, zi, Li, Mi, Ni = surface_step(
                kind[j],
                c[j],
                k[j],
                asph,
                j,
                zv[j],
                n_in[j] / n_out[j],
                sd[j],
                clip,
                xi,
                yi,
                zi,
                Li,
                Mi,
                Ni,
            )
            if s != STATUS_OK:
                st[i] = s
                sf[i] = j + 1
                break
            px[i, j] = xi
            py[i, j] = yi
            pz[i, j] = zi
