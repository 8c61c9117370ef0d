"""Bulk real-ray trace: blocks of rays surface by surface in a scratch buffer, serial and
prange kernels, and the analytic transfer of final segments to a plane (DESIGN: docs/design.md,
"Performance").

Every plane / quadric surface is one branch-free, vectorised pass over the rays of a block; even
aspheres use vectorised Newton passes. Status and failed surface are kept per ray (see
:mod:`.codes`).

A surface with any flag in the placement table (a moved frame, a mirror, a clear aperture, a
coordinate break, rays toward −z: :mod:`.surface`) is traced ray by ray with the scalar
:func:`.surface.surface_step` (:func:`_general_rows`); a centred refracting lens has no flags and
runs only the vectorised passes.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from .codes import (
    F_FRAME,
    F_SKIP,
    G_FLAGS,
    G_LENS,
    G_ZV,
    KIND_ASPHERE,
    L_COAXIAL,
    STATUS_BACKWARD,
    STATUS_CLIPPED,
    STATUS_MISSED,
    STATUS_OK,
    STATUS_TIR,
)
from .jit import kernel
from .surface import (
    NEWTON_MAX,
    NEWTON_TOL,
    acts,
    backward_limit,
    path_length,
    reframe,
    snell,
    surface_step,
    vertex_plane_root,
)

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
# path since the last acting surface (the backward-travel test, :mod:`.surface`)
_RT = 15 * BLOCK
NROWS = 16


@kernel(error_model="numpy", inline="always")
def _ray(buf, i):
    """Ray i of the scratch buffer: (x, y, z, L, M, N)."""
    return buf[_RX + i], buf[_RY + i], buf[_RZ + i], buf[_RL + i], buf[_RM + i], buf[_RN + i]


@kernel(error_model="numpy", inline="always")
def _set_ray(buf, i, x, y, z, L, M, N):
    """Ray i of the scratch buffer set to (x, y, z, L, M, N)."""
    buf[_RX + i] = x
    buf[_RY + i] = y
    buf[_RZ + i] = z
    buf[_RL + i] = L
    buf[_RM + i] = M
    buf[_RN + i] = N


@kernel(error_model="numpy", inline="always")
def _path_limit(zvj, mu, check):
    """The backward-travel limit of a surface at vertex z zvj with index ratio mu (:mod:`.surface`,
    "Travelling backwards"), or −inf where the test does not apply (``check`` False, or a
    surface that does not refract): one compare per ray in the loops below."""
    return backward_limit(zvj) if (check and mu != 1.0) else -np.inf


@kernel(error_model="numpy", inline="always")
def _failure(tir, clipped, back, missed):
    """The status code of a ray at one surface, the first that applies of MISSED, BACKWARD,
    CLIPPED, TIR; 0.0 when it passes. Selects only (branch-free, so the loops vectorise)."""
    code = float(STATUS_TIR) if tir else 0.0
    code = float(STATUS_CLIPPED) if clipped else code
    code = float(STATUS_BACKWARD) if back else code
    return float(STATUS_MISSED) if missed else code


@kernel(error_model="numpy", inline="always")
def _record(buf, i, code, jp1):
    """Ray i of the scratch buffer gets the status ``code`` at surface jp1 (1-based) unless it
    failed before: the first failure is kept (code 0.0 changes nothing). Selects only."""
    old = buf[_RS + i]
    fresh = old == 0.0 and code != 0.0
    buf[_RS + i] = code if old == 0.0 else old
    buf[_RF + i] = jp1 if fresh else buf[_RF + i]


@kernel(error_model="numpy", inline="always")
def _quadric_rows(buf, nb, cj, kj, zvj, sd2, mu, jp1, sphere, check, carry):
    """One plane / quadric surface for the nb rays of the scratch buffer, branch-free (selects
    only) so that it vectorises. Failed rays keep computing on meaningless values; their status
    row records the first failure and they are replaced by NaN when the block is written out.
    ``check``: apply the backward-travel test (:mod:`.surface`, "Travelling backwards": only at
    a surface that refracts, and once an acting surface was met); row ``_RT`` gets the path to
    this surface, to which the row's previous value is added only when ``carry`` (dummy surfaces
    were traced since the last acting one). Branch-free, so the loop stays vectorised (an
    interleaved A/B measured the earlier form, with branches on ``carry`` and a boolean ``and``
    for the test, 3–4 % slower)."""
    ck = cj * (1.0 + kj)
    mu2 = mu * mu
    carried = 1.0 if carry else 0.0
    lim = _path_limit(zvj, mu, check)
    for i in range(nb):
        x0, y0, z0, LL, MM, NN = _ray(buf, i)
        t0, xx, yy, s, hit = vertex_plane_root(cj, kj, zvj, x0, y0, z0, LL, MM, NN)
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
        L2, M2, N2, sin2t = snell(LL, MM, NN, nx, ny, nz, mu, mu2)
        # |d'| = 1 exactly for unit d and n̂: no renormalisation here (it cost 17 % of the bulk
        # time); the drift measured over 11 surfaces is <= 2e-15 (tests check <= 1e-14).
        missed = (not (NN > 0.0)) or not hit or not (w > 0.0)
        clipped = xx * xx + yy * yy > sd2
        tt = t0 + s + buf[_RT + i] * carried  # the path: p = p0 + (t0 + s) d
        buf[_RT + i] = tt
        code = _failure(sin2t > 1.0, clipped, tt < lim, missed)
        _set_ray(buf, i, xx, yy, zvj + zl, L2, M2, N2)
        _record(buf, i, code, jp1)


@kernel(error_model="numpy", inline="always")
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


@kernel(error_model="numpy", inline="always")
def _asphere_rows(buf, nb, cj, kj, asph, j, zvj, sd2, mu, jp1, check, carry):
    """One even-asphere surface for the nb rays of the scratch buffer, vectorised: the conic
    start point (as in :func:`surface_step`), then Newton passes over all rays still iterating
    (same step and stopping rule as :func:`surface_step`, at most ``NEWTON_MAX``), then the
    normal, clipping, the backward-travel test (``check``) and vector refraction as in
    :func:`_quadric_rows`."""
    live = 0
    for i in range(nb):
        x0, y0, z0, LL, MM, NN = _ray(buf, i)
        _t0, xx, yy, s, have = vertex_plane_root(cj, kj, zvj, x0, y0, z0, LL, MM, NN)
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
            xx, yy, _z, LL, MM, NN = _ray(buf, i)
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
    carried = 1.0 if carry else 0.0
    lim = _path_limit(zvj, mu, check)
    for i in range(nb):
        xx, yy, z0, LL, MM, NN = _ray(buf, i)
        dsag = buf[_RDC + i]
        nx = -2.0 * xx * dsag
        ny = -2.0 * yy * dsag
        inv = 1.0 / math.sqrt(nx * nx + ny * ny + 1.0)
        nx *= inv
        ny *= inv
        nz = inv
        L2, M2, N2, sin2t = snell(LL, MM, NN, nx, ny, nz, mu, mu2)
        inv = 1.0 / math.sqrt(L2 * L2 + M2 * M2 + N2 * N2)
        refract = mu != 1.0
        missed = not math.isfinite(dsag)
        clipped = xx * xx + yy * yy > sd2
        # row _RZ still holds the start point's z0; along the line the path is Δz / N (N > 0 here)
        z1 = zvj + buf[_RZL + i]
        tt = (z1 - z0) / NN + buf[_RT + i] * carried
        buf[_RT + i] = tt
        code = _failure(refract and sin2t > 1.0, clipped, tt < lim, missed)
        buf[_RZ + i] = z1
        buf[_RL + i] = L2 * inv if refract else LL
        buf[_RM + i] = M2 * inv if refract else MM
        buf[_RN + i] = N2 * inv if refract else NN
        _record(buf, i, code, jp1)


@kernel(error_model="numpy")
def _general_rows(buf, nb, kind, c, k, asph, geo, j, mu, sdj, clip, check, acting, carry):
    """Surface j (flagged in the placement table) for the nb rays of the scratch buffer, one ray
    at a time with :func:`.surface.surface_step` (frame move, mirror, aperture, rays toward −z).
    Rays that failed before are left as they are."""
    fl = int(geo[j, G_FLAGS])
    jp1 = float(j + 1)
    for i in range(nb):
        if buf[_RS + i] != 0.0:
            continue
        x, y, z, L, M, N = _ray(buf, i)
        if (fl & F_FRAME) != 0:
            x, y, z, L, M, N = reframe(geo, j, x, y, z, L, M, N)
        st = STATUS_OK
        if (fl & F_SKIP) == 0:
            x0, y0, z0, L0, M0, N0 = x, y, z, L, M, N
            st, x, y, z, L, M, N = surface_step(
                kind, c, k, asph, geo, j, mu, sdj, clip, x, y, z, L, M, N,
                False, buf[_RT + i] if carry else 0.0, 1 if check else 0,
            )  # fmt: skip
            t = path_length(x0, y0, z0, x, y, z, L0, M0, N0)
            buf[_RT + i] = t + (buf[_RT + i] if carry else 0.0)
        _set_ray(buf, i, x, y, z, L, M, N)
        if st != STATUS_OK:
            buf[_RS + i] = float(st)
            buf[_RF + i] = jp1


@kernel(error_model="numpy", inline="always")
def _trace_block(kind, c, k, asph, geo, n_in, n_out, sd, clip, i0, i1, x, y, z, L, M, N,
                 ox, oy, oz, oL, oM, oN, ost, osf, buf):  # fmt: skip
    """Trace rays i0..i1-1 (i1 - i0 <= BLOCK) surface by surface in the scratch buffer ``buf``
    (NROWS * BLOCK float64, rows ``_RX`` ... ``_RDP``), then write them to the output arrays.

    Plane / quadric surfaces run the vectorised branch-free loop :func:`_quadric_rows`, even
    aspheres the vectorised Newton passes of :func:`_asphere_rows`, flagged surfaces (placement
    table) :func:`_general_rows`."""
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
        buf[_RT + i] = 0.0
    coaxial = (int(geo[0, G_LENS]) & L_COAXIAL) != 0
    # np.bool_: typed, not literal False, so that the called kernel _general_rows is compiled
    # once (with literals the first surface's call compiled a second copy)
    check = np.bool_(False)  # an acting surface was met: the backward-travel test applies
    carry = np.bool_(False)  # dummy surfaces traced since the last acting one (path in _RT)
    for j in range(c.shape[0]):
        mu = n_in[j] / n_out[j]
        acting = acts(geo, j, n_in, n_out)
        if not coaxial and geo[j, G_FLAGS] != 0.0:
            _general_rows(
                buf, nb, kind[j], c[j], k[j], asph, geo, j, mu, sd[j], clip, check, acting, carry
            )
            if (int(geo[j, G_FLAGS]) & F_SKIP) == 0:
                carry = not acting
            check = check or acting
            continue
        zvj = geo[j, G_ZV]
        if kind[j] == KIND_ASPHERE:
            sd2 = sd[j] * sd[j] if clip else np.inf
            _asphere_rows(buf, nb, c[j], k[j], asph, j, zvj, sd2, mu, float(j + 1), check, carry)
            carry = not acting
            check = check or acting
            continue
        sd2 = sd[j] * sd[j] if clip else np.inf
        if k[j] == 0.0:
            _quadric_rows(buf, nb, c[j], 0.0, zvj, sd2, mu, float(j + 1), True, check, carry)
        else:
            _quadric_rows(buf, nb, c[j], k[j], zvj, sd2, mu, float(j + 1), False, check, carry)
        carry = not acting
        check = check or acting
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


@kernel(error_model="numpy", fastmath={"contract"})
def trace_batch_serial(
    kind, c, k, asph, geo, n_in, n_out, sd, clip, x, y, z, L, M, N, ox, oy, oz, oL, oM, oN, ost, osf
):
    """Bulk trace, one thread. Inputs/outputs are 1-D arrays of equal length (structure of
    arrays); outputs hold the final segment (point on the last surface, direction after it),
    status (int8) and failed surface (int32, 1-based, 0 when OK). Rays are processed in blocks
    of ``BLOCK``, surface by surface within a block."""
    n = x.shape[0]
    buf = np.empty(NROWS * BLOCK)
    for b in range((n + BLOCK - 1) // BLOCK):
        i0 = b * BLOCK
        _trace_block(kind, c, k, asph, geo, n_in, n_out, sd, clip, i0, min(i0 + BLOCK, n),
                     x, y, z, L, M, N, ox, oy, oz, oL, oM, oN, ost, osf, buf)  # fmt: skip


@kernel(error_model="numpy", parallel=True, fastmath={"contract"})
def trace_batch_parallel(
    kind, c, k, asph, geo, n_in, n_out, sd, clip, x, y, z, L, M, N, ox, oy, oz, oL, oM, oN, ost, osf
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
            _trace_block(kind, c, k, asph, geo, n_in, n_out, sd, clip, i0, min(i0 + BLOCK, n),
                         x, y, z, L, M, N, ox, oy, oz, oL, oM, oN, ost, osf, buf)  # fmt: skip


@kernel(error_model="numpy")
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
