"""Plain-numpy vectorized real-ray tracer: the "what numpy alone gives" baseline.

Same mathematics as :mod:`raytrace.kernels` (curvature-form quadric intersection, Newton on even
aspheres, vector Snell, status codes), written as whole-array numpy operations: one pass over the
surfaces, every operation a temporary array over all rays. Millimetres, light toward +z.
"""

from __future__ import annotations

import numpy as np

from raytrace.kernels.codes import KIND_ASPHERE, KIND_PLANE
from raytrace.packing import PackedLens

OK, MISSED, TIR, CLIPPED = 0, 1, 2, 3


def _sag(c, k, a, rho):
    q = np.sqrt(np.maximum(1.0 - (1.0 + k) * c * c * rho, 0.0))
    z = c * rho / (1.0 + q)
    dz = 0.5 * c / np.where(q > 0, q, np.inf)
    pw = rho.copy()
    for m, am in enumerate(a):
        z += am * pw * rho
        dz += (m + 2) * am * pw
        pw *= rho
    return z, dz


def trace_numpy(p: PackedLens, x, y, z, L, M, N, clip: bool = True):
    """Trace rays (1-D arrays) through ``p``; returns (x, y, z, L, M, N, status) of the final
    segment (point on the last surface, direction after it); failed rays are NaN."""
    x = np.array(x, dtype=float)
    y = np.array(y, dtype=float)
    z = np.array(z, dtype=float)
    nrm = np.sqrt(L * L + M * M + N * N)
    L, M, N = L / nrm, M / nrm, N / nrm
    st = np.zeros(x.shape, np.int8)
    with np.errstate(all="ignore"):
        for j in range(p.n_surfaces):
            c, k, zv = p.c[j], p.k[j], p.zv[j]
            mu = p.n_in[j] / p.n_out[j]
            bad = ~(N > 0)
            t0 = (zv - z) / N
            x = x + t0 * L
            y = y + t0 * M
            zl = np.zeros_like(x)
            if p.kind[j] == KIND_PLANE:
                nx, ny, nz = np.zeros_like(x), np.zeros_like(x), np.ones_like(x)
            else:
                A = c * (1.0 + k * N * N)
                B = N - c * (x * L + y * M)
                C = c * (x * x + y * y)
                D = B * B - A * C
                den = B + np.sqrt(np.maximum(D, 0.0))
                s = C / den
                bad |= (D < 0) | ~(den > 0)
                x = x + s * L
                y = y + s * M
                zl = s * N
                if p.kind[j] == KIND_ASPHERE:
                    a = p.asph[j]
                    for _ in range(60):
                        sag, dsag = _sag(c, k, a, x * x + y * y)
                        ds = -(zl - sag) / (N - 2.0 * dsag * (x * L + y * M))
                        ds = np.where(np.isfinite(ds), ds, 0.0)
                        x += ds * L
                        y += ds * M
                        zl += ds * N
                        if np.all(np.abs(ds) <= 1e-14 * (1 + np.abs(x) + np.abs(y) + np.abs(zl))):
                            break
                    _, dsag = _sag(c, k, a, x * x + y * y)
                    nx, ny, nz = -2.0 * x * dsag, -2.0 * y * dsag, np.ones_like(x)
                else:
                    w = 1.0 - c * (1.0 + k) * zl
                    bad |= ~(w > 0)
                    nx, ny, nz = -c * x, -c * y, w
            z = zv + zl
            clipped = (x * x + y * y > p.sd[j] ** 2) if clip else np.zeros(x.shape, bool)
            tir = np.zeros(x.shape, bool)
            if mu != 1.0:
                inv = 1.0 / np.sqrt(nx * nx + ny * ny + nz * nz)
                cosi = (L * nx + M * ny + N * nz) * inv
                sg = np.where(cosi < 0, -inv, inv)
                cosi = np.abs(cosi)
                sin2 = mu * mu * (1.0 - cosi * cosi)
                tir = sin2 > 1.0
                g = (np.sqrt(np.maximum(1.0 - sin2, 0.0)) - mu * cosi) * sg
                L, M, N = mu * L + g * nx, mu * M + g * ny, mu * N + g * nz
                inv = 1.0 / np.sqrt(L * L + M * M + N * N)
                L, M, N = L * inv, M * inv, N * inv
            code = np.where(bad, MISSED, np.where(clipped, CLIPPED, np.where(tir, TIR, OK)))
            st = np.where(st == OK, code, st).astype(np.int8)
    fail = st != OK
    for arr in (x, y, z, L, M, N):
        arr[fail] = np.nan
    return x, y, z, L, M, N, st
