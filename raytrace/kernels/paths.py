"""Ray paths: every surface intersection of a few rays (for drawings and checks)."""

from __future__ import annotations

import math

import numpy as np

from .codes import F_FRAME, F_SKIP, G_ABS, G_ABST, G_FLAGS, STATUS_OK
from .jit import kernel
from .surface import reframe, surface_step


@kernel(error_model="numpy")
def trace_paths(kind, c, k, asph, geo, n_in, n_out, sd, clip, x, y, z, L, M, N, px, py, pz, st, sf):
    """Trace rays and record the intersection point on every surface (for drawings and checks).

    px, py, pz: (n_rays, n) outputs with n <= the packed surfaces: the points in **global**
    coordinates (:mod:`raytrace.frames`; for a centred lens the axis frame is the global one);
    entries after a failure, and of surfaces that are not traced (coordinate breaks), are NaN.
    st / sf: status and 1-based failed surface per ray. Serial: this is for tens of rays, not
    for throughput."""
    ns = c.shape[0]
    nrec = px.shape[1]
    for i in range(x.shape[0]):
        xi, yi, zi = x[i], y[i], z[i]
        nrm = math.sqrt(L[i] * L[i] + M[i] * M[i] + N[i] * N[i])
        Li, Mi, Ni = L[i] / nrm, M[i] / nrm, N[i] / nrm
        st[i] = STATUS_OK
        sf[i] = 0
        for j in range(nrec):
            px[i, j] = np.nan
            py[i, j] = np.nan
            pz[i, j] = np.nan
        for j in range(ns):
            fl = int(geo[j, G_FLAGS])
            if (fl & F_FRAME) != 0:
                xi, yi, zi, Li, Mi, Ni = reframe(geo, j, xi, yi, zi, Li, Mi, Ni)
            if (fl & F_SKIP) != 0:
                continue
            s, xi, yi, zi, Li, Mi, Ni = surface_step(
                kind[j], c[j], k[j], asph, geo, j, n_in[j] / n_out[j], sd[j], clip,
                xi, yi, zi, Li, Mi, Ni,
            )  # fmt: skip
            if s != STATUS_OK:
                st[i] = s
                sf[i] = j + 1
                break
            if j < nrec:
                a = G_ABS
                px[i, j] = geo[j, a] * xi + geo[j, a + 1] * yi + geo[j, a + 2] * zi + geo[j, G_ABST]
                py[i, j] = (
                    geo[j, a + 3] * xi
                    + geo[j, a + 4] * yi
                    + geo[j, a + 5] * zi
                    + geo[j, G_ABST + 1]
                )
                pz[i, j] = (
                    geo[j, a + 6] * xi
                    + geo[j, a + 7] * yi
                    + geo[j, a + 8] * zi
                    + geo[j, G_ABST + 2]
                )
