"""Ray paths: every surface intersection of a few rays (for drawings and checks)."""

from __future__ import annotations

import math

import numpy as np

from .codes import STATUS_OK
from .jit import kernel
from .surface import surface_step

@kernel(error_model="numpy")
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

