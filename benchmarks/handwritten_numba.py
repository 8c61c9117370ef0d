"""A minimal hand-written numba loop (spheres / conics only): the "honest limit" for the project's
kernel. One ``prange`` over rays, a scalar loop over surfaces, the same curvature-form
intersection and vector Snell as :mod:`raytrace.kernels`, a status byte (missed / TIR / clipped /
backward: the same travelling-backwards test, so both loops do the same work) and the transfer to
the image plane. No objects, no blocks, no Python wrapper: arrays in, arrays
out. Millimetres, light toward +z.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange


@njit(cache=True, error_model="numpy", fastmath=False)
def _one(c, k, zv, mu, sd2, x, y, z, L, M, N):
    st = 0
    tacc = 0.0  # path since the last refracting surface (surfaces with mu = 1 pass the ray on)
    acted = False
    for j in range(c.shape[0]):
        t0 = (zv[j] - z) / N
        x += t0 * L
        y += t0 * M
        cj = c[j]
        A = cj * (1.0 + k[j] * N * N)
        B = N - cj * (x * L + y * M)
        C = cj * (x * x + y * y)
        D = B * B - A * C
        if D < 0.0:
            return 1, x, y, z, L, M, N
        s = C / (B + math.sqrt(D))
        tt = tacc + t0 + s
        m = mu[j]
        if m != 1.0:
            if acted and tt < -1e-9 * (1.0 + abs(zv[j])):
                return 5, x, y, z, L, M, N
            acted = True
            tacc = 0.0
        else:
            tacc = tt
        x += s * L
        y += s * M
        zl = s * N
        z = zv[j] + zl
        if x * x + y * y > sd2[j]:
            return 3, x, y, z, L, M, N
        nx = -cj * x
        ny = -cj * y
        nz = 1.0 - cj * (1.0 + k[j]) * zl
        inv = 1.0 / math.sqrt(nx * nx + ny * ny + nz * nz)
        nx *= inv
        ny *= inv
        nz *= inv
        cosi = L * nx + M * ny + N * nz
        s2 = m * m * (1.0 - cosi * cosi)
        if s2 > 1.0:
            return 2, x, y, z, L, M, N
        g = math.sqrt(1.0 - s2) - m * cosi
        L = m * L + g * nx
        M = m * M + g * ny
        N = m * N + g * nz
    return st, x, y, z, L, M, N


@njit(cache=True, error_model="numpy", parallel=True)
def trace_to_image(c, k, zv, mu, sd2, z_img, x, y, z, L, M, N, ox, oy, st):
    """Trace every ray and write its (x, y) on the plane z = z_img and its status (0 = ok)."""
    for i in prange(x.shape[0]):
        s, xx, yy, zz, LL, MM, NN = _one(c, k, zv, mu, sd2, x[i], y[i], z[i], L[i], M[i], N[i])
        t = (z_img - zz) / NN
        ox[i] = xx + t * LL
        oy[i] = yy + t * MM
        st[i] = s


def arrays(p):
    """The few lens arrays the loop needs, from a :class:`raytrace.lens.PackedLens`."""
    if np.any(p.kind == 2):
        raise ValueError("the hand-written loop handles spheres and conics only")
    return (p.c, p.k, p.zv, p.n_in / p.n_out, p.sd * p.sd, float(p.z_image))


def run(p, x, y, z, L, M, N):
    n = x.shape[0]
    ox, oy = np.empty(n), np.empty(n)
    st = np.empty(n, np.int8)
    trace_to_image(*arrays(p), x, y, z, L, M, N, ox, oy, st)
    return ox, oy, st
